"""Gaps (completeness): where no rule of an output reaches ``epsilon``, as non-overlapping
boxes merged from the cells of :mod:`fuzzyctl.analysis.cells`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from fuzzyctl.analysis.cells import Axis, Grid


@dataclass(frozen=True)
class Gap:
    """A box of the input space (closed intervals in input units) where no rule of ``output``
    reaches epsilon; ``best_degree`` is the highest best-rule degree found in it."""

    output: str
    box: dict[str, tuple[float, float]]
    best_degree: float


def gap_mask(best: npt.NDArray[np.float64], epsilon: float) -> npt.NDArray[np.bool_]:
    """Cells where the best rule stays below epsilon (epsilon 0: where no rule fires)."""
    return best <= 0.0 if epsilon <= 0 else best < epsilon


def merge_boxes(mask: npt.NDArray[np.bool_]) -> list[tuple[tuple[int, int], ...]]:
    """Cover the True cells by disjoint boxes of cells (greedy: grow along each axis in turn
    while the whole slab is True and not yet taken)."""
    if mask.ndim == 0:  # a block without inputs: the whole (one-point) space or nothing
        return [()] if bool(mask) else []
    free = mask.copy()
    free_flat = free.reshape(-1)  # a view: taking a box clears its cells here too
    flat = np.flatnonzero(mask)
    boxes = []
    n = mask.ndim
    i = 0
    while i < len(flat):
        chunk = flat[i : i + 4096]  # skip taken cells by the thousand, not one by one
        ok = free_flat[chunk]
        if not ok.any():
            i += len(chunk)
            continue
        j = int(np.argmax(ok))
        i += j + 1
        start = np.unravel_index(int(chunk[j]), mask.shape)
        lo = [int(s) for s in start]
        hi = [int(s) + 1 for s in start]
        for k in range(n):
            while hi[k] < mask.shape[k]:
                sl = [slice(lo[j], hi[j]) for j in range(n)]
                sl[k] = slice(hi[k], hi[k] + 1)
                if not free[tuple(sl)].all():
                    break
                hi[k] += 1
        free[tuple(slice(a, b) for a, b in zip(lo, hi, strict=True))] = False
        boxes.append(tuple((a, b - 1) for a, b in zip(lo, hi, strict=True)))
    return boxes


def find_gaps(grid: Grid, outputs: list[tuple[int, str]], epsilon: float) -> tuple[list[Gap], float, float]:
    """The gap boxes of each output, the fraction of the input space in some gap (by
    volume), and the coverage index (lowest best-rule degree over every cell's point)."""
    axes: list[Axis] = grid.axes
    gaps: list[Gap] = []
    union = np.zeros(tuple(len(a.reps) for a in axes), dtype=bool)
    coverage = 1.0
    for o, name in outputs:
        best = grid.best[o]
        coverage = min(coverage, float(best.min()))
        mask = gap_mask(best, epsilon)
        union |= mask
        for cells in merge_boxes(mask):
            box = {a.name: a.bounds(c0, c1) for a, (c0, c1) in zip(axes, cells, strict=True)}
            sub = best[tuple(slice(c0, c1 + 1) for c0, c1 in cells)]
            gaps.append(Gap(name, box, float(sub.max())))
    volume = np.ones(())
    for k, a in enumerate(axes):
        shape = [1] * len(axes)
        shape[k] = -1
        volume = volume * a.widths.reshape(shape)
    total = float(np.prod([a.high - a.low for a in axes])) if axes else 1.0
    fraction = float(np.sum(np.broadcast_to(volume, union.shape) * union)) / total if total > 0 else 0.0
    return gaps, min(1.0, max(0.0, fraction)), coverage
