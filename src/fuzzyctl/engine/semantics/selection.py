"""fuzzylite's rule activation methods: which rules of a rule block fire, and with which degree.

IEC 61131-7 fires every rule.  fuzzylite lets a rule block choose (``activation: Highest 2``
in FLL, model :attr:`fuzzyctl.model.RuleBlock.rule_activation`); the lowering turns that text
into a :class:`~fuzzyctl.engine.plan.SelectionPlan` with :func:`parse`, and every evaluator
applies it with :func:`select` (one sample) or :func:`select_np` (columns of samples) to the
block's rule degrees (each rule's weight already applied), as fuzzylite 6 and pyfuzzylite 8
do:

* ``First [n [t]]`` / ``Last [n [t]]``: the first / last ``n`` rules (default 1) in block
  order whose degree is > 0 and >= ``t`` (default 0).
* ``Highest [n]`` / ``Lowest [n]``: the ``n`` rules (default 1) with the highest / lowest
  degree > 0; among equal degrees the earlier rule (pyfuzzylite; fuzzylite C++ leaves it to
  its priority queue).
* ``Proportional``: every degree divided by the sum of the block's degrees.
* ``Threshold <op> t``: the rules whose degree ``<op>`` t holds, ``<op>`` one of
  ``< <= == != >= >`` (exact comparisons).

A rule that is not selected has degree 0.  ``General`` (every rule fires) is no selection.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from fuzzyctl.engine.plan import SelectionPlan
from fuzzyctl.engine.semantics.operators import fsum

Arr = npt.NDArray[np.float64]

COMPARISONS: dict[str, Callable[[Any, Any], Any]] = {
    "<": operator.lt,
    "<=": operator.le,
    "==": operator.eq,
    "!=": operator.ne,
    ">=": operator.ge,
    ">": operator.gt,
}
METHODS = ("GENERAL", "FIRST", "LAST", "HIGHEST", "LOWEST", "PROPORTIONAL", "THRESHOLD")


def parse(text: str, rules: tuple[int, ...]) -> SelectionPlan | None:
    """The selection ``text`` describes (``"Highest 2"``), None for ``General``; raises
    ``ValueError`` with a message for anything else."""
    words = text.split()
    if not words:
        return None
    name, args = words[0].upper(), words[1:]
    if name == "GENERAL" and not args:
        return None
    if name not in METHODS:
        raise ValueError(
            f"unknown rule activation {words[0]!r} (known: General, First, Last, Highest, Lowest, "
            "Proportional, Threshold)"
        )
    if name in ("FIRST", "LAST"):
        if len(args) > 2:
            raise ValueError(f"{words[0]} takes a number of rules and a threshold, got {' '.join(args)!r}")
        count = _count(args[0]) if args else 1
        threshold = _number(args[1]) if len(args) > 1 else 0.0
        return SelectionPlan(name, rules, count, threshold)
    if name in ("HIGHEST", "LOWEST"):
        if len(args) > 1:
            raise ValueError(f"{words[0]} takes a number of rules, got {' '.join(args)!r}")
        return SelectionPlan(name, rules, _count(args[0]) if args else 1)
    if name == "PROPORTIONAL":
        if args:
            raise ValueError(f"Proportional takes no parameters, got {' '.join(args)!r}")
        return SelectionPlan(name, rules)
    if len(args) != 2 or args[0] not in COMPARISONS:
        raise ValueError(
            f"Threshold needs a comparison ({' '.join(COMPARISONS)}) and a value, got {' '.join(args)!r}"
        )
    return SelectionPlan(name, rules, threshold=_number(args[1]), comparison=args[0])


def _count(word: str) -> int:
    try:
        value = float(word)
    except ValueError:
        raise ValueError(f"the number of rules must be a number, got {word!r}") from None
    if not (value >= 0 and value == int(value)):
        raise ValueError(f"the number of rules must be a whole number >= 0, got {word!r}")
    return int(value)


def _number(word: str) -> float:
    try:
        value = float(word)
    except ValueError:
        raise ValueError(f"the threshold must be a number, got {word!r}") from None
    if not math.isfinite(value):
        raise ValueError(f"the threshold must be finite, got {word!r}")
    return value


def select(sel: SelectionPlan, degrees: Sequence[float]) -> list[float]:
    """The degrees of the block's rules after the selection (one sample)."""
    k = len(degrees)
    out = [0.0] * k
    if sel.method in ("FIRST", "LAST"):
        order = range(k) if sel.method == "FIRST" else range(k - 1, -1, -1)
        taken = 0
        for j in order:
            a = degrees[j]
            if taken < sel.count and a > 0.0 and a >= sel.threshold:
                out[j] = a
                taken += 1
        return out
    if sel.method in ("HIGHEST", "LOWEST"):
        sign = -1.0 if sel.method == "HIGHEST" else 1.0
        ranked = sorted((sign * a, j) for j, a in enumerate(degrees) if a > 0.0)
        for _key, j in ranked[: sel.count]:
            out[j] = degrees[j]
        return out
    if sel.method == "PROPORTIONAL":
        total = fsum(a for a in degrees if a > 0.0)
        return [a / total if total > 0.0 and a > 0.0 else 0.0 for a in degrees]
    compare = COMPARISONS[sel.comparison]
    return [a if compare(a, sel.threshold) else 0.0 for a in degrees]


def select_np(sel: SelectionPlan, degrees: Arr) -> Arr:
    """:func:`select` on a ``(samples, rules)`` array."""
    d = np.asarray(degrees, dtype=np.float64)
    n, k = d.shape
    positive = d > 0.0
    if sel.method in ("FIRST", "LAST"):
        eligible = positive & (d >= sel.threshold)
        ranks = np.cumsum(eligible if sel.method == "FIRST" else eligible[:, ::-1], axis=1)
        if sel.method == "LAST":
            ranks = ranks[:, ::-1]
        return np.where(eligible & (ranks <= sel.count), d, 0.0)
    if sel.method in ("HIGHEST", "LOWEST"):
        key = -d if sel.method == "HIGHEST" else np.where(positive, d, np.inf)
        order = np.argsort(key, axis=1, kind="stable")  # stable: earlier rules first on ties
        rank = np.empty_like(order)
        rank[np.arange(n)[:, None], order] = np.arange(k)[None, :]
        return np.where(positive & (rank < sel.count), d, 0.0)
    if sel.method == "PROPORTIONAL":
        pos = np.where(positive, d, 0.0)
        total = pos.sum(axis=1, keepdims=True)
        with np.errstate(all="ignore"):
            return np.where(total > 0.0, pos / total, 0.0)
    mask = COMPARISONS[sel.comparison](d, sel.threshold)
    return np.where(mask, d, 0.0)


__all__ = ["COMPARISONS", "METHODS", "parse", "select", "select_np"]
