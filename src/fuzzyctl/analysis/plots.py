"""``fuzzyctl analyze --plot DIR``: for each pair of inputs, the best-rule-degree map on a 2-D
slice (the other inputs at the middle of their range) with the gap and conflict boxes that
cut the slice outlined; PNG, matplotlib without pyplot (docs/analyze.md)."""

from __future__ import annotations

import re
from itertools import combinations
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from fuzzyctl.analysis import cells
from fuzzyctl.analysis.context import build_context

if TYPE_CHECKING:
    from fuzzyctl.analysis.report import Analysis
    from fuzzyctl.model import Document, FunctionBlock

#: points per axis of a map
RESOLUTION = 161


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name)


def pair_maps(
    model: Document | FunctionBlock, result: Analysis, out_dir: Path, *, block: str | None = None
) -> list[Path]:
    """One PNG per input pair ``map_A_B.png`` in ``out_dir``; returns the files written."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.patches import Rectangle

    ctx = build_context(model, block)
    out_dir.mkdir(parents=True, exist_ok=True)
    mids = [(lo + hi) / 2 for lo, hi in ctx.ranges]
    written: list[Path] = []
    outs = [o for o, op in enumerate(ctx.plan.outputs) if op.is_output]
    for i, j in combinations(range(len(ctx.inputs)), 2):
        (xlo, xhi), (ylo, yhi) = ctx.ranges[i], ctx.ranges[j]
        xs, ys = np.linspace(xlo, xhi, RESOLUTION), np.linspace(ylo, yhi, RESOLUTION)
        gx, gy = np.meshgrid(xs, ys)
        cols = [np.full(gx.size, m) for m in mids]
        cols[i], cols[j] = gx.ravel(), gy.ravel()
        _deg, best = cells.row_degrees(ctx, cols)
        # the best rule degree over all outputs' weakest: a gap of any output shows
        z = np.min([best[o] for o in outs], axis=0).reshape(gx.shape) if outs else np.zeros(gx.shape)
        a, b = ctx.inputs[i], ctx.inputs[j]
        others = [(n, m) for k, (n, m) in enumerate(zip(ctx.inputs, mids, strict=True)) if k not in (i, j)]

        def cuts(box: dict[str, tuple[float, float]], others: list[tuple[str, float]] = others) -> bool:
            return all(box.get(n, (m, m))[0] <= m <= box.get(n, (m, m))[1] for n, m in others)

        fig = Figure(figsize=(6.4, 5.2))
        FigureCanvasAgg(fig)
        ax = fig.add_subplot(1, 1, 1)
        im = ax.pcolormesh(xs, ys, z, shading="auto", vmin=0.0, vmax=1.0, cmap="viridis")
        fig.colorbar(im, ax=ax, label="best rule degree (lowest over outputs)")
        for g in result.gaps:
            if cuts(g.box):
                (x0, x1), (y0, y1) = g.box.get(a, (xlo, xhi)), g.box.get(b, (ylo, yhi))
                ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, ec="red", lw=1.5))
        for c in result.conflicts:
            if cuts(c.box):
                (x0, x1), (y0, y1) = c.box.get(a, (xlo, xhi)), c.box.get(b, (ylo, yhi))
                ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, ec="orange", lw=1.5, ls="--"))
        ax.set_xlim(xlo, xhi)
        ax.set_ylim(ylo, yhi)
        ax.set_xlabel(a)
        ax.set_ylabel(b)
        rest = ", ".join(f"{n}={m:.4g}" for n, m in others)
        where = f" (slice at mid-range: {rest})" if rest else ""
        ax.set_title(f"{a} x {b}{where}\nred: gaps, orange dashed: conflicts", fontsize=9)
        fig.tight_layout()
        path = out_dir / f"map_{_safe(a)}_{_safe(b)}.png"
        fig.savefig(path, dpi=100)
        written.append(path)
    return written
