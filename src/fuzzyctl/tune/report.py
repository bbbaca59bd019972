"""The report of a tuning run: ``report.md`` and ``report.json`` (before/after table, changed
parameters, notes), ``cost.png`` (cost history), ``fit.png`` or ``responses.png``
(predictions against the data, or the closed-loop responses, before and after),
``terms.png`` (the membership functions that moved) and ``report.html`` (the same plots,
interactive, plotly.js embedded once so that the page works offline)."""

from __future__ import annotations

import html
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from fuzzyctl.files import write_atomic
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.model import DefuzzifyBlock, FunctionBlock, FuzzifyBlock
from fuzzyctl.sim.plot import write_png

if TYPE_CHECKING:
    from fuzzyctl.tune.api import TuneResult


def _fmt(v: float) -> str:
    return "inf" if math.isinf(v) else f"{v:.6g}"


def write_report(result: TuneResult, directory: Path) -> dict[str, Path]:
    directory.mkdir(parents=True, exist_ok=True)
    files: dict[str, Path] = {}
    files["md"] = directory / "report.md"
    write_atomic(files["md"], markdown(result))
    files["json"] = directory / "report.json"
    write_atomic(files["json"], json.dumps(as_dict(result), indent=2))
    import matplotlib

    matplotlib.use("Agg")
    files["cost.png"] = _png(directory / "cost.png", lambda fig: _cost_mpl(fig, result), (8, 3.6))
    if result.kind == "data":
        files["fit.png"] = _png(directory / "fit.png", lambda fig: _fit_mpl(fig, result), (9, 4.2))
    else:
        n = len(result.traces[0])
        files["responses.png"] = _png(
            directory / "responses.png", lambda fig: _responses_mpl(fig, result), (9, 2.6 * max(1, n) + 0.6)
        )
    moved = _moved_variables(result)
    if moved:
        files["terms.png"] = _png(
            directory / "terms.png", lambda fig: _terms_mpl(fig, result, moved), (9, 2.3 * len(moved) + 0.6)
        )
    files["html"] = directory / "report.html"
    write_atomic(files["html"], _html(result))
    return files


def _png(path: Path, draw: Any, size: tuple[float, float]) -> Path:
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=size)
    draw(fig)
    return write_png(fig, path)


# --------------------------------------------------------------------------- text


def markdown(r: TuneResult) -> str:
    name = r.block.name or "the function block"
    where = "data" if r.kind == "data" else "the closed loop"
    lines = [
        f"# Tuning {name} against {where}",
        "",
        f"- optimizer: {r.optimizer}, seed {r.seed}, {r.evaluations} of {r.budget} evaluations"
        f"{' (interrupted: best so far kept)' if r.interrupted else ''}",
        f"- ran on: {'this process' if r.workers == 0 else f'{r.workers} Dask worker(s)'}, {r.seconds:.1f} s",
        f"- stopped: {r.message}",
        f"- {r.cost_name}: {_fmt(r.before)} -> {_fmt(r.after)}"
        + (f" ({100.0 * (r.after - r.before) / r.before:+.1f} %)" if r.before not in (0.0, math.inf) else ""),
        "",
        "## Before and after",
        "",
        "| | before | after |",
        "|---|---|---|",
        *(f"| {k} | {_fmt(b)} | {_fmt(a)} |" for k, b, a in r.table),
        "",
        "## Changed parameters",
        "",
    ]
    if r.changes:
        lines += ["| parameter | before | after |", "|---|---|---|"]
        lines += [f"| {k} | {b:.6g} | {a:.6g} |" for k, b, a in r.changes]
    else:
        lines.append("none")
    if r.notes:
        lines += ["", "## Notes", "", *(f"- {n}" for n in r.notes)]
    figs = ["cost.png", "fit.png" if r.kind == "data" else "responses.png"]
    if _moved_variables(r):
        figs.append("terms.png")
    lines += ["", "## Plots", "", *(f"![{f}]({f})" for f in figs), "", "Interactive: report.html", ""]
    return "\n".join(lines)


def as_dict(r: TuneResult) -> dict[str, Any]:
    def num(v: float) -> float | None:
        return v if math.isfinite(v) else None

    return {
        "block": r.block.name,
        "kind": r.kind,
        "optimizer": r.optimizer,
        "seed": r.seed,
        "budget": r.budget,
        "evaluations": r.evaluations,
        "seconds": r.seconds,
        "workers": r.workers,
        "interrupted": r.interrupted,
        "message": r.message,
        "cost": {"name": r.cost_name, "before": num(r.before), "after": num(r.after)},
        "table": [{"what": k, "before": num(b), "after": num(a)} for k, b, a in r.table],
        "changes": [{"parameter": k, "before": b, "after": a} for k, b, a in r.changes],
        "history": [[i, num(c), num(b)] for i, c, b in r.history],
        "notes": r.notes,
    }


# --------------------------------------------------------------------------- plots


def _cost_mpl(fig: Any, r: TuneResult) -> None:
    ax = fig.add_subplot(1, 1, 1)
    h = np.array([(i, c, b) for i, c, b in r.history if math.isfinite(c)] or [(0, r.before, r.before)])
    ax.plot(h[:, 0], h[:, 1], ".", ms=3, alpha=0.4, label="candidate")
    ax.plot(h[:, 0], h[:, 2], "-", lw=1.6, label="best so far")
    top = max(float(np.percentile(h[:, 1], 95)), r.before)
    if top > h[:, 2].min():
        ax.set_ylim(min(h[:, 2].min(), r.after) * 0.95, top)
    ax.set_xlabel("evaluation")
    ax.set_ylabel(r.cost_name)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(f"{r.optimizer}: {_fmt(r.before)} -> {_fmt(r.after)}", fontsize=10)


def _predictions(r: TuneResult) -> list[tuple[str, str, np.ndarray, np.ndarray, np.ndarray]]:
    """(split, output, target, before, after) for the data case."""
    p = r.problem
    out = []
    for label, cols in (("training", p.train), ("validation", p.validation)):
        if cols is None:
            continue
        before = p.predict(r.original.blocks[r.block_index], cols)
        after = p.predict(r.block, cols)
        for o in p.outputs:
            out.append((label, o, cols[o], before[o], after[o]))
    return out


def _fit_mpl(fig: Any, r: TuneResult) -> None:
    preds = _predictions(r)
    p = r.problem
    one_input = len(p.inputs) == 1
    ax = fig.add_subplot(1, 1, 1)
    for label, o, y, b, a in preds:
        if one_input:
            x = (p.train if label == "training" else p.validation)[p.inputs[0]]
            k = np.argsort(x)
            ax.plot(x[k], y[k], ".", ms=3, label=f"{o} {label} data")
            ax.plot(x[k], b[k], "--", lw=1, label=f"before ({label})")
            ax.plot(x[k], a[k], "-", lw=1.4, label=f"after ({label})")
            ax.set_xlabel(p.inputs[0])
            ax.set_ylabel(o)
        else:
            ax.plot(y, b, ".", ms=3, alpha=0.5, label=f"{o} {label}: before")
            ax.plot(y, a, ".", ms=3, alpha=0.7, label=f"{o} {label}: after")
            ax.set_xlabel("target")
            ax.set_ylabel("system output")
    if not one_input and preds:
        lo = min(float(np.min(t[2])) for t in preds)
        hi = max(float(np.max(t[2])) for t in preds)
        ax.plot([lo, hi], [lo, hi], "k-", lw=0.8, alpha=0.6)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)


def _responses_mpl(fig: Any, r: TuneResult) -> None:
    p = r.problem
    before, after = r.traces
    n = len(before)
    for k, sc in enumerate(p.scenarios):
        ax = fig.add_subplot(n, 1, k + 1)
        spec = sc.config.quality
        signal = spec.signal if spec is not None else next(iter(n for n in before[k].names if n != "t"))
        t = before[k]["t"]
        if spec is not None and isinstance(spec.setpoint, str):
            ax.plot(t, before[k][spec.setpoint], "k--", lw=0.8, label=spec.setpoint)
        ax.plot(t, before[k][signal], lw=1.1, label=f"{signal} before")
        ax.plot(after[k]["t"], after[k][signal], lw=1.4, label=f"{signal} after")
        ax.set_title(sc.name, fontsize=9)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="best")
    fig.axes[-1].set_xlabel("time [s]")


def _moved_variables(r: TuneResult) -> list[str]:
    moved = []
    before = r.original.blocks[r.block_index]
    blocks: list[FuzzifyBlock | DefuzzifyBlock] = [*before.fuzzify, *before.defuzzify]
    for blk in blocks:
        other: FuzzifyBlock | DefuzzifyBlock | None = r.block.fuzzify_block(
            blk.variable
        ) or r.block.defuzzify_block(blk.variable)
        sets = any(
            hasattr(t.mf, "points") or not registry.flag(getattr(t.mf, "kind", ""), "takagi_sugeno")
            for t in blk.terms
        )
        if other is not None and other.terms != blk.terms and sets:
            moved.append(blk.variable)
    return moved


def _curves(fb: FunctionBlock, var: str) -> tuple[np.ndarray, list[tuple[str, np.ndarray, bool]]]:
    """Sampled membership functions of one variable (singletons as stems)."""
    from fuzzyctl.engine.compile import COMPAT_PROFILES
    from fuzzyctl.engine.lowering.lower import lower
    from fuzzyctl.engine.semantics.shapes import membership_np

    plan, _ = lower(fb, COMPAT_PROFILES["iec"])
    assert plan is not None
    terms: Sequence[Any] = ()
    for fi in plan.fuzzy_inputs:
        if fi.name == var:
            terms = fi.terms
    for op in plan.outputs:
        if op.name == var:
            terms = op.terms
    xs_all = [
        float(p) for t in terms for p in (t.params[0::2] if t.kind in ("points", "singletons") else t.params)
    ]
    lo, hi = (min(xs_all), max(xs_all)) if xs_all else (0.0, 1.0)
    pad = 0.05 * (hi - lo or 1.0)
    x = np.linspace(lo - pad, hi + pad, 600)
    out = []
    for t in terms:
        if t.kind == "function" or registry.flag(t.kind, "takagi_sugeno"):
            continue
        if t.kind == "singleton":
            out.append((t.name, np.array([float(t.params[0])]), True))
            continue
        out.append((t.name, membership_np(t.kind, t.params, t.height, x), False))
    return x, out


def _terms_mpl(fig: Any, r: TuneResult, moved: list[str]) -> None:
    before = r.original.blocks[r.block_index]
    for k, var in enumerate(moved):
        ax = fig.add_subplot(len(moved), 1, k + 1)
        for fb, style, alpha in ((before, "--", 0.6), (r.block, "-", 1.0)):
            x, curves = _curves(fb, var)
            for j, (name, y, stem) in enumerate(curves):
                color = f"C{j % 10}"
                if stem:
                    ax.vlines(y, 0, 1, colors=color, linestyles=style, alpha=alpha)
                    if fb is r.block:
                        ax.text(float(y[0]), 1.02, name, fontsize=7, ha="center", color=color)
                else:
                    ax.plot(
                        x, y, style, color=color, alpha=alpha, lw=1.2, label=name if fb is r.block else None
                    )
        ax.set_title(f"{var}: before (dashed) and after", fontsize=9)
        ax.set_ylim(-0.02, 1.12)
        ax.grid(True, alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7, loc="upper right")


def _html(r: TuneResult) -> str:
    import plotly.graph_objects as go

    figs = []
    h = np.array([(i, c, b) for i, c, b in r.history if math.isfinite(c)] or [(0, r.before, r.before)])
    cost = go.Figure()
    cost.add_trace(go.Scatter(x=h[:, 0], y=h[:, 1], mode="markers", name="candidate", marker={"size": 4}))
    cost.add_trace(go.Scatter(x=h[:, 0], y=h[:, 2], mode="lines", name="best so far"))
    cost.update_layout(title="cost history", xaxis_title="evaluation", yaxis_title=r.cost_name, height=380)
    figs.append(cost)
    if r.kind == "data":
        fit = go.Figure()
        for label, o, y, b, a in _predictions(r):
            fit.add_trace(
                go.Scatter(x=y, y=b, mode="markers", name=f"{o} {label} before", marker={"size": 4})
            )
            fit.add_trace(go.Scatter(x=y, y=a, mode="markers", name=f"{o} {label} after", marker={"size": 4}))
        fit.update_layout(
            title="system output against target", xaxis_title="target", yaxis_title="output", height=480
        )
        figs.append(fit)
    else:
        before, after = r.traces
        for k, sc in enumerate(r.problem.scenarios):
            spec = sc.config.quality
            signal = spec.signal if spec is not None else before[k].names[1]
            f = go.Figure()
            f.add_trace(go.Scatter(x=before[k]["t"], y=before[k][signal], name="before", mode="lines"))
            f.add_trace(go.Scatter(x=after[k]["t"], y=after[k][signal], name="after", mode="lines"))
            f.update_layout(title=f"{sc.name}: {signal}", xaxis_title="time [s]", height=360)
            figs.append(f)
    parts = [fig.to_html(include_plotlyjs=(k == 0), full_html=False) for k, fig in enumerate(figs)]
    table = "".join(
        f"<tr><td>{html.escape(k)}</td><td>{_fmt(b)}</td><td>{_fmt(a)}</td></tr>" for k, b, a in r.table
    )
    changes = "".join(
        f"<tr><td>{html.escape(k)}</td><td>{b:.6g}</td><td>{a:.6g}</td></tr>" for k, b, a in r.changes
    )
    return (
        "<!DOCTYPE html><html><head><meta charset='utf-8'><title>tuning report</title>"
        "<style>body{font-family:sans-serif;margin:2em}"
        "td,th{padding:2px 10px;border-bottom:1px solid #ddd}</style>"
        f"</head><body><h1>Tuning {html.escape(r.block.name or '')}</h1>"
        f"<p>{html.escape(r.optimizer)}, seed {r.seed}, {r.evaluations} evaluations: "
        f"{html.escape(r.cost_name)} {_fmt(r.before)} &rarr; {_fmt(r.after)}</p>"
        f"<table><tr><th></th><th>before</th><th>after</th></tr>{table}</table>"
        "<h2>Changed parameters</h2>"
        f"<table><tr><th>parameter</th><th>before</th><th>after</th></tr>{changes}</table>"
        + "".join(parts)
        + "</body></html>"
    )
