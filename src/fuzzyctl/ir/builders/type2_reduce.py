"""Type reduction in the IR: the centroid interval ``[yl, yr]`` of ``n`` points ``X`` (sorted
ascending) with weights between ``L`` and ``U``, by each method of
:mod:`fuzzyctl.kinds.type_reduction`, with a bounded number of steps (the IR twin of
:mod:`fuzzyctl.engine.type_reduction`, which it is tested against).

Bounds (what a PLC's cycle time needs; :func:`iterations` states them):

* KM and EKM: at most ``n + 2`` iterations of ``O(n)`` each (Karnik-Mendel converges in at
  most ``n``; the two more absorb a last rounding step, as the engine does).  EKM is KM
  started from EKM's switch points ``n/2.4`` and ``n/1.7`` (the sums are recomputed at each
  step rather than updated: the same end points, the same bound).
* IASC and EIASC: one scan of ``n`` steps per end point.

The arrays may be constant tables (Mamdani samples) or temporaries (Sugeno points); every
array index is a constant or a loop counter, so the numpy renderer if-converts the
iterations (a loop whose end differs between rows runs until every row is done).
"""

from __future__ import annotations

from dataclasses import dataclass

from fuzzyctl.ir.nodes import Ex, Index, Var, not_
from fuzzyctl.ir.state import Gen


@dataclass(frozen=True)
class Points:
    """``X``, ``L``, ``U`` of ``n`` points, ``X`` ascending."""

    x: Var
    lower: Var
    upper: Var
    n: int


def iterations(method: str, n: int) -> int:
    """The most iterations of the type reduction of ``n`` points, per end point (each
    iteration is ``O(n)`` for KM/EKM, ``O(1)`` for the IASC scans)."""
    return n + 2 if method in ("KM", "EKM") else n


def reduce(g: Gen, method: str, p: Points) -> tuple[Var, Var]:
    """``(yl, yr)`` by ``method``; the caller makes sure some upper weight is positive."""
    if method in ("KM", "EKM"):
        return _km(g, p, True, method == "EKM"), _km(g, p, False, method == "EKM")
    early = method == "EIASC"
    return _scan(g, p, True, early), _scan(g, p, False, early)


def _mean(g: Gen, p: Points, weight: object, hint: str) -> tuple[Var, Var]:
    """``sum(X w)`` and ``sum(w)`` for ``w = weight(k)`` (a function of the index)."""
    num, den = g.let(0.0, f"{hint}N"), g.let(0.0, f"{hint}D")
    with g.b.for_(g.counter("K"), 0, p.n - 1) as k:
        w = g.let(weight(k), f"{hint}W")  # type: ignore[operator]
        g.b.set(num, num + p.x[k] * w)
        g.b.set(den, den + w)
    return num, den


def _km(g: Gen, p: Points, low_end: bool, enhanced: bool) -> Var:
    """One end point by Karnik-Mendel: ``y`` from a start, then repeatedly the mean with the
    points at or left of ``y`` at one bound and the rest at the other, until it stays."""
    b = g.b
    first, rest = (p.upper, p.lower) if low_end else (p.lower, p.upper)
    hint = "YL" if low_end else "YR"
    y = g.temp(hint=hint)
    if enhanced:  # EKM's start: the switch point n/2.4 (yl) or n/1.7 (yr)
        k0 = max(1, min(p.n - 1, round(p.n / 2.4 if low_end else p.n / 1.7)))
        num, den = _mean(g, p, lambda k: _pick(g, k.lt(k0), first[k], rest[k]), "E")
        with b.if_(den.gt(0.0)):
            b.set(y, num / den)
        with b.else_():
            _midpoint(g, p, y)
    else:
        _midpoint(g, p, y)
    done = g.let(False, "DONE", "BOOL")
    steps = g.let(0, "IT", "INT")
    bound = iterations("KM", p.n)
    with b.while_(not_(done), bound=bound):
        num, den = _mean(g, p, lambda k: _pick(g, p.x[k].le(y), first[k], rest[k]), "S")
        with b.if_(den.gt(0.0)):
            nxt = g.let(num / den, "YN")
            with b.if_(nxt.eq(y)):
                b.set(done, True)
            b.set(y, nxt)
        with b.else_():  # every weight on this side zero: keep the estimate
            b.set(done, True)
        b.set(steps, steps + 1)
        with b.if_(steps.ge(bound)):
            b.set(done, True)
    return y


def _midpoint(g: Gen, p: Points, y: Var) -> None:
    """KM's start: the mean with the interval midpoints as weights."""
    num, den = _mean(g, p, lambda k: (p.lower[k] + p.upper[k]) / 2.0, "M")
    with g.b.if_(den.gt(0.0)):
        g.b.set(y, num / den)
    with g.b.else_():
        g.b.set(y, 0.0)


def _pick(g: Gen, cond: Ex, a: Index, b: Index) -> Var:
    t = g.temp(hint="PW")
    with g.b.if_(cond):
        g.b.set(t, a)
    with g.b.else_():
        g.b.set(t, b)
    return t


def _scan(g: Gen, p: Points, low_end: bool, early: bool) -> Var:
    """One end point by IASC (``early`` False: until the mean stops improving) or EIASC
    (``early``: until the mean passes the next point): start from every point at its lower
    weight and move the points to their upper weight one by one from the end (``yl``: the
    left, ``yr``: the right)."""
    b = g.b
    num, den = _mean(g, p, lambda k: p.lower[k], "I")
    best = g.temp(hint="YL" if low_end else "YR")
    have = g.let(den.gt(0.0), "HAVE", "BOOL")
    with b.if_(have):
        b.set(best, num / den)
    with b.else_():
        b.set(best, 0.0)
    done = g.let(False, "DONE", "BOOL")
    start, stop, step = (0, p.n - 1, 1) if low_end else (p.n - 1, 0, -1)
    with b.for_(g.counter("K"), start, stop, step) as k, b.if_(not_(done)):
        d = g.let(p.upper[k] - p.lower[k], "D")
        b.set(num, num + p.x[k] * d)
        b.set(den, den + d)
        with b.if_(den.gt(0.0)):
            y = g.let(num / den, "Y")
            better = y.lt(best) if low_end else y.gt(best)
            if early:  # the new mean is the best so far; stop when it passes the next point
                with b.if_(not_(have).or_(better)):
                    b.set(best, y)
                b.set(have, True)
                inside, nxt = (k.lt(p.n - 1), k + 1) if low_end else (k.gt(0), k - 1)
                # nested: Structured Text has no short-circuit AND (X[n] does not exist)
                with b.if_(inside), b.if_(y.le(p.x[nxt]) if low_end else y.ge(p.x[nxt])):
                    b.set(done, True)
            else:  # the mean got worse: the best is behind
                worse = y.gt(best) if low_end else y.lt(best)
                with b.if_(have.and_(worse)):
                    b.set(done, True)
                with b.else_():
                    with b.if_(not_(have).or_(better)):
                        b.set(best, y)
                    b.set(have, True)
    return best


__all__ = ["Points", "iterations", "reduce"]
