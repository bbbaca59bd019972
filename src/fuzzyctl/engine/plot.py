"""Pictures of an explanation: the accumulated output sets as text (terminals, logs) and as
PNG (matplotlib, imported only when asked for)."""

from __future__ import annotations

import itertools
import math
from pathlib import Path
from typing import TYPE_CHECKING

from fuzzyctl.engine.explain import Explanation, OutputTrace
from fuzzyctl.files import atomic_writer

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from fuzzyctl.engine.variables import VariableInfo


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
        rows.append(f"      {trace.name} = {trace.value:.6g}" + _why(trace))
    return "\n".join(rows)


def _why(trace: OutputTrace) -> str:
    """Why an output has the value it has, when that is not the accumulated set's."""
    if not trace.fired:
        return " (no rule fired: default)"
    if not math.isfinite(trace.value):
        return " (rules fired; a term is NaN or infinite there)"
    return ""


def explanation_figure(explanation: Explanation) -> Figure:
    """One panel per output: the accumulated set (or singleton bars) and the value, as a
    matplotlib Figure (no pyplot state: it can be shown, saved or embedded)."""
    from matplotlib.figure import Figure

    outs = [o for o in explanation.outputs if o.kind in ("mamdani", "singleton")] or list(explanation.outputs)
    fig = Figure(figsize=(7, 2.6 * max(len(outs), 1)))
    axes = fig.subplots(len(outs), 1, squeeze=False)
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
        ax.set_xlabel(o.name)
        ax.set_ylabel("degree")
        ax.set_ylim(bottom=0)
    fig.tight_layout()
    return fig


def save_png(explanation: Explanation, path: str | Path) -> None:
    """:func:`explanation_figure` written to a PNG file, atomically."""
    save_figure(explanation_figure(explanation), path)


def save_figure(fig: Figure, path: str | Path, dpi: int = 100) -> None:
    """A Figure written as PNG through :func:`fuzzyctl.files.atomic_writer`."""
    with atomic_writer(path, "wb") as handle:
        fig.savefig(handle, format="png", dpi=dpi)


def plot_terms(variable: VariableInfo, *, points: int = 1001, ax: Axes | None = None) -> Figure:
    """The membership functions of one variable (``ctl.inputs["temp"]``,
    ``ctl.outputs["valve"]``) as a labelled matplotlib Figure, like scikit-fuzzy's ``view()``:
    one curve per term over the variable's range (the span of its terms where it has none),
    singletons as vertical lines.  ``ax`` draws into an existing Axes instead."""
    from matplotlib.figure import Figure

    if ax is None:
        fig = Figure(figsize=(7, 3))
        ax = fig.subplots()
    else:
        fig = ax.figure  # type: ignore[assignment]
    low, high = _extent(variable)
    xs = [low + (high - low) * i / (points - 1) for i in range(points)]

    def label(name: str, x: float, y: float, color: str) -> None:
        where = (x - low) / (high - low) if high > low else 0.5
        align = "left" if where < 0.08 else ("right" if where > 0.92 else "center")
        ax.annotate(name, (x, y), textcoords="offset points", xytext=(0, 3), ha=align, color=color)

    for index, term in enumerate(variable.terms):
        color = f"C{index % 10}"
        if term.kind == "singleton" and not isinstance(term.params[0], str):
            x0 = float(term.params[0])
            height = 1.0 if isinstance(term.height, str) else float(term.height)
            ax.vlines([x0], 0, [height], linewidth=2.5, color=color, label=term.name)
            label(term.name, x0, height, color)
            continue
        try:
            ys = term.membership(xs)
        except ValueError:
            continue  # Takagi-Sugeno or variable-parameter terms: no curve of x alone
        ax.plot(xs, ys, linewidth=1.5, label=term.name, color=color)
        peak = int(ys.argmax())
        label(term.name, xs[peak], float(ys[peak]), color)
    pad = 0.02 * (high - low)
    ax.set_xlim(low - pad, high + pad)  # terms at the ends stay visible
    ax.set_ylim(0, 1.1)
    ax.set_xlabel(variable.name)
    ax.set_ylabel("degree of membership")
    ax.set_title(f"{variable.name} ({variable.role})")
    if variable.terms:
        ax.legend(loc="best", fontsize="small")
    fig.tight_layout()
    return fig


def _extent(variable: VariableInfo) -> tuple[float, float]:
    if variable.range is not None and variable.range[1] > variable.range[0]:
        return variable.range
    xs: list[float] = []
    for t in variable.terms:
        if t.points:
            xs += [x for x, _ in t.points]
        xs += [float(p) for p in t.params if not isinstance(p, str)]
    if not xs:
        return 0.0, 1.0
    lo, hi = min(xs), max(xs)
    return (lo, hi) if hi > lo else (lo - 1.0, hi + 1.0)
