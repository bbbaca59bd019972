"""Centre of gravity of a smooth output (Gaussian, bell, sigmoid, ... terms, or operators that
bend straight lines) in the generated block, to the tolerance its header states.

An accumulated set of smooth terms has no closed-form integral.  The generated code (the PLC
block, and the native evaluator through :mod:`fuzzyctl.ir.programs.native`) does this,
written in the IR so that Structured Text (``EXP`` is an IEC 61131-3 standard function) and C
share it (the reference is :mod:`fuzzyctl.engine.reference.quadrature`):

1. the output range is cut at constant breakpoints: every term's characteristic points
   (peaks, joins, support ends: :func:`fuzzyctl.engine.semantics.shapes.characteristic_points`), its
   corners when piecewise linear, and the panels the calibration below adds;
2. each interval is sampled at :data:`SAMPLES` points; where the branch the set takes changes
   between two samples the kink is located by :data:`BISECTIONS` halvings (several kinks
   between two samples: up to :data:`ROUNDS`).  The branch code has one bit per comparison
   that decides a branch: each term against the degrees where its activation jumps or bends
   (:data:`fuzzyctl.engine.semantics.operators.ACT_LEVELS`, the table the engine's integrators cut at:
   MIN bends at the rule degree a, NIPMIN jumps at 1 - a and bends at a, BDIF bends at
   1 - a), which set is largest (MAX, NIPMAX), where NIPMAX's sum reaches 1, where DMAX meets
   two nonzero sets, where a bounded sum reaches 1.  Terms are monotonic between the
   breakpoints, so each crosses a level at most once per interval;
3. every piece between breakpoints and kinks is smooth and is integrated by adaptive
   Gauss-Kronrod 7/15 (area and first moment): a panel is accepted when the Kronrod and
   Gauss values agree to :data:`QTOL` per unit of width (:data:`QTOL_REAL` in REAL builds),
   else halved, with at most :data:`QCAP` panels per evaluation and :data:`STACK` pending -
   the bounded work a PLC cycle needs.  A panel accepted short of the tolerance (cap
   reached) sets INFO 16#04.

A function term of x alone (the native evaluator; the PLC block refuses it) is the IR of its
expression at x; a set of no degree is left out (it may be negative or NaN), NaN wins under
MAX, and a panel that is not finite makes the output NaN (:func:`undefined`), as in the
reference.

Calibration (generation time) halves each interval until the :data:`NODES`-point and
``2*NODES``-point Gauss-Legendre rules agree on every term to :data:`PANEL_TOL`: it makes the
sampling of step 2 dense where terms are narrow.  The error aimed at (:func:`cog_bound`, in
the header) is ``2 QTOL (high - low)^2 / area`` on the CoG; tests compare it with the
observed difference to the reference interpreter.
"""

from __future__ import annotations

import contextlib
import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from fuzzyctl.engine.lowering.grid import left_limit, right_limit
from fuzzyctl.engine.plan import EX, EBinary, ECall, ENum, EUnary, ExprPlan, OutputPlan, Slot, TermPlan
from fuzzyctl.engine.reference.pwl import gauss_legendre
from fuzzyctl.engine.semantics import shapes
from fuzzyctl.engine.semantics.expr import eval_expr_np
from fuzzyctl.engine.semantics.operators import ACT_LEVELS, CLIP_BRANCH
from fuzzyctl.ir.builders import terms as T
from fuzzyctl.ir.nodes import Ex, Num, Var, not_
from fuzzyctl.ir.state import Gen
from fuzzyctl.kinds import norms

SAMPLES = 8  # points per interval where the branch taken is compared
BISECTIONS = 46  # halvings locating a kink (to 2^-46 ~ 1.4e-14 of the sample spacing)
ROUNDS = 8  # kinks located between two samples at most
NODES = 8  # Gauss-Legendre nodes of the generation-time calibration
QTOL = 1e-12  # Gauss-Kronrod acceptance per unit of width (area; moment: times the range)
QTOL_REAL = 1e-5  # the same in REAL (32-bit float) builds, where rounding is ~1e-7
STACK = 48  # pending panels at most (depth first: STACK - 2 nested halvings of one piece)
QCAP = 4000  # panels per evaluation at most (15 evaluations of the set each)
PIECE_MIN = 1e-13  # pieces narrower than this share of the range are not integrated
CODE_BITS = 50  # branch comparisons coded exactly (LREAL mantissa)
PANEL_TOL = 1e-10  # calibration tolerance per unit of width
MAX_DEPTH = 8  # halvings of one interval at most


@dataclass(frozen=True)
class SmoothSet:
    """One activated set: ``w * act(a, term)``."""

    term: int
    a: Ex
    w: Ex
    act: str


@dataclass(frozen=True)
class Calibration:
    cuts: tuple[float, ...]
    worst: float  # largest disagreement found per unit of width (<= PANEL_TOL when met)


def constant_term(t: TermPlan) -> bool:
    """Parameters known when the code is generated (a function term: of x and constants
    only; one reading inputs or outputs changes with them, and the calibration below
    samples every term then)."""
    if t.kind == "function":
        return _of_x_only(t.expr)
    return not isinstance(t.height, Slot) and not any(isinstance(p, Slot) for p in t.params)


def _of_x_only(e: ExprPlan | None) -> bool:
    if isinstance(e, ENum | EX):
        return True
    if isinstance(e, EUnary):
        return _of_x_only(e.operand)
    if isinstance(e, EBinary):
        return _of_x_only(e.left) and _of_x_only(e.right)
    if isinstance(e, ECall):
        return all(_of_x_only(a) for a in e.args)
    return False  # an input, an output (or none)


def has_function_terms(op: OutputPlan, sets: list[SmoothSet]) -> bool:
    """A set's term is a function term: it may be negative, NaN or infinite (a 0/0), which
    the reference answers with NaN (engine/reference/interp.py ``_smooth``)."""
    return any(op.terms[s.term].kind == "function" for s in sets)


def _no_outputs(_o: int) -> Ex:
    raise AssertionError("a function of x alone reads no output")


def finite(v: Ex) -> Ex:
    """``v`` is neither infinite nor NaN (``v - v`` is 0 only then)."""
    return (v - v).eq(0.0)


def _degree_np(t: TermPlan, x: np.ndarray) -> np.ndarray:
    if t.pwl is not None:
        return shapes.pwl_value_np(t.pwl, x)
    if t.kind == "function":
        assert t.expr is not None
        y = np.broadcast_to(np.asarray(eval_expr_np(t.expr, [], [], x), dtype=np.float64), x.shape)
        # a 0/0 somewhere calibrates nothing (the run time answers NaN there)
        return np.where(np.isfinite(y), y, 0.0)
    return shapes.membership_np(t.kind, [float(p) for p in t.params], float(t.height), x)  # type: ignore[arg-type]


def _breakpoints(op: OutputPlan) -> list[float]:
    assert op.low is not None and op.high is not None
    lo, hi = op.low, op.high
    pts = {lo, hi}
    for t in op.terms:
        if t.pwl is not None:
            cand = [x for x, _y in t.pwl]
        elif t.kind == "function":
            cand = []  # no characteristic points known (the reference's cuts: none either)
        else:
            cand = list(shapes.characteristic_points(t.kind, [float(p) for p in t.params]))  # type: ignore[arg-type]
        pts.update(c for c in cand if lo < c < hi and math.isfinite(c))
    return sorted(pts)


def calibrate(op: OutputPlan) -> Calibration:
    """The breakpoints of ``op`` refined until every term is integrated to :data:`PANEL_TOL`."""
    assert op.low is not None and op.high is not None
    width, low = op.high - op.low, op.low
    x8, w8 = (np.array(v) for v in gauss_legendre(NODES))
    x16, w16 = (np.array(v) for v in gauss_legendre(2 * NODES))
    worst = 0.0

    def err(a: float, b: float) -> float:
        d = b - a
        out = 0.0
        for t in op.terms:
            xa, xb = a + x8 * d, a + x16 * d
            fa, fb = _degree_np(t, xa), _degree_np(t, xb)
            e_area = abs(float(fa @ w8 - fb @ w16)) * d
            e_mom = abs(float((fa * (xa - low)) @ w8 - (fb * (xb - low)) @ w16)) * d / width
            out = max(out, e_area, e_mom)
        return out / d

    cuts: list[float] = []
    bps = _breakpoints(op)
    for a, b in itertools.pairwise(bps):
        stack = [(a, b, 0)]
        pieces: list[float] = []
        while stack:
            u, v, depth = stack.pop()
            e = err(u, v)
            if e > PANEL_TOL and depth < MAX_DEPTH:
                m = 0.5 * (u + v)
                stack += [(m, v, depth + 1), (u, m, depth + 1)]
                continue
            worst = max(worst, e)
            pieces.append(u)
        cuts += pieces
    cuts.append(bps[-1])
    return Calibration(tuple(cuts), worst)


def cog_bound() -> str:
    """The error the generated CoG aims at, as text for the header (checked against the
    reference interpreter by tests/codegen/test_gen_accuracy.py and test_realsys.py)."""
    return (
        f"each panel accepted when Kronrod and Gauss agree to {QTOL:.0e} x width (area) and "
        f"{QTOL:.0e} x width x (high - low) (moment), so |CoG error| <= {2 * QTOL:.0e} x "
        f"(high - low)^2 / area (in a REAL (float) build {QTOL_REAL:.0e} and {2 * QTOL_REAL:.0e}), "
        f"kinks located to 2^-{BISECTIONS} of the sample spacing; unless INFO = 16#04: more "
        f"than {QCAP} panels of 15 points per evaluation (or {STACK - 2} nested halvings of "
        f"one piece) were needed"
    )


# --------------------------------------------------------------------------- the set at x


def _const_pwl(g: Gen, pts: tuple[tuple[float, float], ...], x: Ex) -> Var:
    """``shapes.pwl_value`` of constant breakpoints as an IF chain."""
    out = g.temp(hint="MU")
    xs = sorted({q[0] for q in pts})
    b = g.b
    branches: list[tuple[Ex, float | Ex]] = [(x.lt(xs[0]), pts[0][1])]
    for k, u in enumerate(xs):
        pv = shapes.pwl_value(pts, u)
        branches.append((x.eq(u), pv))
        if k + 1 < len(xs):
            u1 = xs[k + 1]
            r0, l1 = right_limit(pts, u), left_limit(pts, u1)
            val: float | Ex = r0 if r0 == l1 else r0 + (x - u) * ((l1 - r0) / (u1 - u))
            branches.append((x.lt(u1), val))
    for k, (cond, val) in enumerate(branches):
        with b.if_(cond) if k == 0 else b.elif_(cond):
            b.set(out, val)
    with b.else_():
        b.set(out, pts[-1][1])
    return out


def set_at(g: Gen, op: OutputPlan, sets: list[SmoothSet], x: Var, accu: str) -> tuple[Var, Var]:
    """The accumulated set at ``x`` and a code of the branch it took: a sum of distinct powers
    of two, one per comparison that decides a branch - each term against the levels where its
    activation jumps or bends (:data:`fuzzyctl.engine.semantics.operators.ACT_LEVELS`), which set is the
    largest (MAX, NIPMAX), whether NIPMAX's sum reached 1, whether DMAX meets two nonzero sets,
    whether a bounded sum reached 1.  Between two points of equal code the set is smooth."""
    b = g.b
    acc = g.let(0.0, "ACC")
    code = g.let(0.0, "CODE")
    bit = itertools.count()
    entry = norms.accumulation(accu)
    tests = entry.branch_tests if entry is not None else frozenset()

    def flag(cond: Ex) -> None:
        # 2^(k mod CODE_BITS): exact in LREAL; beyond CODE_BITS comparisons two flips could
        # cancel (a kink then integrated by the adaptive rule, not located)
        with b.if_(cond):
            b.set(code, code + float(2 ** (next(bit) % CODE_BITS)))

    for s in sets:
        term = op.terms[s.term]
        where = f"term {op.name}.{term.name}"
        mu: Ex
        if term.pwl is not None:
            mu = _const_pwl(g, term.pwl, x)
        elif term.kind == "function":
            assert term.expr is not None
            mu = T.expression(g, term.expr, [], _no_outputs, x, where)
        else:
            ps: list[Ex] = [Num(float(p)) for p in term.params]  # type: ignore[arg-type]
            mu = T.smooth(g, term.kind, ps, x, where)
            if float(term.height) != 1.0:  # type: ignore[arg-type]
                mu = g.let(Num(float(term.height)) * mu, "MU")  # type: ignore[arg-type]
        mu = mu if isinstance(mu, Var) else g.let(mu, "MU")
        for offset, slope in ACT_LEVELS.get(s.act, ()):
            level = Num(offset) + Num(slope) * s.a
            # the clipping edge as the reference's branch tests it (operators.CLIP_BRANCH)
            flag(mu.ge(level) if s.act in CLIP_BRANCH and (offset, slope) == (0.0, 1.0) else mu.gt(level))
        c = g.let(T.mul(s.w, T.tnorm(g, s.act, s.a, mu)), "C")
        if term.kind == "function":
            # the reference leaves out a set of no degree (a function term may be negative
            # or NaN where min(0, mu) would not be 0)
            with b.if_(not_((s.a * s.w).gt(0.0))):
                b.set(c, 0.0)
        if "larger" in tests:
            flag(c.gt(acc))
        if "sum_below_one" in tests:
            flag((acc + c).lt(1.0))
        if "both_positive" in tests:
            flag(c.gt(0.0).and_(acc.gt(0.0)))
        T.accumulate_into(g, accu, acc, c)
        if term.kind == "function":
            # NaN wins, as in the reference's numpy (MAX's ``c > acc`` alone would drop it)
            with b.if_(c.ne(c)):
                b.set(acc, c)
    if "at_one" in tests:
        flag(acc.ge(1.0))
    return acc, code


# --------------------------------------------------------------------------- the driver


def smooth_cog(g: Gen, op: OutputPlan, sets: list[SmoothSet], cal: Calibration) -> tuple[Var, Var, Var]:
    """Emit the CoG of ``op`` from its activated ``sets``; returns (value, fired, capped):
    ``capped`` is TRUE when a panel was accepted short of :data:`QTOL` (iteration cap)."""
    b = g.b
    accu = op.accu or "MAX"
    pts, n = smooth_pieces(g, op, sets, cal)
    area, mom = g.let(0.0, "QA"), g.let(0.0, "QM")
    value, fired = g.temp(hint="Y"), g.temp("BOOL", "FIRED")
    capped = g.let(False, "QCAPPED", "BOOL")
    bad = g.let(False, "QBAD", "BOOL") if has_function_terms(op, sets) else None

    def accept(u: Var, d: Var, ka: Var, km: Var, ys: Var | None) -> None:
        b.set(area, area + ka * d)
        b.set(mom, mom + km * d)

    panels(g, op, sets, accu, pts, n, capped, accept, bad=bad)
    b.set(fired, area.gt(0.0))
    with b.if_(fired):
        b.set(value, float(op.low or 0.0) + mom / area)
    with b.else_():
        b.set(value, 0.0)
    if bad is not None:
        undefined(g, bad, value, fired)
    return value, fired, capped


def undefined(g: Gen, bad: Var, value: Var, fired: Var) -> None:
    """A panel was not finite (a function term's 0/0): the output is NaN, fired - not the
    DEFAULT of "no rule fired" (the reference's ``_smooth``)."""
    with g.b.if_(bad):
        g.b.set(fired, True)
        g.b.set(value, g.call("NAN"))


def smooth_pieces(g: Gen, op: OutputPlan, sets: list[SmoothSet], cal: Calibration) -> tuple[Var, Var]:
    """Steps 1 and 2 of the module docstring: the pieces ``pts[0..n-1]`` (sorted) between
    which the accumulated set is smooth."""
    b = g.b
    accu = op.accu or "MAX"
    cuts = cal.cuts
    nc = len(cuts)
    cap = (nc - 1) * (SAMPLES * ROUNDS + 1) + 2
    ctab = g.declare(g.fresh("QCUT", "QCUT"), "REAL", "const", nc, cuts, f"{op.name}: breakpoints")
    pts = g.array("QPT", "REAL", cap)
    n = g.let(0, "NQ", "INT")
    i = g.counter("QI")
    with b.for_(i, 0, nc - 2) as iv:
        a_, b_ = g.let(ctab[iv], "QL"), g.let(ctab[iv + 1], "QR")
        b.set(pts[n], a_)
        b.set(n, n + 1)
        x = g.temp(hint="X")
        xprev, c0 = g.let(a_, "XP"), g.let(0.0, "C0")
        j = g.counter("QJ")
        with b.for_(j, 0, SAMPLES - 1) as jv:
            with b.if_(jv.eq(SAMPLES - 1)):
                b.set(x, b_)
            with b.else_():
                b.set(x, a_ + (b_ - a_) * (g.call("TO_REAL", jv) / float(SAMPLES - 1)))
            _val, cx = set_at(g, op, sets, x, accu)
            with b.if_(jv.gt(0).and_(cx.ne(c0))):
                _locate(g, op, sets, accu, xprev, x, c0, cx, pts, n, cap)
            b.set(xprev, x)
            b.set(c0, cx)
    b.set(pts[n], cuts[-1])
    b.set(n, n + 1)
    return pts, n


#: what :func:`panels` calls for each accepted panel: (start, width, Kronrod mean of the set,
#: of the set times x - low, the 15 node values when asked for)
Accept = Callable[[Var, Var, Var, Var, "Var | None"], None]


def gk_nodes(g: Gen, ends: bool = False) -> Var:
    """The 15 Gauss-Kronrod nodes on 0..1 (ascending), a constant table; with ``ends``, 0
    and 1 around them (the nodes of :func:`panels` with ``keep_nodes``)."""
    from fuzzyctl.engine.reference.quadrature import NODES as GKX

    xv = tuple(0.5 * (float(v) + 1.0) for v in GKX)
    if ends:
        xv = (0.0, *xv, 1.0)
    return g.declare(g.fresh("GKX", "GKX"), "REAL", "const", len(xv), xv, "Gauss-Kronrod nodes on 0..1")


def panels(
    g: Gen,
    op: OutputPlan,
    sets: list[SmoothSet],
    accu: str,
    pts: Var,
    n: Var,
    capped: Var,
    accept: Accept,
    keep_nodes: bool = False,
    bad: Var | None = None,
) -> None:
    """Step 3: the set over the pieces ``pts[0..n-1]`` by adaptive Gauss-Kronrod 7/15: a
    panel is accepted when Kronrod and Gauss agree to :data:`QTOL` per unit of width (area;
    times the range for the moment), else halved - at most :data:`QCAP` panels per
    evaluation and :data:`STACK` pending ones (depth first: STACK - 2 nested halvings); a
    panel accepted short of the tolerance sets ``capped``.  ``accept`` emits what is done
    with each accepted panel; panels are accepted in increasing x (the left half of a split
    panel first), so that the same code run twice visits the same panels in the same order.
    With ``keep_nodes`` the panels have 17 nodes (their ends too, with no weight), kept in
    the table passed to ``accept``, and a piece too narrow to integrate is a panel of no
    width (its start is a node of LM/RM/MoM: an isolated point where a drastic sum reaches
    1 lies between two such pieces).  With ``bad`` (function terms), a panel whose area or
    moment is not finite is accepted at once and sets ``bad`` (the reference's NaN: no
    halving makes it a number)."""
    from fuzzyctl.engine.reference.quadrature import NODES as GKX
    from fuzzyctl.engine.reference.quadrature import WG as GKG
    from fuzzyctl.engine.reference.quadrature import WK as GKK

    b = g.b
    low = float(op.low or 0.0)
    width = float((op.high or 0.0) - low) or 1.0
    xv = tuple(0.5 * (float(v) + 1.0) for v in GKX)
    kv_, gv = tuple(0.5 * float(v) for v in GKK), tuple(0.5 * float(v) for v in GKG)
    if keep_nodes:  # the panel's ends too, with no weight (LM/RM/MoM read them)
        xv, kv_, gv = (0.0, *xv, 1.0), (0.0, *kv_, 0.0), (0.0, *gv, 0.0)
    m = len(xv)
    xs = g.declare(g.fresh("GKX", "GKX"), "REAL", "const", m, xv, "Gauss-Kronrod nodes on 0..1")
    wk = g.declare(g.fresh("GKK", "GKK"), "REAL", "const", m, kv_, "Kronrod weights")
    wg = g.declare(g.fresh("GKG", "GKG"), "REAL", "const", m, gv, "Gauss weights (0 off the 7 Gauss nodes)")
    # the program is precision-neutral; in REAL (float) 1e-10 vanishes beside 1 and the
    # tolerance must be one REAL can reach, else every panel would run to the cap
    tol = g.let(QTOL, "QTOL")
    probe = g.let(Num(1.0) + Num(1e-10), "QE")  # stored: rounded to the variable's type
    with b.if_(probe.eq(1.0)):
        b.set(tol, QTOL_REAL)
    sl, sr = g.array("QSL", "REAL", STACK), g.array("QSR", "REAL", STACK)
    ys = g.array("QY", "REAL", NODES_WITH_ENDS) if keep_nodes else None
    sp = g.let(0, "QSP", "INT")
    used = g.let(0, "QUSED", "DINT")
    p = g.counter("QP")
    v = (xs, wk, wg, tol, sl, sr, ys, sp, used, bad)
    # pieces narrower than PIECE_MIN of the range are left out: bisection brackets a point to
    # a few ulps, and a node there would give an isolated point (DMIN's peak) a positive area
    with b.for_(p, 0, n - 2) as pv:
        _wide_piece(g, op, sets, accu, pts, pv, width, capped, accept, v)


#: nodes of a panel with its two ends (:func:`panels` with ``keep_nodes``)
NODES_WITH_ENDS = 17


def _wide_piece(
    g: Gen,
    op: OutputPlan,
    sets: list[SmoothSet],
    accu: str,
    pts: Var,
    pv: Var,
    width: float,
    capped: Var,
    accept: Accept,
    v: tuple[Var, Var, Var, Var, Var, Var, Var | None, Var, Var, Var | None],
) -> None:
    """The panels of piece ``pv`` of :func:`panels` (``v``: its tables and variables)."""
    b = g.b
    low = float(op.low or 0.0)
    xs, wk, wg, tol, sl, sr, ys, sp, used, bad = v
    wide = (pts[pv + 1] - pts[pv]).gt(PIECE_MIN * width)
    with b.if_(wide) if ys is None else contextlib.nullcontext():
        b.set(sl[0], pts[pv])
        if ys is None:
            b.set(sr[0], pts[pv + 1])
        else:  # a narrow piece is a panel of no width: its start is a node, with no area
            b.set(sr[0], pts[pv])
            with b.if_(wide):
                b.set(sr[0], pts[pv + 1])
        b.set(sp, 1)
        with b.while_(sp.gt(0)):
            b.set(sp, sp - 1)
            u, d = g.let(sl[sp], "QU"), g.let(sr[sp] - sl[sp], "QD")
            ka, km, ga, gm = (g.let(0.0, h) for h in ("KA", "KM", "GA", "GM"))
            k = g.counter("QK")
            with b.for_(k, 0, (NODES_WITH_ENDS if ys is not None else 15) - 1) as kv:
                xq = g.let(u + xs[kv] * d, "XQ")
                y, _code = set_at(g, op, sets, xq, accu)
                if ys is not None:
                    b.set(ys[kv], y)
                ym = g.let(y * (xq - low), "YM")
                b.set(ka, ka + wk[kv] * y)
                b.set(km, km + wk[kv] * ym)
                b.set(ga, ga + wg[kv] * y)
                b.set(gm, gm + wg[kv] * ym)
            b.set(used, used + 1)
            ok: Ex = g.call("ABS", ka - ga).le(tol).and_(g.call("ABS", km - gm).le(tol * width))
            if bad is not None:
                nonfinite = g.let(not_(finite(ka).and_(finite(km))), "QNF", "BOOL")
                with b.if_(nonfinite):
                    b.set(bad, True)
                ok = ok.or_(nonfinite)
            mid = g.let(u + 0.5 * d, "QMID")
            # a panel a few ulps wide holds a jump the bisection placed to the last bit: its
            # share is rounding, not a missed tolerance (no halving, no INFO)
            split = g.let(mid.gt(u).and_(mid.lt(u + d)), "QSPLIT", "BOOL")
            room = sp.lt(STACK - 2).and_(used.lt(QCAP))
            with b.if_(not_(ok).and_(split).and_(room)):
                b.set(sl[sp], mid)
                b.set(sr[sp], u + d)
                b.set(sl[sp + 1], u)
                b.set(sr[sp + 1], mid)
                b.set(sp, sp + 2)
            with b.else_():
                accept(u, d, ka, km, ys)
                with b.if_(not_(ok).and_(split)):
                    b.set(capped, True)


def _locate(
    g: Gen,
    op: OutputPlan,
    sets: list[SmoothSet],
    accu: str,
    lo0: Var,
    x: Var,
    c0: Var,
    cx: Var,
    pts: Var,
    n: Var,
    cap: int,
) -> None:
    """Kinks between two samples (``lo0`` with code ``c0``, ``x`` with code ``cx``) appended to
    ``pts`` by bisection on the branch code."""
    b = g.b
    lo, hi = g.let(lo0, "LO"), g.let(x, "HI")
    code, chi = g.let(c0, "CL"), g.let(cx, "CH")
    q = g.let(0, "QR", "INT")
    go = g.let(True, "GO", "BOOL")
    with b.while_(go):
        k = g.counter("QB")
        with b.for_(k, 1, BISECTIONS):
            mid = g.let(0.5 * (lo + hi), "MID")
            _v, cm = set_at(g, op, sets, mid, accu)
            with b.if_(cm.eq(code)):
                b.set(lo, mid)
            with b.else_():
                b.set(hi, mid)
                b.set(chi, cm)
        with b.if_(n.lt(cap - 1)):
            b.set(pts[n], 0.5 * (lo + hi))
            b.set(n, n + 1)
        b.set(q, q + 1)
        stop = chi.eq(cx).or_(not_(hi.lt(x))).or_(q.ge(ROUNDS)).or_(n.ge(cap - 1))
        with b.if_(stop):
            b.set(go, False)
        with b.else_():
            b.set(lo, hi)
            b.set(hi, x)
            b.set(code, chi)
            b.set(chi, cx)
