"""Small static C functions that stand in for libm in the generated C.

The C target promises "no libm beyond ``exp``": small controllers (and some certification
rules) allow one well-understood transcendental, not a whole math library.  Every other
function the generator needs - ``sqrt`` for the exact CoA, ``pow`` for bell terms and power
hedges, ``cos`` for cosine terms, and whatever a function term calls - is written here with
``+ - * /``, comparisons, integer casts and (where it is the natural tool) ``exp``.  All of
them compute in ``double`` whatever the block's real type, to a few units in the last place
(see docs/codegen.md for the method of each and the measured errors).

Each helper is wrapped in its own ``#ifndef`` guard, so several generated sources can be
compiled as one translation unit (a unity build) without clashing definitions.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Helper:
    """One helper: its C name, the helpers it calls, whether it calls ``exp``, its code."""

    name: str
    needs: tuple[str, ...]
    uses_exp: bool
    code: str


def _h(name: str, needs: tuple[str, ...], uses_exp: bool, code: str) -> Helper:
    return Helper(name, needs, uses_exp, code.strip("\n"))


# The constants are the usual fdlibm splits: ln 2 and pi/2 as sums of a short head (exact
# when multiplied by a small integer) and a tail, so the argument reductions lose nothing.
HELPERS: dict[str, Helper] = {
    h.name: h
    for h in (
        _h(
            "fz_fabs",
            (),
            False,
            """
static double fz_fabs(double x)
{
    return x <= 0.0 ? 0.0 - x : x; /* -0.0 -> +0.0, NaN stays NaN */
}""",
        ),
        _h(
            "fz_sqrt",
            (),
            False,
            """
/* sqrt: scale by powers of 4 into [0.5, 2), Newton from a linear guess, scale back. */
static double fz_sqrt(double x)
{
    double m = x, s = 1.0, y;
    int i;
    if (!(x > 0.0) || x > 1.7976931348623157e308) {
        return x == 0.0 || x > 0.0 ? x : NAN; /* 0, +inf and NaN pass; negatives are NaN */
    }
    while (m >= 3.402823669209385e38) { m *= 2.938735877055719e-39; s *= 1.8446744073709552e19; }
    while (m < 2.938735877055719e-39) { m *= 3.402823669209385e38; s *= 5.421010862427522e-20; }
    while (m >= 2.0) { m *= 0.25; s *= 2.0; }
    while (m < 0.5) { m *= 4.0; s *= 0.5; }
    y = 0.41 + 0.59 * m;
    for (i = 0; i < 6; i++) {
        y = 0.5 * (y + m / y);
    }
    y = y + (m - y * y) / (2.0 * y);
    return y * s;
}""",
        ),
        _h(
            "fz_log",
            (),
            False,
            """
/* natural log: x = m * 2^k with m in [sqrt(1/2), sqrt(2)), then
   log m = 2 atanh(s), s = (m-1)/(m+1), |s| < 0.172, by its series (relative 1e-17). */
static double fz_log(double x)
{
    double m = x, s, z, p;
    int k = 0;
    if (!(x > 0.0)) {
        return x == 0.0 ? -HUGE_VAL : NAN;
    }
    if (x > 1.7976931348623157e308) {
        return x;
    }
    while (m >= 1.8446744073709552e19) { m *= 5.421010862427522e-20; k += 64; }
    while (m < 5.421010862427522e-20) { m *= 1.8446744073709552e19; k -= 64; }
    while (m >= 1.4142135623730951) { m *= 0.5; k += 1; }
    while (m < 0.7071067811865476) { m *= 2.0; k -= 1; }
    s = (m - 1.0) / (m + 1.0);
    z = s * s;
    p = 1.0 / 25.0;
    p = 1.0 / 23.0 + z * p;
    p = 1.0 / 21.0 + z * p;
    p = 1.0 / 19.0 + z * p;
    p = 1.0 / 17.0 + z * p;
    p = 1.0 / 15.0 + z * p;
    p = 1.0 / 13.0 + z * p;
    p = 1.0 / 11.0 + z * p;
    p = 1.0 / 9.0 + z * p;
    p = 1.0 / 7.0 + z * p;
    p = 1.0 / 5.0 + z * p;
    p = 1.0 / 3.0 + z * p;
    return k * 6.93147180369123816490e-01 + (k * 1.90821492927058770002e-10 + 2.0 * (s + s * z * p));
}""",
        ),
        _h(
            "fz_pow",
            ("fz_log",),
            True,
            """
/* pow(a, p) = exp(p log a); negative a only for integer p (else NaN), like C's pow. */
static double fz_pow(double a, double p)
{
    double r;
    int odd = 0;
    if (p == 0.0 || a == 1.0) {
        return 1.0;
    }
    if (a != a || p != p) {
        return a + p;
    }
    if (a < 0.0) {
        if (p > -9007199254740992.0 && p < 9007199254740992.0) {
            long long n = (long long)p;
            if ((double)n != p) {
                return NAN;
            }
            odd = (int)(n % 2 != 0);
        }
        a = -a;
    }
    if (a == 0.0) {
        r = p > 0.0 ? 0.0 : HUGE_VAL;
    } else {
        r = exp(p * fz_log(a));
    }
    return odd ? -r : r;
}""",
        ),
        _h(
            "fz_sincos",
            (),
            False,
            """
/* sin and cos together: x = n pi/2 + r by a three-part Cody-Waite reduction (exact for
   |x| < 1e6), Taylor polynomials on |r| <= pi/4 (relative 1e-17), quadrant from n. */
static void fz_sincos(double x, double *sn, double *cs)
{
    double r, z, s, c;
    long long n;
    int q;
    if (!(x - x == 0.0)) { /* inf or NaN */
        *sn = *cs = x - x;
        return;
    }
    if (x > 4.0e15 || x < -4.0e15) { /* beyond the reduction: no meaningful phase left */
        *sn = *cs = NAN;
        return;
    }
    n = (long long)(x * 6.36619772367581382433e-01 + (x >= 0.0 ? 0.5 : -0.5));
    r = x - (double)n * 1.57079632673412561417e+00;
    r = r - (double)n * 6.07710050630396597660e-11;
    r = r - (double)n * 2.02226624871116645580e-21;
    r = r - (double)n * 8.47842766036889956997e-32;
    z = r * r;
    s = -1.0 / 121645100408832000.0;
    s = 1.0 / 355687428096000.0 + z * s;
    s = -1.0 / 1307674368000.0 + z * s;
    s = 1.0 / 6227020800.0 + z * s;
    s = -1.0 / 39916800.0 + z * s;
    s = 1.0 / 362880.0 + z * s;
    s = -1.0 / 5040.0 + z * s;
    s = 1.0 / 120.0 + z * s;
    s = -1.0 / 6.0 + z * s;
    s = r + r * z * s;
    c = -1.0 / 6402373705728000.0;
    c = 1.0 / 20922789888000.0 + z * c;
    c = -1.0 / 87178291200.0 + z * c;
    c = 1.0 / 479001600.0 + z * c;
    c = -1.0 / 3628800.0 + z * c;
    c = 1.0 / 40320.0 + z * c;
    c = -1.0 / 720.0 + z * c;
    c = 1.0 / 24.0 + z * c;
    c = 1.0 - 0.5 * z + z * z * c;
    q = (int)(((n % 4) + 4) % 4);
    *sn = q == 0 ? s : q == 1 ? c : q == 2 ? -s : -c;
    *cs = q == 0 ? c : q == 1 ? -s : q == 2 ? -c : s;
}""",
        ),
        _h(
            "fz_sin",
            ("fz_sincos",),
            False,
            """
static double fz_sin(double x)
{
    double s, c;
    fz_sincos(x, &s, &c);
    return s;
}""",
        ),
        _h(
            "fz_cos",
            ("fz_sincos",),
            False,
            """
static double fz_cos(double x)
{
    double s, c;
    fz_sincos(x, &s, &c);
    return c;
}""",
        ),
        _h(
            "fz_tan",
            ("fz_sincos",),
            False,
            """
static double fz_tan(double x)
{
    double s, c;
    fz_sincos(x, &s, &c);
    return s / c;
}""",
        ),
        _h(
            "fz_sinh",
            (),
            True,
            """
/* sinh: its Taylor series near 0 (no cancellation), (e^x - e^-x)/2 elsewhere. */
static double fz_sinh(double x)
{
    double z = x * x, p, e;
    if (x > -0.5 && x < 0.5) {
        p = 1.0 / 121645100408832000.0;
        p = 1.0 / 355687428096000.0 + z * p;
        p = 1.0 / 1307674368000.0 + z * p;
        p = 1.0 / 6227020800.0 + z * p;
        p = 1.0 / 39916800.0 + z * p;
        p = 1.0 / 362880.0 + z * p;
        p = 1.0 / 5040.0 + z * p;
        p = 1.0 / 120.0 + z * p;
        p = 1.0 / 6.0 + z * p;
        return x + x * z * p;
    }
    e = exp(x);
    return 0.5 * (e - 1.0 / e);
}""",
        ),
        _h(
            "fz_cosh",
            (),
            True,
            """
static double fz_cosh(double x)
{
    double e = exp(x);
    return 0.5 * (e + 1.0 / e);
}""",
        ),
        _h(
            "fz_tanh",
            ("fz_sinh",),
            True,
            """
static double fz_tanh(double x)
{
    double e;
    if (x > 40.0 || x < -40.0) {
        return x > 0.0 ? 1.0 : -1.0;
    }
    e = exp(x);
    return fz_sinh(x) / (0.5 * (e + 1.0 / e));
}""",
        ),
        _h(
            "fz_log10",
            ("fz_log",),
            False,
            """
static double fz_log10(double x)
{
    return fz_log(x) / 2.302585092994045684;
}""",
        ),
        _h(
            "fz_floor",
            (),
            False,
            """
/* floor, ceil, rint: integer casts below 2^52 (larger doubles are integers already). */
static double fz_floor(double x)
{
    double n;
    if (!(x > -4503599627370496.0 && x < 4503599627370496.0)) {
        return x;
    }
    n = (double)(long long)x;
    return n > x ? n - 1.0 : n;
}""",
        ),
        _h(
            "fz_ceil",
            (),
            False,
            """
static double fz_ceil(double x)
{
    double n;
    if (!(x > -4503599627370496.0 && x < 4503599627370496.0)) {
        return x;
    }
    n = (double)(long long)x;
    return n < x ? n + 1.0 : n;
}""",
        ),
        _h(
            "fz_rint",
            (),
            False,
            """
static double fz_rint(double x)
{
    long long n;
    double f;
    if (!(x > -4503599627370496.0 && x < 4503599627370496.0)) {
        return x;
    }
    n = (long long)x; /* toward zero; then to nearest, halves to even */
    f = x - (double)n;
    if (f > 0.5 || (f == 0.5 && n % 2 != 0)) {
        n += 1;
    } else if (f < -0.5 || (f == -0.5 && n % 2 != 0)) {
        n -= 1;
    }
    return (double)n;
}""",
        ),
        _h(
            "fz_fmod",
            (),
            False,
            """
/* fmod by binary long division: every subtraction is exact (Sterbenz), like C's fmod. */
static double fz_fmod(double x, double y)
{
    double r = x < 0.0 ? -x : x, ay = y < 0.0 ? -y : y, t;
    if (x != x || y != y || ay == 0.0 || r > 1.7976931348623157e308) {
        return NAN;
    }
    if (r < ay || ay > 1.7976931348623157e308) {
        return x;
    }
    t = ay;
    while (t <= 0.5 * r) {
        t *= 2.0;
    }
    for (;;) {
        if (r >= t) {
            r -= t;
        }
        if (t == ay) {
            break;
        }
        t *= 0.5;
    }
    return x < 0.0 ? -r : r;
}""",
        ),
        _h(
            "fz_atan",
            ("fz_sqrt",),
            False,
            """
/* atan: 1/x above 1, three half-angle steps t -> t/(1+sqrt(1+t^2)) to |t| < 0.1,
   then the series (relative 1e-17). */
static double fz_atan(double x)
{
    double t = x < 0.0 ? -x : x, z, p, r;
    int inv = 0, i;
    if (x != x || t < 1e-8) {
        return x; /* atan x = x (1 - x^2/3 ...): exact to rounding, and no subnormal halving */
    }
    if (t > 1.0) {
        t = 1.0 / t;
        inv = 1;
    }
    for (i = 0; i < 3; i++) {
        t = t / (1.0 + fz_sqrt(1.0 + t * t));
    }
    z = t * t;
    p = -1.0 / 19.0;
    p = 1.0 / 17.0 + z * p;
    p = -1.0 / 15.0 + z * p;
    p = 1.0 / 13.0 + z * p;
    p = -1.0 / 11.0 + z * p;
    p = 1.0 / 9.0 + z * p;
    p = -1.0 / 7.0 + z * p;
    p = 1.0 / 5.0 + z * p;
    p = -1.0 / 3.0 + z * p;
    r = 8.0 * (t + t * z * p);
    if (inv) {
        r = (1.57079632679489655800e+00 - r) + 6.12323399573676603587e-17;
    }
    return x < 0.0 ? -r : r;
}""",
        ),
        _h(
            "fz_atan2",
            ("fz_atan",),
            False,
            """
static double fz_atan2(double y, double x)
{
    double a;
    if (x != x || y != y) {
        return x + y;
    }
    if (x == 0.0 && y == 0.0) {
        return 0.0; /* signed zeros are not tracked */
    }
    if (x == 0.0) {
        return y > 0.0 ? 1.57079632679489661923 : -1.57079632679489661923;
    }
    a = fz_atan(y / x);
    if (x > 0.0) {
        return a;
    }
    return y < 0.0 ? a - 3.14159265358979323846 : a + 3.14159265358979323846;
}""",
        ),
        _h(
            "fz_asin",
            ("fz_atan2", "fz_sqrt"),
            False,
            """
static double fz_asin(double x)
{
    if (!(x >= -1.0 && x <= 1.0)) {
        return NAN;
    }
    return fz_atan2(x, fz_sqrt((1.0 - x) * (1.0 + x)));
}""",
        ),
        _h(
            "fz_acos",
            ("fz_atan2", "fz_sqrt"),
            False,
            """
static double fz_acos(double x)
{
    if (!(x >= -1.0 && x <= 1.0)) {
        return NAN;
    }
    return fz_atan2(fz_sqrt((1.0 - x) * (1.0 + x)), x);
}""",
        ),
    )
}


def closure(names: set[str]) -> list[str]:
    """``names`` and every helper they call, in an order where callees come first."""
    out: list[str] = []

    def visit(n: str) -> None:
        if n in out:
            return
        for d in HELPERS[n].needs:
            visit(d)
        out.append(n)

    for n in sorted(names):
        visit(n)
    return out


def render(names: set[str]) -> list[str]:
    """The C text of ``names`` and their callees, each in its own include guard."""
    lines: list[str] = []
    for n in closure(names):
        guard = f"FUZZYCTL_HELPER_{n.upper()}"
        lines += [f"#ifndef {guard}", f"#define {guard}", HELPERS[n].code, "#endif", ""]
    return lines
