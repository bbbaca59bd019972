"""Fixed-point values with their proof: the interval analysis and rounding-error bookkeeping
of the integer code generators (``codegen --arith int16|int32``).

A :class:`FX` is one integer expression of the generated code together with what is known
about it at generation time: the interval of the stored integer (every operation checks that
the interval fits its type, so the generated code cannot overflow), the scale (the real
value is ``stored * scale``) and a bound of the absolute error of that real value against
the exact (real-number) computation it stands for.  Every operation propagates both, so the
error bound of an output is derived from the rounding of each step, not measured.

Two integer types are used: *narrow* (the ``--arith`` width: stored values, degrees) and
*wide* (twice as wide: products and sums before they are rescaled).  Conversions are IR calls
``WIDEN`` / ``NARROW`` that the integer renderers spell (``INT_TO_DINT``, ``(int32_t)``).

Arithmetic at generation time is exact (:class:`fractions.Fraction`)."""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

from fuzzyctl.escape import CodegenError
from fuzzyctl.ir.nodes import Call, Ex, Int, Var
from fuzzyctl.kinds.arith import Arith

__all__ = ["FX", "Width", "add", "const", "fx_max", "fx_min", "mul", "narrow", "rdiv", "sub", "widen"]


@dataclass(frozen=True)
class Width:
    """The two integer types of one arithmetic: narrow (``bits``) and wide (``2 * bits``)."""

    arith: Arith

    @property
    def bits(self) -> int:
        return self.arith.bits

    def limits(self, wide: bool) -> tuple[int, int]:
        b = 2 * self.bits if wide else self.bits
        return -(1 << (b - 1)), (1 << (b - 1)) - 1

    def fits(self, lo: int, hi: int, wide: bool) -> bool:
        low, high = self.limits(wide)
        return low <= lo and hi <= high


@dataclass(frozen=True)
class FX:
    """An integer expression: ``ex`` (IR), stored interval ``[lo, hi]``, real value
    ``stored * scale`` within ``err`` of the exact value, ``wide`` its type."""

    ex: Ex
    lo: int
    hi: int
    scale: Fraction
    err: Fraction
    wide: bool

    @property
    def magnitude(self) -> Fraction:
        """A bound of the computed real value's magnitude."""
        return max(abs(self.lo), abs(self.hi)) * self.scale

    def value_interval(self) -> tuple[Fraction, Fraction]:
        """An interval holding the exact real value."""
        return self.lo * self.scale - self.err, self.hi * self.scale + self.err


def _check(w: Width, lo: int, hi: int, wide: bool, what: str) -> None:
    if not w.fits(lo, hi, wide):
        low, high = w.limits(wide)
        kind = "wide" if wide else "stored"
        raise CodegenError(
            f"--arith {w.arith.name}: {what} may reach {lo}..{hi}, outside the {kind} integer range "
            f"{low}..{high} (interval analysis): the system cannot be computed without overflow"
        )


def const(w: Width, value: Fraction, scale: Fraction, wide: bool = False, what: str = "a constant") -> FX:
    """``value`` rounded to the nearest multiple of ``scale``."""
    n = round(value / scale)
    _check(w, n, n, wide, what)
    return FX(Int(n), n, n, scale, abs(n * scale - value), wide)


def var(name: str, like: FX) -> FX:
    """``like`` stored in the variable ``name`` (same interval, scale, error, type)."""
    return FX(Var(name), like.lo, like.hi, like.scale, like.err, like.wide)


def widen(x: FX) -> FX:
    if x.wide:
        return x
    ex = Int(x.ex.value) if isinstance(x.ex, Int) else Call("WIDEN", (x.ex,))
    return FX(ex, x.lo, x.hi, x.scale, x.err, True)


def narrow(w: Width, x: FX, what: str) -> FX:
    if not x.wide:
        return x
    _check(w, x.lo, x.hi, False, what)
    ex = Int(x.ex.value) if isinstance(x.ex, Int) else Call("NARROW", (x.ex,))
    return FX(ex, x.lo, x.hi, x.scale, x.err, False)


def _pair(w: Width, a: FX, b: FX, lo: int, hi: int) -> tuple[FX, FX, bool]:
    """Both operands in one type: the narrow one when the result fits it, else the wide."""
    if not a.wide and not b.wide and w.fits(lo, hi, False):
        return a, b, False
    return widen(a), widen(b), True


def add(w: Width, a: FX, b: FX, what: str = "a sum") -> FX:
    assert a.scale == b.scale, (a.scale, b.scale)
    lo, hi = a.lo + b.lo, a.hi + b.hi
    a, b, wide = _pair(w, a, b, lo, hi)
    _check(w, lo, hi, wide, what)
    if isinstance(a.ex, Int) and isinstance(b.ex, Int):  # folded, as in mul
        return FX(Int(lo), lo, hi, a.scale, a.err + b.err, wide)
    return FX(a.ex + b.ex, lo, hi, a.scale, a.err + b.err, wide)


def sub(w: Width, a: FX, b: FX, what: str = "a difference") -> FX:
    assert a.scale == b.scale, (a.scale, b.scale)
    lo, hi = a.lo - b.hi, a.hi - b.lo
    a, b, wide = _pair(w, a, b, lo, hi)
    _check(w, lo, hi, wide, what)
    if isinstance(a.ex, Int) and isinstance(b.ex, Int):  # folded, as in mul
        return FX(Int(lo), lo, hi, a.scale, a.err + b.err, wide)
    return FX(a.ex - b.ex, lo, hi, a.scale, a.err + b.err, wide)


def mul(w: Width, a: FX, b: FX, what: str = "a product") -> FX:
    """The product, always in the wide type."""
    ends = [a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi]
    lo, hi = min(ends), max(ends)
    _check(w, lo, hi, True, what)
    # |ab - a'b'| <= |a| eb + |b'| ea with |a| <= |a'| + ea
    err = (a.magnitude + a.err) * b.err + b.magnitude * a.err
    a, b = widen(a), widen(b)
    if isinstance(a.ex, Int) and isinstance(b.ex, Int):
        # folded here: a product of two literals would be computed in C's int and overflow
        return FX(Int(lo), lo, hi, a.scale * b.scale, err, True)
    return FX(a.ex * b.ex, lo, hi, a.scale * b.scale, err, True)


def _trunc_div(n: int, k: int) -> int:
    """C's and Structured Text's integer division (toward zero)."""
    q = abs(n) // abs(k)
    return q if (n >= 0) == (k > 0) else -q


def rdiv(w: Width, x: FX, k: int, what: str = "a rescaled value") -> FX:
    """``x / k`` rounded to nearest (``k`` > 0): the scale grows by ``k``.  Integer division
    truncates toward zero in C and Structured Text, so a dividend that may be negative is
    first shifted by a multiple of ``k`` that makes it non-negative (the floor, then the
    multiple taken back): the rounding adds at most half a unit of the new scale.  When
    the shifted dividend would not fit, truncation stays and the bound is one and a half."""
    assert k > 0
    if k == 1:
        return x
    half = k // 2
    _check(w, k, k, x.wide, "a divisor")
    nearest = Fraction(1, 2) + (Fraction(1, 2 * k) if k % 2 else 0)
    scale, wide = x.scale * k, x.wide
    if isinstance(x.ex, Int):  # a constant: divided here, exactly as the target would
        q = _trunc_div(x.lo + half, k)
        _check(w, q, q, wide, what)
        return FX(Int(q), q, q, scale, x.err + abs(q * scale - x.lo * x.scale), wide)
    m = 0 if x.lo + half >= 0 else -((x.lo + half) // k)
    if w.fits(x.lo + half + m * k, x.hi + half + m * k, wide):
        lo, hi = (x.lo + half) // k, (x.hi + half) // k
        ex = (x.ex + (half + m * k)) / Int(k)
        rounding = nearest
        if m:
            ex = ex - m
    else:
        _check(w, x.lo + half, x.hi + half, wide, what)
        lo, hi = _trunc_div(x.lo + half, k), _trunc_div(x.hi + half, k)
        ex = (x.ex + half) / Int(k)
        rounding = Fraction(3, 2)
    _check(w, lo, hi, wide, what)
    return FX(ex, lo, hi, scale, x.err + rounding * scale, wide)


def fx_min(a: FX, b: FX) -> tuple[int, int, Fraction]:
    """Interval and error of min(a, b) (min is 1-Lipschitz in each operand)."""
    return min(a.lo, b.lo), min(a.hi, b.hi), max(a.err, b.err)


def fx_max(a: FX, b: FX) -> tuple[int, int, Fraction]:
    return max(a.lo, b.lo), max(a.hi, b.hi), max(a.err, b.err)
