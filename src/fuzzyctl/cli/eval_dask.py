"""``fuzzyctl eval FILE --dask DATA -o DIR``: score a directory or glob of Parquet/CSV files
that may not fit in memory, partition by partition on Dask, into Parquet partitions.

Kept apart from ``cli/run.py`` (the single-process CSV path); ``eval`` hands over here when
``--dask`` is given."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

DaskOpt = Annotated[
    str | None,
    typer.Option(
        "--dask",
        help="Score a directory or glob of Parquet/CSV files on Dask into Parquet partitions in -o DIR.",
        show_default=False,
    ),
]
WorkersOpt = Annotated[
    int | None,
    typer.Option(
        "--workers",
        help="With --dask: local worker processes (default: one per CPU; 0: this process).",
        show_default=False,
    ),
]
SchedulerOpt = Annotated[
    str | None,
    typer.Option(
        "--scheduler",
        help="With --dask: an existing scheduler tcp://HOST:PORT (or $DASK_SCHEDULER_ADDRESS).",
        show_default=False,
    ),
]


def run(
    file: Path,
    source: str,
    output: Path | None,
    *,
    block: str | None,
    compat: str,
    workers: int | None,
    scheduler: str | None,
) -> None:
    from rich.progress import MofNCompleteColumn, TimeElapsedColumn

    import fuzzyctl
    from fuzzyctl.cli.app import stderr_progress
    from fuzzyctl.tune import frames, parallel

    frames.require_dask()
    if output is None:
        raise typer.BadParameter("--dask needs -o DIR for the Parquet partitions", param_hint="--output")
    if output.exists() and not output.is_dir():
        raise typer.BadParameter(f"{output} exists and is not a directory", param_hint="--output")
    if workers is not None and scheduler is not None:
        raise typer.BadParameter("give either --workers or --scheduler", param_hint="--scheduler")
    model = fuzzyctl.load(file)
    execu: Any = parallel.executor(workers, scheduler)
    try:
        with stderr_progress(MofNCompleteColumn(), TimeElapsedColumn(), hidden=False) as progress:
            task = progress.add_task(f"scoring {source}", total=None)

            def tick(done: int, total: int) -> None:
                progress.update(task, completed=done, total=total)

            parts, rows = frames.score_to_parquet(
                source, model, output, block=block, execu=execu, progress=tick, compat=compat
            )
        where = "this process" if execu.workers == 0 else f"{execu.workers} Dask worker(s)"
    finally:
        execu.close()
    typer.echo(f"{rows} rows in {parts} partition(s) scored on {where}; wrote {output}/part-*.parquet")
