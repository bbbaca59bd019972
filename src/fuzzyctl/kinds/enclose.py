"""Rigorous enclosures of a formula (:mod:`fuzzyctl.kinds.formula`) over intervals of its
first argument, with an enclosure of its derivative (forward-mode differentiation on
intervals), evaluated on numpy arrays of intervals at once.

Every operation rounds its ends outward (one float step for ``+ - * /`` and ``sqrt``, which
IEEE rounds correctly; four for ``exp``, ``log``, ``cos`` and ``pow``, which the C library
computes to within one or two), so the enclosure holds the real-number value and also the
value the float forms of the formula compute from arguments inside the intervals.  A NaN or
an operation whose result cannot be bounded (a division by an interval holding 0, ``log`` or
``sqrt`` reaching below 0) gives the whole line, which no bound accepts.

A conditional whose test is undecided on an interval gives the hull of both branches and an
unbounded derivative (the formula may jump there); ``abs``, ``min`` and ``max`` keep a
bounded derivative (they are Lipschitz: the mean value inclusion holds with the hull of
their one-sided derivatives)."""

from __future__ import annotations

import ast
import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from fuzzyctl.kinds import formula as fm

__all__ = ["Enclosure", "enclose"]

Arr = npt.NDArray[np.float64]
Bools = npt.NDArray[np.bool_]
_INF = math.inf


@dataclass(frozen=True)
class Enclosure:
    """``[lo, hi]`` holds the value, ``[dlo, dhi]`` the derivative in the first argument."""

    lo: Arr
    hi: Arr
    dlo: Arr
    dhi: Arr


@dataclass(frozen=True)
class _Test:
    """A test on intervals: where it may hold, where it may fail."""

    may: Bools
    may_not: Bools


def _down(a: Arr, steps: int = 1) -> Arr:
    for _ in range(steps):
        a = np.nextafter(a, -_INF)
    return a


def _up(a: Arr, steps: int = 1) -> Arr:
    for _ in range(steps):
        a = np.nextafter(a, _INF)
    return a


def _clean(lo: Arr, hi: Arr) -> tuple[Arr, Arr]:
    """NaN ends become the whole line."""
    return np.where(np.isnan(lo), -_INF, lo), np.where(np.isnan(hi), _INF, hi)


def _iv(lo: Arr, hi: Arr, dlo: Arr, dhi: Arr, steps: int = 1) -> Enclosure:
    lo, hi = _clean(_down(lo, steps), _up(hi, steps))
    # a derivative computed as exactly 0 is a constant's (0 * x and 0 + 0 are exact; an
    # underflow to 0 is below 5e-324, far inside the margin the callers add)
    dlo, dhi = _clean(np.where(dlo == 0, 0.0, _down(dlo)), np.where(dhi == 0, 0.0, _up(dhi)))
    return Enclosure(lo, hi, dlo, dhi)


def _two_sum(a: Arr, b: Arr) -> tuple[Arr, Arr]:
    """``a + b`` rounded and its exact rounding error (Knuth's TwoSum)."""
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


def _sum_down(a: Arr, b: Arr) -> Arr:
    """A float not above the real ``a + b`` (the rounded sum when it is exact)."""
    with np.errstate(invalid="ignore"):
        s, err = _two_sum(a, b)
    return np.where(err < 0, _down(s), np.where(np.isnan(err), _down(s), s))


def _sum_up(a: Arr, b: Arr) -> Arr:
    with np.errstate(invalid="ignore"):
        s, err = _two_sum(a, b)
    return np.where(err > 0, _up(s), np.where(np.isnan(err), _up(s), s))


def _point(v: float, n: int) -> Enclosure:
    a = np.full(n, v)
    z = np.zeros(n)
    return Enclosure(a, a, z, z)


def _mul(alo: Arr, ahi: Arr, blo: Arr, bhi: Arr) -> tuple[Arr, Arr]:
    ps = np.stack([alo * blo, alo * bhi, ahi * blo, ahi * bhi])
    # 0 * inf is NaN: the product is then unbounded
    return _clean(np.min(ps, axis=0), np.max(ps, axis=0))


def _recip(lo: Arr, hi: Arr) -> tuple[Arr, Arr]:
    zero = (lo <= 0) & (hi >= 0)
    with np.errstate(divide="ignore"):
        rlo, rhi = 1.0 / hi, 1.0 / lo
    return np.where(zero, -_INF, rlo), np.where(zero, _INF, rhi)


def _cos_range(lo: Arr, hi: Arr) -> tuple[Arr, Arr]:
    """The range of ``cos`` on ``[lo, hi]``: its ends, 1 where a multiple of 2 pi lies inside,
    -1 where an odd multiple of pi does (the multiples found with a margin: more extremes
    counted is only looser)."""
    with np.errstate(invalid="ignore"):
        a, b = np.cos(lo), np.cos(hi)
        k0 = np.ceil(lo / math.pi - 1e-9)
        k1 = np.floor(hi / math.pi + 1e-9)
    has = k1 >= k0
    even = has & ((k1 - k0 >= 1) | (np.mod(k0, 2) == 0))
    odd = has & ((k1 - k0 >= 1) | (np.mod(k0, 2) == 1))
    rlo = np.where(odd, -1.0, np.minimum(a, b))
    rhi = np.where(even, 1.0, np.maximum(a, b))
    wide = ~np.isfinite(lo) | ~np.isfinite(hi) | (hi - lo >= 2 * math.pi)
    return np.where(wide, -1.0, rlo), np.where(wide, 1.0, rhi)


class _Eval:
    def __init__(self, helpers: Mapping[str, fm.Formula], n: int) -> None:
        self.helpers = helpers
        self.n = n

    def formula(self, f: fm.Formula, args: list[Enclosure]) -> Enclosure:
        env = dict(zip(f.args, args, strict=True))
        for name, node in f.lets:
            env[name] = self.ex(node, env)
        return self.ex(f.body, env)

    def ex(self, e: ast.expr, env: dict[str, Enclosure]) -> Enclosure:
        n = self.n
        if isinstance(e, ast.Constant):
            return _point(float(e.value), n)  # type: ignore[arg-type]
        if isinstance(e, ast.Name):
            if e.id in env:
                return env[e.id]
            if e.id == "pi":
                z = np.zeros(n)
                return Enclosure(_down(np.full(n, math.pi)), _up(np.full(n, math.pi)), z, z)
            return _iv(np.full(n, -_INF), np.full(n, _INF), np.full(n, -_INF), np.full(n, _INF))
        if isinstance(e, ast.NamedExpr):
            v = self.ex(e.value, env)
            env[e.target.id] = v
            return v
        if isinstance(e, ast.UnaryOp):
            a = self.ex(e.operand, env)
            return Enclosure(-a.hi, -a.lo, -a.dhi, -a.dlo)
        if isinstance(e, ast.BinOp):
            return self.binop(e.op, self.ex(e.left, env), self.ex(e.right, env))
        if isinstance(e, ast.IfExp):
            t = self.test(e.test, env)
            a = self.ex(e.body, _narrowed(e.test, env, True))
            b = self.ex(e.orelse, _narrowed(e.test, env, False))
            only_a, only_b = t.may & ~t.may_not, t.may_not & ~t.may
            lo = np.where(only_a, a.lo, np.where(only_b, b.lo, np.minimum(a.lo, b.lo)))
            hi = np.where(only_a, a.hi, np.where(only_b, b.hi, np.maximum(a.hi, b.hi)))
            dlo = np.where(only_a, a.dlo, np.where(only_b, b.dlo, -_INF))
            dhi = np.where(only_a, a.dhi, np.where(only_b, b.dhi, _INF))
            return Enclosure(lo, hi, dlo, dhi)
        if isinstance(e, ast.Call):
            assert isinstance(e.func, ast.Name)
            args = [self.ex(a, env) for a in e.args]
            if e.func.id in self.helpers:
                return self.formula(self.helpers[e.func.id], args)
            return self.call(e.func.id, args)
        raise fm.FormulaError(f"{ast.unparse(e)!r}: no interval form")

    def binop(self, op: ast.operator, a: Enclosure, b: Enclosure) -> Enclosure:
        if isinstance(op, ast.Add | ast.Sub):
            sub = isinstance(op, ast.Sub)
            blo, bhi = (-b.hi, -b.lo) if sub else (b.lo, b.hi)
            dlo, dhi = (-b.dhi, -b.dlo) if sub else (b.dlo, b.dhi)
            lo, hi = _sum_down(a.lo, blo), _sum_up(a.hi, bhi)
            d = _iv(lo, hi, a.dlo + dlo, a.dhi + dhi, steps=0)
            return d
        if isinstance(op, ast.Mult):
            lo, hi = _mul(a.lo, a.hi, b.lo, b.hi)
            d1 = _mul(a.dlo, a.dhi, b.lo, b.hi)
            d2 = _mul(a.lo, a.hi, b.dlo, b.dhi)
            return _iv(lo, hi, d1[0] + d2[0], d1[1] + d2[1])
        assert isinstance(op, ast.Div), op
        rlo, rhi = _recip(b.lo, b.hi)
        rlo, rhi = _down(rlo), _up(rhi)
        lo, hi = _mul(a.lo, a.hi, rlo, rhi)
        # (a / b)' = a' / b - (a / b) b' / b
        d1 = _mul(a.dlo, a.dhi, rlo, rhi)
        q = _mul(lo, hi, b.dlo, b.dhi)
        d2 = _mul(q[0], q[1], rlo, rhi)
        out = _iv(lo, hi, d1[0] - d2[1], d1[1] - d2[0], steps=2)
        # 0 / b is exactly 0 where b excludes 0
        zero = (a.lo == 0) & (a.hi == 0) & ((b.lo > 0) | (b.hi < 0))
        return Enclosure(np.where(zero, 0.0, out.lo), np.where(zero, 0.0, out.hi), out.dlo, out.dhi)

    def call(self, name: str, args: list[Enclosure]) -> Enclosure:
        a = args[0]
        with np.errstate(all="ignore"):
            if name == "exp":
                lo, hi = np.exp(a.lo), np.exp(a.hi)
                d = _mul(lo, hi, a.dlo, a.dhi)
                return _iv(lo, hi, d[0], d[1], steps=4)
            if name == "log":
                bad = a.lo <= 0
                lo, hi = np.where(bad, -_INF, np.log(np.maximum(a.lo, 1e-300))), np.log(a.hi)
                r = _recip(a.lo, a.hi)
                d = _mul(a.dlo, a.dhi, r[0], r[1])
                return _iv(lo, hi, d[0], d[1], steps=4)
            if name == "sqrt":
                bad = a.lo < 0
                lo = np.where(bad, -_INF, np.sqrt(np.maximum(a.lo, 0.0)))
                hi = np.where(bad, _INF, np.sqrt(a.hi))
                r = _recip(2 * lo, 2 * hi)
                d = _mul(a.dlo, a.dhi, r[0], r[1])
                return _iv(lo, hi, d[0], d[1])
            if name == "cos":
                lo, hi = _cos_range(a.lo, a.hi)
                s = _cos_range(a.lo - math.pi / 2, a.hi - math.pi / 2)  # sin, with a margin below
                s = (np.maximum(_down(s[0], 4) - 1e-15, -1.0), np.minimum(_up(s[1], 4) + 1e-15, 1.0))
                d = _mul(-s[1], -s[0], a.dlo, a.dhi)
                return _iv(lo, hi, d[0], d[1], steps=4)
            if name == "abs":
                pos, neg = a.lo >= 0, a.hi <= 0
                lo = np.where(pos, a.lo, np.where(neg, -a.hi, 0.0))
                hi = np.maximum(np.abs(a.lo), np.abs(a.hi))
                both = (np.minimum(a.dlo, -a.dhi), np.maximum(a.dhi, -a.dlo))
                dlo = np.where(pos, a.dlo, np.where(neg, -a.dhi, both[0]))
                dhi = np.where(pos, a.dhi, np.where(neg, -a.dlo, both[1]))
                return Enclosure(lo, hi, dlo, dhi)
            if name in ("min", "max"):
                return self.minmax(name == "min", a, args[1])
            if name == "pow":
                return self.power(a, args[1])
        whole = np.full(self.n, _INF)
        return Enclosure(-whole, whole, -whole, whole)  # isnan and the like: not enclosed

    def minmax(self, is_min: bool, a: Enclosure, b: Enclosure) -> Enclosure:
        pick = np.minimum if is_min else np.maximum
        a_only = (a.hi <= b.lo) if is_min else (a.lo >= b.hi)
        b_only = (b.hi <= a.lo) if is_min else (b.lo >= a.hi)
        dlo = np.where(a_only, a.dlo, np.where(b_only, b.dlo, np.minimum(a.dlo, b.dlo)))
        dhi = np.where(a_only, a.dhi, np.where(b_only, b.dhi, np.maximum(a.dhi, b.dhi)))
        return Enclosure(pick(a.lo, b.lo), pick(a.hi, b.hi), dlo, dhi)

    def power(self, a: Enclosure, b: Enclosure) -> Enclosure:
        """``a ** b`` for a base >= 0 and an exponent that does not depend on ``x`` (else
        unbounded): ``a ** b`` is monotone in each, so its extremes are at the corners."""
        ok = (a.lo >= 0) & (b.dlo == 0) & (b.dhi == 0)

        def corners(e_lo: Arr, e_hi: Arr) -> tuple[Arr, Arr]:
            ps = np.stack(
                [np.power(a.lo, e_lo), np.power(a.lo, e_hi), np.power(a.hi, e_lo), np.power(a.hi, e_hi)]
            )
            return _clean(_down(np.min(ps, axis=0), 4), _up(np.max(ps, axis=0), 4))

        lo, hi = corners(b.lo, b.hi)
        # d/dx a^b = b a^(b - 1) a'
        q = corners(_down(b.lo - 1), _up(b.hi - 1))
        q = _mul(q[0], q[1], b.lo, b.hi)
        d = _mul(q[0], q[1], a.dlo, a.dhi)
        out = _iv(lo, hi, d[0], d[1])
        return Enclosure(
            np.where(ok, out.lo, -_INF),
            np.where(ok, out.hi, _INF),
            np.where(ok, out.dlo, -_INF),
            np.where(ok, out.dhi, _INF),
        )

    def test(self, e: ast.expr, env: dict[str, Enclosure]) -> _Test:
        if isinstance(e, ast.BoolOp):
            parts = [self.test(v, env) for v in e.values]
            may, may_not = parts[0].may, parts[0].may_not
            for p in parts[1:]:
                if isinstance(e.op, ast.And):
                    may, may_not = may & p.may, may_not | p.may_not
                else:
                    may, may_not = may | p.may, may_not & p.may_not
            return _Test(may, may_not)
        if isinstance(e, ast.Compare):
            left = self.ex(e.left, env)
            may = np.ones(self.n, dtype=bool)
            may_not = np.zeros(self.n, dtype=bool)
            for op, right_e in zip(e.ops, e.comparators, strict=True):
                right = self.ex(right_e, env)
                t = _compare(op, left, right)
                may, may_not = may & t.may, may_not | t.may_not
                left = right
            return _Test(may, may_not)
        raise fm.FormulaError(f"{ast.unparse(e)!r}: no interval form of this test")


def _narrowed(test: ast.expr, env: dict[str, Enclosure], holds: bool) -> dict[str, Enclosure]:
    """``env`` with a name compared to a constant narrowed to the values where ``test``
    is ``holds`` (a branch is only taken there: its enclosure may assume it)."""
    if not (
        isinstance(test, ast.Compare) and len(test.ops) == 1 and isinstance(test.comparators[0], ast.Constant)
    ):
        return dict(env)
    left = test.left.target if isinstance(test.left, ast.NamedExpr) else test.left
    if not isinstance(left, ast.Name) or left.id not in env:
        return dict(env)
    v, op = env[left.id], test.ops[0]
    c = float(test.comparators[0].value)  # type: ignore[arg-type]
    lo, hi = v.lo, v.hi
    upper = isinstance(op, ast.Lt | ast.LtE) if holds else isinstance(op, ast.Gt | ast.GtE)
    lower = isinstance(op, ast.Gt | ast.GtE) if holds else isinstance(op, ast.Lt | ast.LtE)
    if upper:
        hi = np.minimum(hi, c)
    elif lower:
        lo = np.maximum(lo, c)
    elif isinstance(op, ast.Eq) and holds:
        lo, hi = np.maximum(lo, c), np.minimum(hi, c)
    # where the branch cannot be taken the narrowed interval is empty: its value is dropped
    return {**env, left.id: Enclosure(np.minimum(lo, hi), hi, v.dlo, v.dhi)}


def _compare(op: ast.cmpop, a: Enclosure, b: Enclosure) -> _Test:
    if isinstance(op, ast.Gt | ast.GtE):
        a, b = b, a
        op = ast.Lt() if isinstance(op, ast.Gt) else ast.LtE()
    if isinstance(op, ast.Lt):
        return _Test(a.lo < b.hi, a.hi >= b.lo)
    if isinstance(op, ast.LtE):
        return _Test(a.lo <= b.hi, a.hi > b.lo)
    meet = (a.lo <= b.hi) & (b.lo <= a.hi)
    exact = (a.lo == a.hi) & (b.lo == b.hi) & (a.lo == b.lo)
    if isinstance(op, ast.Eq):
        return _Test(meet, ~exact)
    assert isinstance(op, ast.NotEq), op
    return _Test(~exact, meet)


def enclose(
    f: fm.Formula, helpers: Mapping[str, fm.Formula], lo: Arr, hi: Arr, params: tuple[float, ...]
) -> Enclosure:
    """Enclosures of ``f(x, *params)`` and of its derivative in ``x`` for ``x`` in each
    ``[lo[i], hi[i]]``."""
    n = len(lo)
    ev = _Eval(helpers, n)
    one, zero = np.ones(n), np.zeros(n)
    x = Enclosure(np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64), one, one)
    args = [x] + [Enclosure(np.full(n, p), np.full(n, p), zero, zero) for p in params]
    with np.errstate(all="ignore"):
        return ev.formula(f, args)
