"""``fuzzyctl analyze FILE``: gaps, conflicts, redundancy, monotonicity and surface facts of a
rule base (docs/analyze.md).  The work is :func:`fuzzyctl.analyze`; this only prints it."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Any

import typer

from fuzzyctl import formats
from fuzzyctl.cli.app import app, stderr_progress
from fuzzyctl.cli.eval_dask import SchedulerOpt, WorkersOpt


@app.command()
def analyze(
    file: Annotated[
        Path,
        typer.Argument(
            help=f"The fuzzy system ({formats.names_text(' or ', upper=True)}).", exists=True, dir_okay=False
        ),
    ],
    epsilon: Annotated[
        float,
        typer.Option("--epsilon", help="A rule fires at degree >= E (default 0: > 0).", min=0.0, max=1.0),
    ] = 0.0,
    delta: Annotated[
        float,
        typer.Option(
            "--delta", help="Conflicts: rules firing together above D (default 0.5).", min=0.0, max=0.999999
        ),
    ] = 0.5,
    monotone: Annotated[
        list[str] | None,
        typer.Option("--monotone", help="Declared signs, e.g. valve:-temp,+pressure (repeatable)."),
    ] = None,
    block: Annotated[str | None, typer.Option("--block", help="Function block (default: the first).")] = None,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the JSON object of docs/analyze.md.")
    ] = False,
    data: Annotated[
        list[str] | None,
        typer.Option(
            "--data",
            help="Coverage from a log: a CSV/Parquet file, a directory or a glob (repeatable).",
            show_default=False,
        ),
    ] = None,
    dask: Annotated[
        bool,
        typer.Option(
            "--dask", help="With --data: count the files' partitions in parallel on Dask (same numbers)."
        ),
    ] = False,
    workers: WorkersOpt = None,
    scheduler: SchedulerOpt = None,
    plot: Annotated[
        Path | None,
        typer.Option(
            "--plot",
            help="Write PNGs to DIR: a best-rule-degree map per input pair (and coverage.png with --data).",
            file_okay=False,
            show_default=False,
        ),
    ] = None,
) -> None:
    """Find where no rule fires (gaps), rules that contradict each other, duplicate, subsumed
    and dead rules, unused terms, monotonicity violations and the output surface's range,
    slope and jumps, before the controller meets the plant."""
    import fuzzyctl
    from fuzzyctl.analysis import analyze as run
    from fuzzyctl.analysis import usage as cov_mod

    model = fuzzyctl.load(file)
    result = run(model, block=block, epsilon=epsilon, delta=delta, monotone=monotone or ())
    if (dask or workers is not None or scheduler is not None) and not data:
        raise typer.BadParameter("--dask, --workers and --scheduler go with --data", param_hint="--dask")
    if not dask and (workers is not None or scheduler is not None):
        raise typer.BadParameter("--workers and --scheduler go with --dask", param_hint="--workers")
    if data and dask:
        cov = _dask_coverage(model, list(data), block, epsilon, workers, scheduler)
    else:
        cov = cov_mod.coverage(model, list(data), block=block, epsilon=epsilon) if data else None
    pngs = _plots(model, result, cov, plot, block) if plot is not None else []
    if as_json:
        obj = result.to_json()
        if cov is not None:
            obj["coverage"] = cov.to_json()
        typer.echo(json.dumps(obj, allow_nan=False, default=str))
        return
    from rich.console import Console

    console = Console(highlight=False, soft_wrap=True)
    console.print(
        f"[bold]{file}[/bold]: block {result.block}, {result.cells} cells"
        + ("" if result.exact else " (not exact, see notes)")
    )
    for line in result.lines():
        console.print(line, markup=False)
    if cov is not None:
        console.print(cov_mod.table(cov))
        for line in cov_mod.lines(cov):
            console.print(line, markup=False)
    for png in pngs:
        console.print(f"wrote {png}", markup=False)


def _plots(model: object, result: object, cov: object, out_dir: Path, block: str | None) -> list[Path]:
    from fuzzyctl.analysis import plots
    from fuzzyctl.analysis import usage as cov_mod

    written = plots.pair_maps(model, result, out_dir, block=block)  # type: ignore[arg-type]
    if cov is not None:
        written.append(cov_mod.plot(cov, out_dir / "coverage.png"))  # type: ignore[arg-type]
    return written


def _dask_coverage(
    model: Any, data: list[str], block: str | None, epsilon: float, workers: int | None, scheduler: str | None
) -> Any:
    """Coverage on Dask: a local cluster (``--workers``, default one per CPU; 0: this process)
    or an existing scheduler, with a progress bar on stderr as ``eval --dask`` shows."""
    from rich.progress import MofNCompleteColumn, TimeElapsedColumn

    from fuzzyctl.analysis import usage as cov_mod
    from fuzzyctl.analysis import usage_dask
    from fuzzyctl.tune import parallel

    usage_dask.require_dask()
    if workers is not None and scheduler is not None:
        raise typer.BadParameter("give either --workers or --scheduler", param_hint="--scheduler")
    execu = parallel.executor(workers, scheduler)
    try:
        with stderr_progress(MofNCompleteColumn(), TimeElapsedColumn(), hidden=False) as progress:
            task = progress.add_task("coverage", total=None)

            def tick(done: int, total: int) -> None:
                progress.update(task, completed=done, total=total)

            return cov_mod.coverage(
                model,
                list(data),
                block=block,
                epsilon=epsilon,
                dask=True,
                scheduler=getattr(execu, "client", None) or "sync",
                progress=tick,
            )
    finally:
        execu.close()
