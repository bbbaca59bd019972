"""Plots of a trace: a PNG (matplotlib) and an interactive HTML page (plotly, with plotly.js
embedded so that the page works offline).  One panel per group of signals, a shared time
axis."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from fuzzyctl.files import write_atomic
from fuzzyctl.sim.loop import Trace


def default_panels(trace: Trace, *, first: Sequence[str] = (), drives: Sequence[str] = ()) -> list[list[str]]:
    """``first`` (e.g. the controlled signal and its setpoint), then every other plain signal
    on its own, then the driven plant inputs, then the fuzzy block's outputs."""
    panels: list[list[str]] = []
    used = {"t"}
    if first:
        panels.append([n for n in first if n in trace])
        used.update(first)
    internals = [n for n in trace.names if "." in n]
    plain = [n for n in trace.names if n not in used and "." not in n and n not in drives]
    for name in plain:
        panels.append([name])
    if drives:
        panels.append([n for n in drives if n in trace])
    fb = [n for n in internals if n.startswith("fb.")]
    if fb:
        panels.append(fb)
    return [p for p in panels if p]


def _label(trace: Trace, name: str) -> str:
    unit = trace.units.get(name)
    return f"{name} [{unit}]" if unit and unit != "1" else name


def save_png(
    trace: Trace,
    path: str | Path,
    panels: Sequence[Sequence[str]],
    *,
    title: str = "",
    dashed: Sequence[str] = (),
) -> Path:
    """Draw the panels one above the other (``dashed``: e.g. the setpoints) and write a PNG
    atomically."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = Path(path)
    n = len(panels)
    fig, axes = plt.subplots(n, 1, figsize=(9, 1.9 * n + 0.8), sharex=True, squeeze=False)
    t = trace["t"]
    for ax, names in zip(axes[:, 0], panels, strict=True):
        for name in names:
            style = "--" if name in dashed else "-"
            ax.plot(t, trace[name], style, label=_label(trace, name), linewidth=1.3)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right", fontsize=8, framealpha=0.8)
    axes[-1, 0].set_xlabel("time [s]")
    if title:
        fig.suptitle(title, fontsize=11)
    return write_png(fig, path)


def write_png(fig: Any, path: Path) -> Path:
    """Lay out a matplotlib figure, write it as a PNG (110 dpi) atomically and close it."""
    import io

    import matplotlib.pyplot as plt

    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    write_atomic(path, buf.getvalue())
    return path


def save_html(
    trace: Trace,
    path: str | Path,
    panels: Sequence[Sequence[str]],
    *,
    title: str = "",
    dashed: Sequence[str] = (),
) -> Path:
    """An interactive page (zoom, hover, toggle signals) with plotly.js embedded."""
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    path = Path(path)
    n = len(panels)
    fig = make_subplots(rows=n, cols=1, shared_xaxes=True, vertical_spacing=0.04)
    t = trace["t"]
    for row, names in enumerate(panels, start=1):
        for name in names:
            fig.add_trace(
                go.Scatter(
                    x=t,
                    y=trace[name],
                    name=_label(trace, name),
                    mode="lines",
                    legendgroup=str(row),
                    line={"dash": "dash"} if name in dashed else {},
                ),
                row=row,
                col=1,
            )
    fig.update_xaxes(title_text="time [s]", row=n, col=1)
    fig.update_layout(
        title=title, height=230 * n + 120, hovermode="x unified", legend={"groupclick": "toggleitem"}
    )
    html = fig.to_html(include_plotlyjs=True, full_html=True)
    write_atomic(path, html)
    return path
