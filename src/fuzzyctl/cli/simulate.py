"""``fuzzyctl simulate``: run a configured closed loop (plant, structure, fuzzy controller)."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Annotated

import typer

from fuzzyctl.cli.app import app


@app.command("simulate")
def simulate(
    config: Annotated[
        Path, typer.Argument(help="Loop configuration (TOML, see docs/sim.md).", show_default=False)
    ],
    runtime: Annotated[
        str | None,
        typer.Option("--runtime", "-r", help="Run the controller on: engine, siemens, xfuz, native."),
    ] = None,
    cycle: Annotated[
        float | None, typer.Option("--cycle", help="Controller cycle time [s] (overrides the file).")
    ] = None,
    duration: Annotated[
        float | None, typer.Option("--duration", help="Simulated time [s] (overrides the file).")
    ] = None,
    out_dir: Annotated[
        Path | None,
        typer.Option("--out-dir", "-o", help="Directory for the CSV, PNG and HTML (default: current)."),
    ] = None,
    csv: Annotated[Path | None, typer.Option("--csv", help="CSV path (default: OUT_DIR/<name>.csv).")] = None,
    png: Annotated[Path | None, typer.Option("--png", help="PNG path (default: OUT_DIR/<name>.png).")] = None,
    html: Annotated[
        Path | None, typer.Option("--html", help="HTML path (default: OUT_DIR/<name>.html).")
    ] = None,
    no_csv: Annotated[bool, typer.Option("--no-csv", help="Do not write the CSV.")] = False,
    no_png: Annotated[bool, typer.Option("--no-png", help="Do not write the PNG.")] = False,
    no_html: Annotated[bool, typer.Option("--no-html", help="Do not write the HTML.")] = False,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the quality figures and files as JSON.")
    ] = False,
) -> None:
    """Simulate a closed loop; print its quality figures, write CSV + PNG + HTML."""
    from rich.console import Console
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn
    from rich.table import Table

    from fuzzyctl.sim.config import load_config
    from fuzzyctl.sim.experiment import simulate as run
    from fuzzyctl.sim.experiment import write_outputs

    if cycle is not None and not (cycle > 0 and math.isfinite(cycle)):
        raise typer.BadParameter(f"must be > 0, got {cycle}", param_hint="--cycle")
    if duration is not None and not (duration > 0 and math.isfinite(duration)):
        raise typer.BadParameter(f"must be > 0, got {duration}", param_hint="--duration")
    cfg = load_config(config)
    console = Console(stderr=True)
    with Progress(
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        TextColumn("{task.percentage:>3.0f}%"),
        TimeRemainingColumn(),
        console=console,
        transient=True,
        disable=as_json,
    ) as progress:
        task = progress.add_task(f"simulating {cfg.title}", total=1)

        def tick(done: int, total: int) -> None:
            progress.update(task, completed=done, total=total)

        result = run(cfg, runtime=runtime, cycle=cycle, duration=duration, progress=tick)

    base = out_dir if out_dir is not None else Path.cwd()
    stem = config.stem
    write_outputs(
        result,
        csv=None if no_csv else (csv or base / f"{stem}.csv"),
        png=None if no_png else (png or base / f"{stem}.png"),
        html=None if no_html else (html or base / f"{stem}.html"),
    )
    q = result.quality
    if as_json:
        doc = {
            "title": cfg.title,
            "runtime": result.runtime,
            "cycle": result.cycle,
            "duration": float(result.trace["t"][-1]),
            "quality": None if q is None else {k: _json_number(v) for k, v in q.as_dict().items()},
            "files": {k: str(v) for k, v in result.files.items()},
        }
        typer.echo(json.dumps(doc))
        return
    out = Console(highlight=False)
    out.print(
        f"{cfg.title}: {result.runtime}, cycle {result.cycle:g} s, {result.trace['t'][-1]:g} s simulated"
    )
    if q is not None:
        table = Table(title=f"quality of {q.signal} (setpoint {q.setpoint:g})")
        for name in ("ISE", "IAE", "ITAE", "overshoot", "overshoot %", "settling time", "final error"):
            table.add_column(name, justify="right")
        settle = "never" if math.isinf(q.settling_time) else f"{q.settling_time:.2f} s"
        table.add_row(
            f"{q.ise:.4g}",
            f"{q.iae:.4g}",
            f"{q.itae:.4g}",
            f"{q.overshoot:.3g}",
            f"{q.overshoot_percent:.2f}",
            settle,
            f"{q.final_error:.3g}",
        )
        out.print(table)
        limits = "".join(f", |{k}| <= {v:g}" for k, v in cfg.quality.limits.items()) if cfg.quality else ""
        out.print(f"settling: |{q.signal} - setpoint| <= {q.band:g}{limits} from then on")
    for kind, path in result.files.items():
        out.print(f"{kind}: {path}", soft_wrap=True)  # a path must stay copyable: never broken


def _json_number(v: float | str) -> float | str | None:
    if isinstance(v, float) and not math.isfinite(v):
        return None if math.isnan(v) else ("inf" if v > 0 else "-inf")
    return v
