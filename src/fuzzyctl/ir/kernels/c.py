"""The kernels of the evaluator program (:mod:`fuzzyctl.ir.programs.evaluator`) in C, for the
native backend: the same algorithms as the scalar Python kernels (:mod:`fuzzyctl.engine.reference.pwl`),
written once here.

``fz_am_lines`` is :func:`fuzzyctl.engine.reference.pwl.interval_pieces` followed by
:func:`~fuzzyctl.engine.reference.pwl.area_moment`: on one grid interval every activated set is a line
(clipped by MIN activation), the pieces between kinks, crossings (MAX) and the point where the
sum reaches 1 (BSUM) are linear and integrated in closed form; under PROBOR a piece is a
product of linear factors, integrated with Gauss-Legendre nodes exact for its degree.
"""

from __future__ import annotations

from fuzzyctl.engine.reference.pwl import gauss_legendre

ACCU_CODES = {"MAX": 1, "SUM": 2, "NSUM": 2, "BSUM": 3, "PROBOR": 4}


def gl_tables(max_lines: int) -> str:
    """Gauss-Legendre nodes and weights on [0, 1] for PROBOR of 2..max_lines factors, with
    the engine's node count ((n + 3) // 2 + 1)."""
    offs = [0] * (max_lines + 2)
    xs: list[float] = []
    ws: list[float] = []
    counts = [0] * (max_lines + 2)
    for n in range(2, max_lines + 1):
        m = (n + 3) // 2 + 1
        nodes, weights = gauss_legendre(m)
        offs[n], counts[n] = len(xs), m
        xs.extend(nodes)
        ws.extend(weights)
    xs = xs or [0.0]
    ws = ws or [0.0]
    return (
        f"static const double fz_glx[{len(xs)}] = {{{', '.join(repr(v) for v in xs)}}};\n"
        f"static const double fz_glw[{len(ws)}] = {{{', '.join(repr(v) for v in ws)}}};\n"
        f"static const int fz_gln[{len(counts)}] = {{{', '.join(map(str, counts))}}};\n"
        f"static const int fz_glo[{len(offs)}] = {{{', '.join(map(str, offs))}}};\n"
    )


AM_LINES = r"""
/* pwl._value: the set of line i at t (exactly w*a at its kink) */
static inline double fz_line(double L, double R, double a, double w, int mn, double kink, double t)
{
    double y;
    if (mn) {
        if (t == kink) return w * a;
        y = L + (R - L) * t;
        return w * (y >= a ? a : y);
    }
    return w * a * (L + (R - L) * t);
}

static inline void fz_piece(double xa, double xb, double v0, double v1, double *area, double *mom)
{
    double dx = xb - xa;
    *area += 0.5 * dx * (v0 + v1);
    *mom += dx * (xa * (2.0 * v0 + v1) + xb * (v0 + 2.0 * v1)) / 6.0;
}

static void fz_sort(double *v, int n)
{
    int i, j;
    for (i = 1; i < n; i++) {
        double k = v[i];
        for (j = i - 1; j >= 0 && v[j] > k; j--) v[j + 1] = v[j];
        v[j + 1] = k;
    }
}

static inline double fz_probor(const double *p0, const double *p1, int n, double s)
{
    double acc = 0.0, c;
    int k;
    for (k = 0; k < n; k++) {
        c = p0[k] + (p1[k] - p0[k]) * s;
        acc = acc + c - acc * c;
    }
    return acc;
}

/* pwl._combine: the accumulated set between xa and xb from the lines' values at both ends */
static void fz_combine(double xa, double xb, const double *p0, const double *p1, int n, int accu,
                       double *area, double *mom)
{
    double cuts[FZ_MAXL * FZ_MAXL], s0 = 0.0, s1 = 0.0, v0, v1, xp, vp, xs, vs, d0, d1, y, dx;
    int i, j, k, nc = 0;
    if (n == 1) {
        fz_piece(xa, xb, p0[0], p1[0], area, mom);
        return;
    }
    if (accu == 1) {
        for (i = 0; i < n; i++)
            for (j = i + 1; j < n; j++) {
                d0 = p0[i] - p0[j];
                d1 = p1[i] - p1[j];
                if (d0 * d1 < 0.0) cuts[nc++] = d0 / (d0 - d1);
            }
        v0 = p0[0];
        v1 = p1[0];
        for (k = 1; k < n; k++) {
            if (p0[k] > v0) v0 = p0[k];
            if (p1[k] > v1) v1 = p1[k];
        }
        if (!nc) {
            fz_piece(xa, xb, v0, v1, area, mom);
            return;
        }
        fz_sort(cuts, nc);
        dx = xb - xa;
        xp = xa;
        vp = v0;
        for (i = 0; i < nc; i++) {
            xs = xa + cuts[i] * dx;
            vs = p0[0] + (p1[0] - p0[0]) * cuts[i];
            for (k = 1; k < n; k++) {
                y = p0[k] + (p1[k] - p0[k]) * cuts[i];
                if (y > vs) vs = y;
            }
            fz_piece(xp, xs, vp, vs, area, mom);
            xp = xs;
            vp = vs;
        }
        fz_piece(xp, xb, vp, v1, area, mom);
        return;
    }
    if (accu == 4) {
        int m = fz_gln[n], o = fz_glo[n], q;
        double a = 0.0, mo = 0.0, f;
        dx = xb - xa;
        for (q = 0; q < m; q++) {
            f = fz_probor(p0, p1, n, fz_glx[o + q]);
            a += fz_glw[o + q] * f;
            mo += fz_glw[o + q] * f * (xa + fz_glx[o + q] * dx);
        }
        *area += a * dx;
        *mom += mo * dx;
        return;
    }
    for (k = 0; k < n; k++) {
        s0 += p0[k];
        s1 += p1[k];
    }
    if (accu == 3 && (s0 - 1.0) * (s1 - 1.0) < 0.0) {
        double s = (1.0 - s0) / (s1 - s0), xm = xa + s * (xb - xa);
        fz_piece(xa, xm, s0 < 1.0 ? s0 : 1.0, 1.0, area, mom);
        fz_piece(xm, xb, 1.0, s1 < 1.0 ? s1 : 1.0, area, mom);
        return;
    }
    if (accu == 3) {
        if (s0 > 1.0) s0 = 1.0;
        if (s1 > 1.0) s1 = 1.0;
    }
    fz_piece(xa, xb, s0, s1, area, mom);
}

/* area and moment of the accumulated activated sets on [x0, x1] (pwl.interval_pieces) */
static void fz_am_lines(double x0, double x1, int accu, int n, const double *L, const double *R,
                        const double *a, const double *w, const unsigned char *mn, double *area,
                        double *mom)
{
    double ll[FZ_MAXL], rr[FZ_MAXL], aa[FZ_MAXL], ww[FZ_MAXL], kink[FZ_MAXL];
    double ts[FZ_MAXL + 2], p0[FZ_MAXL], p1[FZ_MAXL], dx = x1 - x0, t0, t1, xa, xb;
    unsigned char mm[FZ_MAXL];
    int i, m = 0, nt = 2, u;
    *area = 0.0;
    *mom = 0.0;
    for (i = 0; i < n; i++) {
        if (a[i] * w[i] > 0.0) {
            ll[m] = L[i];
            rr[m] = R[i];
            aa[m] = a[i];
            ww[m] = w[i];
            mm[m] = mn[i];
            m++;
        }
    }
    if (!m) return;
    ts[0] = 0.0;
    ts[1] = 1.0;
    for (i = 0; i < m; i++) {
        kink[i] = -1.0;
        if (mm[i] && (ll[i] - aa[i]) * (rr[i] - aa[i]) < 0.0) {
            kink[i] = (aa[i] - ll[i]) / (rr[i] - ll[i]);
            ts[nt++] = kink[i];
        }
    }
    fz_sort(ts, nt);
    for (i = 1, u = 1; i < nt; i++)
        if (ts[i] != ts[u - 1]) ts[u++] = ts[i];
    nt = u;
    for (i = 0; i < m; i++) p0[i] = fz_line(ll[i], rr[i], aa[i], ww[i], mm[i], kink[i], 0.0);
    for (u = 1; u < nt; u++) {
        t0 = ts[u - 1];
        t1 = ts[u];
        xa = t0 > 0.0 ? x0 + t0 * dx : x0;
        xb = t1 < 1.0 ? x0 + t1 * dx : x1;
        for (i = 0; i < m; i++) p1[i] = fz_line(ll[i], rr[i], aa[i], ww[i], mm[i], kink[i], t1);
        fz_combine(xa, xb, p0, p1, m, accu, area, mom);
        for (i = 0; i < m; i++) p0[i] = p1[i];
    }
}
"""


def am_lines_code(max_lines: int) -> str:
    """The ``fz_am_lines`` kernel for at most ``max_lines`` sets per interval."""
    return f"#define FZ_MAXL {max(2, max_lines)}\n" + gl_tables(max(2, max_lines)) + AM_LINES


#: Smooth sets in the native evaluator (fuzzyctl.ir.kernels.smooth_columns locates kinks the same way).
SMOOTH_SAMPLES = 8  # points per characteristic interval where the branch taken is compared
SMOOTH_BISECTIONS = 40  # steps locating a kink
SMOOTH_ROUNDS = 4  # kinks located between two samples at most
SMOOTH_RTOL = 1e-10  # adaptive Gauss-Kronrod tolerance, relative (engine.quadrature's default)
SMOOTH_DEPTH = 48  # halvings of one piece at most (a jump not at a located point: width 2^-48)
SMOOTH_BUDGET = 40000  # Gauss-Kronrod panels per evaluation at most (bounded work)

SMOOTH_DRIVER = r"""
/* degree thresholds of single activated sets (ACT MIN, NIPMIN, BDIF): where term k crosses
   level c between a and b; bisection to the last bit (a jump of NIPMIN, a kink of MIN) */
static int {name}_cross(int k, double c, double a, double b, double *pt)
{{
    double fa = {mu}(k, a) - c, fb = {mu}(k, b) - c, lo = a, hi = b, mid;
    int i;
    if (!((fa < 0.0 && fb > 0.0) || (fa > 0.0 && fb < 0.0))) return 0;
    for (i = 0; i < 1100; i++) {{
        mid = 0.5 * (lo + hi);
        if (!(mid > lo && mid < hi)) break;
        if (({mu}(k, mid) - c < 0.0) == (fa < 0.0)) lo = mid;
        else hi = mid;
    }}
    *pt = hi;
    return 1;
}}

static int {name}_levels(double a, double b, const double *h, double *pts)
{{
    int n = 0;
{level_calls}
    (void)a; (void)b; (void)h; (void)pts;
    return n;
}}

/* adaptive Gauss-Kronrod 7/15 (engine/reference/quadrature.py's rule and acceptance test) on one piece */
static void {name}_gk(double a, double b, const double *h, const double *w, double *k, double *ek,
                      double *km, double *ekm)
{{
    static const double xs[15] = {{{nodes}}}, wk[15] = {{{wk}}}, wg[15] = {{{wg}}};
    double c = 0.5 * (a + b), r = 0.5 * (b - a), kk = 0.0, gg = 0.0, kx = 0.0, gx = 0.0, x, y, code;
    int j;
    for (j = 0; j < 15; j++) {{
        x = c + r * xs[j];
        y = {set}(x, h, w, &code);
        kk += wk[j] * y;
        gg += wg[j] * y;
        kx += wk[j] * y * x;
        gx += wg[j] * y * x;
    }}
    *k = kk * r;
    *km = kx * r;
    *ek = fabs(kk - gg) * r;
    *ekm = fabs(kx - gx) * r;
}}

/* CoG of a smooth accumulated set: the characteristic intervals are sampled, where the branch
   the set takes changes (which set is the largest, whether it is clipped, a bound reached)
   the kink is located by bisection, thresholds of single sets exactly ({name}_cross); every
   piece between them is integrated by adaptive Gauss-Kronrod to {rtol} relative */
static void {name}(const double *h, const double *w, double *value, unsigned char *fired)
{{
    static const double cuts[{nc}] = {{{cuts}}};
    double pts[{cap}], area = 0.0, mom = 0.0, total = 0.0, code, c0, cx, cr, lo, hi, end, mid, cm, a, b, x;
    double sa[{depth} + 2], sb[{depth} + 2], k1, e1, m1, em1, tol, span, scale, share;
    int i, j, k, q, np = 0, top, budget = {budget};
    for (i = 0; i + 1 < {nc}; i++) {{
        a = cuts[i];
        b = cuts[i + 1];
        pts[np++] = a;
        {set}(a, h, w, &c0);
        for (j = 1; j < {samples}; j++) {{
            x = j + 1 < {samples} ? a + (b - a) * ((double)j / ({samples} - 1)) : b;
            lo = a + (b - a) * ((double)(j - 1) / ({samples} - 1));
            np += {name}_levels(lo, x, h, pts + np);
            {set}(x, h, w, &cx);
            if (cx != c0) {{
                hi = x;
                code = c0;
                for (q = 0; q < {rounds} && np < {cap} - {nlev} - 2; q++) {{
                    end = hi;
                    for (k = 0; k < {bisections}; k++) {{
                        mid = 0.5 * (lo + hi);
                        {set}(mid, h, w, &cm);
                        if (cm == code) lo = mid;
                        else hi = mid;
                    }}
                    pts[np++] = 0.5 * (lo + hi);
                    {set}(hi, h, w, &cr);
                    if (cr == cx || !(hi < end)) break;
                    lo = hi;
                    hi = end;
                    code = cr;
                }}
            }}
            c0 = cx;
        }}
    }}
    pts[np++] = cuts[{nc} - 1];
    for (i = 1; i < np; i++) {{ /* insertion sort: the points are nearly in order */
        x = pts[i];
        for (j = i - 1; j >= 0 && pts[j] > x; j--) pts[j + 1] = pts[j];
        pts[j + 1] = x;
    }}
    span = cuts[{nc} - 1] - cuts[0];
    scale = fabs(cuts[0]) > fabs(cuts[{nc} - 1]) ? fabs(cuts[0]) : fabs(cuts[{nc} - 1]);
    scale = scale > span ? scale : span;
    /* pieces of at most 1e-13 of the scale lie between two points found for one kink or
       around a spike of no width (DMIN where a term is exactly 1): no area, and a node on
       the spike would fire a set that has none */
    for (i = 0; i + 1 < np; i++) {{ /* the total, for the relative tolerance */
        if (!(pts[i + 1] - pts[i] > 1e-13 * scale)) continue;
        {name}_gk(pts[i], pts[i + 1], h, w, &k1, &e1, &m1, &em1);
        total += fabs(k1);
    }}
    total = total > 1e-300 ? total : 1e-300;
    for (i = 0; i + 1 < np; i++) {{
        if (!(pts[i + 1] - pts[i] > 1e-13 * scale)) continue;
        sa[0] = pts[i];
        sb[0] = pts[i + 1];
        top = 1;
        while (top > 0) {{
            top--;
            a = sa[top];
            b = sb[top];
            {name}_gk(a, b, h, w, &k1, &e1, &m1, &em1);
            budget--;
            share = (b - a) / span;
            tol = {rtol} * total * (share > 1e-6 ? share : 1e-6);
            if ((e1 <= tol && em1 <= tol * scale) || b - a <= 1e-13 * scale || top >= {depth}
                || budget <= 0) {{
                area += k1;
                mom += m1;
                continue;
            }}
            mid = 0.5 * (a + b);
            sa[top] = mid; sb[top] = b; top++;
            sa[top] = a; sb[top] = mid; top++;
        }}
    }}
    *fired = area > 0.0;
    *value = area > 0.0 ? mom / area : 0.0;
}}
"""


def smooth_driver(
    name: str, set_fn: str, mu_fn: str, levels: list[tuple[int, str]], cuts: list[float], num: object
) -> str:
    """The C of one smooth output's CoG: ``set_fn`` computes the set and its branch code,
    ``mu_fn(k, x)`` the degree of set k's term, ``levels`` are ``(k, C expression of h)``: the
    degrees of term k where set k jumps or bends (:func:`activation_levels`)."""
    n_levels = len(levels)
    from fuzzyctl.engine.reference.quadrature import NODES, WG, WK

    fmt = num  # the renderer's literal printer
    cap = (len(cuts) - 1) * (SMOOTH_SAMPLES * (SMOOTH_ROUNDS + n_levels) + 1) + 2
    return SMOOTH_DRIVER.format(
        name=name,
        set=set_fn,
        mu=mu_fn,
        level_calls="\n".join(f"    n += {name}_cross({k}, {c}, a, b, pts + n);" for k, c in levels),
        nlev=n_levels,
        nc=len(cuts),
        cuts=", ".join(fmt(c) for c in cuts),  # type: ignore[operator]
        nodes=", ".join(repr(float(v)) for v in NODES),
        wk=", ".join(repr(float(v)) for v in WK),
        wg=", ".join(repr(float(v)) for v in WG),
        cap=cap,
        samples=SMOOTH_SAMPLES,
        rounds=SMOOTH_ROUNDS,
        bisections=SMOOTH_BISECTIONS,
        rtol=repr(SMOOTH_RTOL),
        depth=SMOOTH_DEPTH,
        budget=SMOOTH_BUDGET,
    )


def activation_levels(act: str, k: int) -> list[tuple[int, str]]:
    """``(k, C expression of h[k])`` for each level where activation ``act`` of set k jumps
    or bends as a function of its term degree (:data:`fuzzyctl.engine.semantics.operators.ACT_LEVELS`)."""
    from fuzzyctl.engine.semantics.operators import ACT_LEVELS

    return [(k, f"{offset!r} + {slope!r} * h[{k}]") for offset, slope in ACT_LEVELS.get(act, ())]


AM_MAX2 = r"""
/* pieces of a polyline through (x0 + t dx, v) for ordered t: area and moment (batch._polyline_am) */
static inline void fz_poly_am(double x0, double dx, const double *ts, const double *vs, int n,
                              double *area, double *mom)
{
    double a = 0.0, tm = 0.0, d, s;
    int k;
    for (k = 0; k + 1 < n; k++) {
        d = ts[k + 1] - ts[k];
        s = vs[k] + vs[k + 1];
        a += d * s;
        tm += d * (ts[k] * (s + vs[k]) + ts[k + 1] * (s + vs[k + 1]));
    }
    a *= 0.5 * dx;
    *area = a;
    *mom = x0 * a + (dx * dx / 6.0) * tm;
}

/* one activated set on the interval: w * min(a, line) or w * a * line (batch._clipped_line_am) */
static inline void fz_clipped_am(double x0, double dx, double L, double R, double a, double w, int mn,
                                 double *area, double *mom)
{
    double ts[3], vs[3], tk, y;
    if (!mn) {
        ts[0] = 0.0; ts[1] = 1.0;
        vs[0] = w * a * L; vs[1] = w * a * R;
        fz_poly_am(x0, dx, ts, vs, 2, area, mom);
        return;
    }
    tk = R != L ? (a - L) / (R - L) : 0.0;
    tk = tk < 0.0 ? 0.0 : (tk > 1.0 ? 1.0 : tk);
    ts[0] = 0.0; ts[1] = tk; ts[2] = 1.0;
    y = L + (R - L) * tk;
    vs[0] = w * (a < L ? a : L);
    vs[1] = w * ((L - a) * (R - a) < 0.0 ? a : (a < y ? a : y));
    vs[2] = w * (a < R ? a : R);
    fz_poly_am(x0, dx, ts, vs, 3, area, mom);
}

/* two activated sets under MAX, exactly and without sorting (batch._max_of_two):
   max = c1 + c2 - min(c1, c2), min(c1, c2) = min(H, p1, p2) is concave */
static inline __attribute__((always_inline)) void fz_am_max2(
    double x0, double x1, double L1, double R1, double h1, double w1, int mn1,
    double L2, double R2, double h2, double w2, int mn2, double *area, double *mom)
{
    double dx = x1 - x0, a1, b1, a2, b2, a3, b3, P1, S1, P2, S2, H, t, pts[5], vals[5], v0, v1;
    int k, hit;
    if (!(h2 * w2 > 0.0)) { /* one set alone: no crossing */
        fz_clipped_am(x0, dx, L1, R1, h1, w1, mn1, area, mom);
        return;
    }
    if (!(h1 * w1 > 0.0)) {
        fz_clipped_am(x0, dx, L2, R2, h2, w2, mn2, area, mom);
        return;
    }
    fz_clipped_am(x0, dx, L1, R1, h1, w1, mn1, &a1, &b1);
    fz_clipped_am(x0, dx, L2, R2, h2, w2, mn2, &a2, &b2);
    if (mn1) { P1 = w1 * L1; S1 = w1 * (R1 - L1); } else { P1 = w1 * h1 * L1; S1 = w1 * h1 * (R1 - L1); }
    if (mn2) { P2 = w2 * L2; S2 = w2 * (R2 - L2); } else { P2 = w2 * h2 * L2; S2 = w2 * h2 * (R2 - L2); }
    H = HUGE_VAL;
    if (mn1 && w1 * h1 < H) H = w1 * h1;
    if (mn2 && w2 * h2 < H) H = w2 * h2;
    t = S1 != S2 ? (P2 - P1) / (S1 - S2) : 0.0;
    t = t != t ? 0.0 : (t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t));
    pts[0] = 0.0; pts[2] = t; pts[4] = 1.0;
    int hits[2];
    for (k = 0; k < 2; k++) {
        double ta = k ? t : 0.0, tb = k ? 1.0 : t, ma, mb;
        ma = P1 + S1 * ta; if (P2 + S2 * ta < ma) ma = P2 + S2 * ta;
        mb = P1 + S1 * tb; if (P2 + S2 * tb < mb) mb = P2 + S2 * tb;
        hit = (ma - H) * (mb - H) < 0.0;
        hits[k] = hit;
        pts[1 + 2 * k] = hit ? ta + (H - ma) / (mb - ma) * (tb - ta) : ta;
    }
    for (k = 0; k < 5; k++) {
        if ((k == 1 && hits[0]) || (k == 3 && hits[1])) {
            vals[k] = H; /* exactly H where min(p1, p2) crosses it */
            continue;
        }
        v0 = P1 + S1 * pts[k];
        v1 = P2 + S2 * pts[k];
        v0 = v1 < v0 ? v1 : v0;
        vals[k] = H < v0 ? H : v0;
    }
    fz_poly_am(x0, dx, pts, vals, 5, &a3, &b3);
    *area = a1 + a2 - a3;
    *mom = b1 + b2 - b3;
}
"""
