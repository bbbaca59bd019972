"""``fuzzyctl simulate``: run a configured closed loop (plant, structure, fuzzy controller)."""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Annotated

import typer

from fuzzyctl.cli.app import app, record_table, stderr_progress


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
    csv: Annotated[
        Path | None, typer.Option("--csv", help="CSV path (default: OUT_DIR/CONFIG-NAME.csv).")
    ] = None,
    png: Annotated[
        Path | None, typer.Option("--png", help="PNG path (default: OUT_DIR/CONFIG-NAME.png).")
    ] = None,
    html: Annotated[
        Path | None, typer.Option("--html", help="HTML path (default: OUT_DIR/CONFIG-NAME.html).")
    ] = None,
    no_csv: Annotated[bool, typer.Option("--no-csv", help="Do not write the CSV.")] = False,
    no_png: Annotated[bool, typer.Option("--no-png", help="Do not write the PNG.")] = False,
    no_html: Annotated[bool, typer.Option("--no-html", help="Do not write the HTML.")] = False,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the quality figures and files as JSON.")
    ] = False,
) -> None:
    """Simulate a closed loop; print its quality figures and write CSV, PNG and HTML (all three
    into the current directory unless options name which; --json writes only what is named)."""
    from rich.console import Console

    from fuzzyctl.sim.config import load_config
    from fuzzyctl.sim.experiment import simulate as run
    from fuzzyctl.sim.experiment import write_outputs

    if cycle is not None and not (cycle > 0 and math.isfinite(cycle)):
        raise typer.BadParameter(f"must be > 0, got {cycle}", param_hint="--cycle")
    if duration is not None and not (duration > 0 and math.isfinite(duration)):
        raise typer.BadParameter(f"must be > 0, got {duration}", param_hint="--duration")
    cfg = load_config(config)
    with _progress(f"simulating {cfg.title}", hidden=as_json) as tick:
        result = run(cfg, runtime=runtime, cycle=cycle, duration=duration, progress=tick)
    write_outputs(result, **_targets(config, out_dir, csv, png, html, no_csv, no_png, no_html, as_json))
    if as_json:
        typer.echo(json.dumps(result.to_dict()))
        return
    out = Console(highlight=False)
    out.print(
        f"{cfg.title}: {result.runtime}, cycle {result.cycle:g} s, {result.trace['t'][-1]:g} s simulated"
    )
    if (q := result.quality) is not None:
        out.print(
            record_table(f"quality of {q.signal} (setpoint {q.setpoint:g})", result.figures(), out.width)
        )
        limits = "".join(f", |{k}| <= {v:g}" for k, v in cfg.quality.limits.items()) if cfg.quality else ""
        out.print(f"settling: |{q.signal} - setpoint| <= {q.band:g}{limits} from then on")
    for kind, path in result.files.items():
        out.print(f"{kind}: {path}", soft_wrap=True)  # a path must stay copyable: never broken


@contextmanager
def _progress(description: str, *, hidden: bool) -> Iterator[Callable[[int, int], None]]:
    """A progress bar on stderr (none with ``hidden``); yields the loop's callback."""
    from rich.progress import TextColumn, TimeRemainingColumn

    with stderr_progress(
        TextColumn("{task.percentage:>3.0f}%"), TimeRemainingColumn(), hidden=hidden
    ) as progress:
        task = progress.add_task(description, total=1)

        def tick(done: int, total: int) -> None:
            progress.update(task, completed=done, total=total)

        yield tick


def _targets(
    config: Path,
    out_dir: Path | None,
    csv: Path | None,
    png: Path | None,
    html: Path | None,
    no_csv: bool,
    no_png: bool,
    no_html: bool,
    as_json: bool,
) -> dict[str, Path | None]:
    """Only what was asked: files named with --csv/--png/--html are written, and no others
    unless --out-dir asks for all of them; with none of those options a run writes all three
    into the current directory, except with --json (scripts that parse the figures)."""
    named = {"csv": csv, "png": png, "html": html}
    skip = {"csv": no_csv, "png": no_png, "html": no_html}
    if out_dir is None and (any(named.values()) or as_json):
        return {k: (None if skip[k] else v) for k, v in named.items()}
    base = out_dir if out_dir is not None else Path()
    return {k: None if skip[k] else (v or base / f"{config.stem}.{k}") for k, v in named.items()}
