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


def _two_over_pi_words() -> str:
    """2/pi's first 1280 bits as 40 C words of 32 bits, from an integer Machin formula (no
    transcribed constant to get wrong)."""
    bits = 1500
    one = 1 << bits

    def arctan_inv(k: int) -> int:
        total, term, n, sign = 0, one // k, 1, 1
        while term:
            total += sign * (term // n)
            term //= k * k
            n, sign = n + 2, -sign
        return total

    pi = 16 * arctan_inv(5) - 4 * arctan_inv(239)
    frac = (2 * one * one) // pi
    words = [(frac >> (bits - 32 * (k + 1))) & 0xFFFFFFFF for k in range(40)]
    rows = [", ".join(f"0x{w:08X}UL" for w in words[i : i + 6]) for i in range(0, 40, 6)]
    return ",\n    ".join(rows)


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
            "fz_rem_pio2_big",
            (),
            False,
            """
/* Payne-Hanek reduction for |x| >= 2^19, where Cody-Waite runs out of exact bits: x = M 2^E
   (M a 53-bit integer); only the bits of 2/pi that reach below 2^2 after scaling matter, so
   M times 224 of them (from word k0 on) gives x 2/pi mod 4 in fixed point, exactly to 2^-130.
   Returns the quadrant, *r = x - n pi/2 in [-pi/4, pi/4] (an error of about 1 ulp). */
static const unsigned long fz_two_over_pi[40] = {
    FZ_TWO_OVER_PI_WORDS
};
static int fz_rem_pio2_big(double x, double *r)
{
    unsigned long long limb[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, cur, carry, mw[2], top = 0, mid = 0, low = 0;
    double m = x, f, tail;
    int e = 0, k0, t, s, pos, fbits, q;
    while (m >= 1.8446744073709552e19) { m *= 5.421010862427522e-20; e += 64; }
    while (m >= 9007199254740992.0) { m *= 0.5; e += 1; }
    while (m < 4503599627370496.0) { m *= 2.0; e -= 1; }
    cur = (unsigned long long)m; /* x = cur 2^e, cur in [2^52, 2^53) */
    mw[0] = cur & 0xFFFFFFFFULL;
    mw[1] = cur >> 32;
    k0 = e >= 2 ? (e - 2) / 32 : 0;
    for (s = 0; s < 2; s++) { /* limb = cur * (words k0 .. k0+6), little-endian 32-bit limbs */
        carry = 0;
        for (t = 0; t < 7; t++) {
            cur = (unsigned long long)fz_two_over_pi[k0 + 6 - t] * mw[s] + limb[t + s] + carry;
            limb[t + s] = cur & 0xFFFFFFFFULL;
            carry = cur >> 32;
        }
        limb[7 + s] += carry;
    }
    fbits = 32 * (k0 + 7) - e; /* the binary point sits below bit fbits */
    q = (int)((limb[fbits >> 5] >> (fbits & 31)) & 1U);
    q |= (int)((limb[(fbits + 1) >> 5] >> ((fbits + 1) & 31)) & 1U) << 1;
    for (pos = fbits - 1; pos >= fbits - 159; pos--) { /* 159 bits: f >= 2^-62 keeps 97 */
        unsigned long long bit = (limb[pos >> 5] >> (pos & 31)) & 1U;
        if (pos >= fbits - 53) {
            top = 2 * top + bit;
        } else if (pos >= fbits - 106) {
            mid = 2 * mid + bit;
        } else {
            low = 2 * low + bit;
        }
    }
    tail = (double)mid * 1.232595164407831e-32 + (double)low * 1.3684555315672042e-48;
    f = (double)top * 1.1102230246251565e-16;
    if (f >= 0.5) { /* round to the nearest quadrant: f - 1 is exact (Sterbenz) */
        f -= 1.0;
        q += 1;
    }
    f += tail;
    *r = f * 1.5707963267948966 + f * 6.123233995736766e-17;
    return q & 3;
}""".replace("FZ_TWO_OVER_PI_WORDS", _two_over_pi_words()),
        ),
        _h(
            "fz_sincos",
            ("fz_rem_pio2_big",),
            False,
            """
/* sin and cos together: x = n pi/2 + r by a four-part Cody-Waite reduction below 2^19 (exact
   there), by fz_rem_pio2_big above; Taylor polynomials on |r| <= pi/4 (relative 1e-17),
   quadrant from n.  Accurate to a few ulp over the whole double range, like libm. */
static void fz_sincos(double x, double *sn, double *cs)
{
    double r, z, s, c;
    long long n;
    int q;
    if (!(x - x == 0.0)) { /* inf or NaN */
        *sn = *cs = x - x;
        return;
    }
    if (x >= 524288.0 || x <= -524288.0) {
        q = fz_rem_pio2_big(x >= 0.0 ? x : -x, &r);
        if (x < 0.0) { /* sin(-x) = -sin x: reflect the reduced argument and the quadrant */
            r = -r;
            q = (4 - q) & 3;
        }
        n = q;
    } else {
        n = (long long)(x * 6.36619772367581382433e-01 + (x >= 0.0 ? 0.5 : -0.5));
        r = x - (double)n * 1.57079632673412561417e+00;
        r = r - (double)n * 6.07710050630396597660e-11;
        r = r - (double)n * 2.02226624871116645580e-21;
        r = r - (double)n * 8.47842766036889956997e-32;
    }
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
