"""Pictures of an explanation: the accumulated output sets as text (terminals, logs) and as
PNG (matplotlib, imported only when asked for)."""

from __future__ import annotations

import itertools
import math
import os
import tempfile
from pathlib import Path

from fuzzyctl.engine.explain import Explanation, OutputTrace


def _value_at(bps: tuple[tuple[float, float], ...], x: float) -> float:
    """The polyline's upper value at x (vertical edges included)."""
    best = 0.0
    for (x0, y0), (x1, y1) in itertools.pairwise(bps):
        if x0 <= x <= x1:
            best = max(best, y0, y1) if x1 == x0 else max(best, y0 + (y1 - y0) * (x - x0) / (x1 - x0))
    return best


def ascii_plot(trace: OutputTrace, width: int = 64, height: int = 10) -> str:
    """The accumulated set of one output as text; ``|`` marks the defuzzified value."""
    if trace.kind == "singleton":
        pts = list(trace.singletons)
        if not pts:
            return "(no singleton activated)"
        lo = min(x for x, _ in pts)
        hi = max(x for x, _ in pts)
    elif trace.breakpoints:
        pts = []
        lo, hi = trace.breakpoints[0][0], trace.breakpoints[-1][0]
    else:
        return "(nothing to plot: Takagi-Sugeno weights are listed in the table)"
    if hi <= lo:
        lo, hi = lo - 1.0, hi + 1.0
    cols = [lo + (hi - lo) * i / (width - 1) for i in range(width)]
    if trace.kind == "singleton":
        ys = [0.0] * width
        for x, v in pts:
            i = round((x - lo) / (hi - lo) * (width - 1))
            ys[i] = max(ys[i], v)
    else:
        ys = [_value_at(trace.breakpoints, x) for x in cols]
    top = max(max(ys), 1e-300)
    scale_top = 1.0 if top <= 1.0 else top
    mark = None
    if math.isfinite(trace.value) and lo <= trace.value <= hi:
        mark = round((trace.value - lo) / (hi - lo) * (width - 1))
    rows = []
    for r in range(height, 0, -1):
        level = scale_top * (r - 0.5) / height
        line = "".join("#" if y >= level else ("|" if i == mark else " ") for i, y in enumerate(ys))
        label = f"{scale_top * r / height:5.2f} "
        rows.append(label + line)
    rows.append("      " + "-" * width)
    left, right = f"{lo:g}", f"{hi:g}"
    rows.append("      " + left + " " * max(width - len(left) - len(right), 1) + right)
    if mark is not None:
        rows.append("      " + " " * mark + f"^ {trace.name} = {trace.value:.6g}")
    else:
        rows.append(
            f"      {trace.name} = {trace.value:.6g}" + ("" if trace.fired else " (no rule fired: default)")
        )
    return "\n".join(rows)


def save_png(explanation: Explanation, path: str | Path) -> None:
    """One panel per output: the accumulated set (or singleton bars) and the value; written
    atomically."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    outs = [o for o in explanation.outputs if o.kind in ("mamdani", "singleton")] or list(explanation.outputs)
    fig, axes = plt.subplots(len(outs), 1, figsize=(7, 2.6 * max(len(outs), 1)), squeeze=False)
    for ax, o in zip(axes[:, 0], outs, strict=True):
        if o.kind == "singleton":
            xs = [x for x, _ in o.singletons]
            ax.vlines(xs, 0, [v for _, v in o.singletons], linewidth=3)
        elif o.breakpoints:
            ax.fill_between(
                [p[0] for p in o.breakpoints], [p[1] for p in o.breakpoints], step=None, alpha=0.4
            )
            ax.plot([p[0] for p in o.breakpoints], [p[1] for p in o.breakpoints], linewidth=1)
        if math.isfinite(o.value):
            ax.axvline(o.value, color="red", linestyle="--", label=f"{o.name} = {o.value:.6g}")
            ax.legend(loc="upper right")
        ax.set_title(f"{o.name} ({o.method}{', ' + o.accumulation if o.accumulation else ''})")
        ax.set_ylim(bottom=0)
    fig.tight_layout()
    target = Path(path)
    fd, tmp = tempfile.mkstemp(suffix=".png", dir=target.parent or ".")
    os.close(fd)
    try:
        fig.savefig(tmp, format="png", dpi=100)
        os.replace(tmp, target)
    finally:
        plt.close(fig)
        if os.path.exists(tmp):
            os.unlink(tmp)
