"""The proof machinery of the integer generators (``ir/builders/fixed_arith.py``) against
brute force: every stored value of small operands is pushed through the generated expression
with C's and Structured Text's integer semantics (division truncates toward zero), and the
result must lie in the stated interval and within the stated error of the exact rational
value."""

from __future__ import annotations

from fractions import Fraction

import pytest

from fuzzyctl.escape import CodegenError
from fuzzyctl.ir.builders import fixed_arith as fa
from fuzzyctl.ir.builders.fixed_arith import FX, Width
from fuzzyctl.ir.nodes import Bin, Call, Ex, Int, Neg, Var
from fuzzyctl.kinds import arith

W16 = Width(arith.get("int16"))


def _eval(e: Ex, env: dict[str, int]) -> int:
    """The value C computes (no overflow: the intervals prove there is none)."""
    if isinstance(e, Int):
        return e.value
    if isinstance(e, Var):
        return env[e.name]
    if isinstance(e, Call):
        return _eval(e.args[0], env)
    if isinstance(e, Neg):
        return -_eval(e.operand, env)
    assert isinstance(e, Bin), e
    a, b = _eval(e.left, env), _eval(e.right, env)
    if e.op == "+":
        return a + b
    if e.op == "-":
        return a - b
    if e.op == "*":
        return a * b
    assert e.op == "/"
    q = abs(a) // abs(b)
    return q if (a >= 0) == (b > 0) else -q


def _check(result: FX, exact: Fraction, env: dict[str, int]) -> None:
    got = _eval(result.ex, env)
    assert result.lo <= got <= result.hi
    lo, hi = W16.limits(result.wide)
    assert lo <= got <= hi
    assert abs(got * result.scale - exact) <= result.err, (got, exact, result.err)


@pytest.mark.parametrize("k", [2, 3, 16, 7, 1024])
@pytest.mark.parametrize("span", [(-50, 40), (0, 90), (-90, -3)])
def test_rounded_division_of_every_value(k: int, span: tuple[int, int]) -> None:
    """Negative dividends included: truncation toward zero must not break the bound."""
    x = FX(Var("x"), span[0], span[1], Fraction(1, 8), Fraction(0), False)
    r = fa.rdiv(W16, x, k)
    assert r.err <= Fraction(1, 2) * r.scale + Fraction(1, 2 * k) * r.scale
    for v in range(span[0], span[1] + 1):
        _check(r, Fraction(v, 8), {"x": v})


def test_products_sums_and_constants_of_every_value() -> None:
    a = FX(Var("a"), -40, 60, Fraction(1, 16), Fraction(0), False)
    b = FX(Var("b"), 0, 30, Fraction(1, 4), Fraction(0), False)
    c = fa.const(W16, Fraction(1, 3), Fraction(1, 64), wide=True)
    expr = fa.rdiv(W16, fa.add(W16, fa.mul(W16, a, b), c), 8)
    for va in range(-40, 61):
        for vb in range(0, 31, 3):
            exact = Fraction(va, 16) * Fraction(vb, 4) + Fraction(1, 3)
            _check(expr, exact, {"a": va, "b": vb})


def test_overflow_is_refused_not_wrapped() -> None:
    big = FX(Var("x"), -30000, 30000, Fraction(1), Fraction(0), False)
    with pytest.raises(CodegenError, match="outside the stored integer range"):
        fa.narrow(W16, fa.add(W16, big, big), "a sum")
    huge = fa.widen(FX(Var("y"), 0, 1 << 16, Fraction(1), Fraction(0), True))
    with pytest.raises(CodegenError, match="outside the wide integer range"):
        fa.mul(W16, huge, huge)
