"""Inputs outside their declared RANGE, checked where values enter a controller.

IEC 61131-7 leaves a value outside the RANGE to the terms (the outer shoulders hold, a
triangle gives 0): the engine computes exactly that, and these checks never change the
numbers unless asked to.  What they add is a word about it, as MATLAB's ``evalfis`` does:

- ``"warn"`` (the default): the result as computed, and an :class:`InputRangeWarning`;
- ``"clamp"``: the value is limited to the RANGE first (what a PLC block's input limiter does);
- ``"raise"``: an :class:`~fuzzyctl.diagnostics.InputError` naming the input and its RANGE;
- ``"ignore"``: the result as computed, silently.

An input without a declared RANGE (most FCL files) has the span of its terms' points as
its range (crane.fcl's distance: -4..20), as the engine's universe; one whose terms are not
all point lists (a Gaussian, a term with a variable parameter) and no RANGE is not checked."""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from fuzzyctl.diagnostics import InputError

if TYPE_CHECKING:
    import numpy as np
    import numpy.typing as npt

#: the modes of ``out_of_range`` (compile, evaluate, evaluate_batch, explain)
OUT_OF_RANGE = ("warn", "clamp", "raise", "ignore")

Ranges = Mapping[str, "tuple[float, float]"]


class InputRangeWarning(UserWarning):
    """Inputs were outside their declared RANGE; ``counts`` maps each such input to how many
    values were (1 for a single evaluation), ``total`` is the number of values of each."""

    def __init__(self, counts: Mapping[str, int], ranges: Ranges, total: int = 1) -> None:
        self.counts = dict(counts)
        self.total = total
        parts = []
        for name, n in counts.items():
            lo, hi = ranges[name]
            many = f"{n} of {total} values of " if total > 1 else ""
            parts.append(f"{many}input {name!r} outside its range {lo:g}..{hi:g}")
        super().__init__(
            "; ".join(parts) + ": the result is what the terms give there "
            "(out_of_range='clamp' limits the inputs, 'raise' refuses them, 'ignore' is silent)"
        )


def check_mode(mode: str) -> str:
    if mode not in OUT_OF_RANGE:
        raise InputError(f"out_of_range must be one of {', '.join(OUT_OF_RANGE)}, not {mode!r}")
    return mode


def declared_ranges(variables: Mapping[str, Any]) -> dict[str, tuple[float, float]]:
    """name -> (low, high) of the variables (``VariableInfo``): the declared RANGE, else the
    span of the terms' points when every term is a point list."""
    out = {}
    for name, info in variables.items():
        rng = getattr(info, "range", None)
        terms = getattr(info, "terms", ())
        if rng is None and terms and all(t.points for t in terms):
            xs = [x for t in terms for x, _y in t.points]
            rng = (min(xs), max(xs))
        if rng is not None and rng[0] < rng[1]:
            out[name] = (float(rng[0]), float(rng[1]))
    return out


def outside_message(name: str, value: float, rng: tuple[float, float]) -> str:
    return f"input {name!r} = {value:g} is outside its range {rng[0]:g}..{rng[1]:g}"


def check_values(ranges: Ranges, names: Sequence[str], values: list[float], mode: str) -> list[float]:
    """One evaluation's input values (in ``names`` order), as ``mode`` says."""
    if mode == "ignore" or not ranges:
        return values
    outside = [
        i
        for i, name in enumerate(names)
        if name in ranges and not ranges[name][0] <= values[i] <= ranges[name][1] and values[i] == values[i]
    ]
    if not outside:
        return values
    check_mode(mode)
    if mode == "raise":
        i = outside[0]
        raise InputError(outside_message(names[i], values[i], ranges[names[i]]) + " (out_of_range='raise')")
    if mode == "clamp":
        values = list(values)
        for i in outside:
            lo, hi = ranges[names[i]]
            values[i] = min(max(values[i], lo), hi)
        return values
    # stacklevel: check_values < Controller._in_range < _values < evaluate < the caller
    warnings.warn(InputRangeWarning({names[i]: 1 for i in outside}, ranges), stacklevel=5)
    return values


def count_outside(ranges: Ranges, columns: Mapping[str, npt.NDArray[np.float64]]) -> dict[str, int]:
    """name -> how many values of its column lie outside its RANGE (NaN is not counted)."""
    import numpy as np

    counts = {}
    for name, arr in columns.items():
        if name in ranges:
            lo, hi = ranges[name]
            n = int(np.count_nonzero((arr < lo) | (arr > hi)))
            if n:
                counts[name] = n
    return counts


def check_columns(
    ranges: Ranges, names: Sequence[str], arrays: list[npt.NDArray[np.float64] | None], mode: str
) -> list[npt.NDArray[np.float64] | None]:
    """A batch's input columns (None: the input's default), as ``mode`` says: one warning
    with a count per column, the first offending row refused, or the columns clamped."""
    import numpy as np

    if mode == "ignore" or not ranges:
        return arrays
    counts = count_outside(ranges, {n: a for n, a in zip(names, arrays, strict=True) if a is not None})
    if not counts:
        return arrays
    check_mode(mode)
    if mode == "raise":
        name = next(iter(counts))
        arr = arrays[list(names).index(name)]
        assert arr is not None
        lo, hi = ranges[name]
        row = int(np.flatnonzero((arr < lo) | (arr > hi))[0])
        text = outside_message(name, float(arr[row]), (lo, hi))
        raise InputError(f"row {row}: {text} (out_of_range='raise')")
    if mode == "clamp":
        return [
            np.clip(a, *ranges[n]) if a is not None and n in counts else a
            for n, a in zip(names, arrays, strict=True)
        ]
    total = next(len(a) for a in arrays if a is not None)
    warnings.warn(InputRangeWarning(counts, ranges, total), stacklevel=3)  # evaluate_batch's caller
    return arrays


def outside_lines(ranges: Ranges, values: Mapping[str, float]) -> list[str]:
    """One line per input value outside its range, for a command line to print."""
    return [
        outside_message(name, v, ranges[name]) + ": the result is what the terms give there"
        for name, v in values.items()
        if name in ranges and not ranges[name][0] <= v <= ranges[name][1] and v == v
    ]
