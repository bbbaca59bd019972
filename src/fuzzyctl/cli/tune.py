"""``fuzzyctl learn`` and ``fuzzyctl tune``: a fuzzy system from data, and tuning against
data or the closed loop (docs/tune.md)."""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Annotated, Any

import typer

from fuzzyctl import formats
from fuzzyctl.cli.app import FromOpt, app, stderr_progress

WorkersOpt = Annotated[
    int | None,
    typer.Option(
        "--workers",
        help="Dask worker processes on this machine (default: one per CPU; 0: run in this process).",
        show_default=False,
    ),
]
SchedulerOpt = Annotated[
    str | None,
    typer.Option(
        "--scheduler",
        help="An existing Dask scheduler, tcp://HOST:PORT (default: $DASK_SCHEDULER_ADDRESS, else local).",
        show_default=False,
    ),
]
SeedOpt = Annotated[int, typer.Option("--seed", help="Random seed (splits, optimisers, clustering).")]
ValidationOpt = Annotated[
    float, typer.Option("--validation", help="Fraction of the rows kept for validation (0: none).")
]
ValidationDataOpt = Annotated[
    Path | None,
    typer.Option(
        "--validation-data", help="Validation (checking) rows from this file instead.", show_default=False
    ),
]


OldOutOpt = Annotated[
    Path | None,
    typer.Option("--out", hidden=True, help="Old spelling of -o/--output (one release).", show_default=False),
]


#: what learn and tune say when an invocation reads as the old spelling
RENAMED = "-o/--output now names the file written (it was -o/--out); name the column(s) with --target"


def _output_file(output: Path | None, old: Path | None) -> Path:
    """-o/--output FILE, or the old --out FILE with a note (kept for one release)."""
    from fuzzyctl.cli.app import err_console

    if old is not None:
        if output is not None:
            raise typer.BadParameter(RENAMED, param_hint="--out")
        err_console.print("note: --out is now -o/--output (--out goes in the next release)", markup=False)
        return old
    if output is None:
        raise typer.BadParameter("name the file to write: -o/--output FILE", param_hint="-o/--output")
    return output


def _fmt(v: float) -> str:
    return "inf" if math.isinf(v) else f"{v:.6g}"


def _print_table(title: str, rows: list[tuple[str, float, float]] | list[tuple[str, float]]) -> None:
    from rich.console import Console
    from rich.table import Table

    table = Table(title=title)
    table.add_column("")
    if rows and len(rows[0]) == 3:
        table.add_column("before", justify="right")
        table.add_column("after", justify="right")
    else:
        table.add_column("value", justify="right")
    for row in rows:
        table.add_row(row[0], *(_fmt(float(v)) for v in row[1:]))
    Console(highlight=False).print(table)


def _load(file: Path, fmt: str) -> Any:
    import fuzzyctl

    return fuzzyctl.load(file, format=fmt)


@app.command("learn")
def learn(
    data: Annotated[Path, typer.Argument(help="CSV or Parquet file with a header row.", show_default=False)],
    inputs: Annotated[
        list[str],
        typer.Option(
            "--inputs", help="Input columns: a,b or 'a b' (or --inputs a --inputs b).", show_default=False
        ),
    ],
    target: Annotated[
        str, typer.Option("--target", help="The column to learn (the system's output).", show_default=False)
    ],
    output: Annotated[
        Path | None,
        typer.Option("-o", "--output", help="Write the learned system here (FCL).", show_default=False),
    ] = None,
    old_out: OldOutOpt = None,
    method: Annotated[str, typer.Option("--method", help="grid (partition) or cluster (k-means).")] = "grid",
    kind: Annotated[str, typer.Option("--type", help="tsk (Takagi-Sugeno) or mamdani (singletons).")] = "tsk",
    terms: Annotated[
        int | None,
        typer.Option(
            "--terms",
            help="Terms per input (grid; default 5/3/2 by input count) or clusters (default 10).",
            show_default=False,
        ),
    ] = None,
    out_terms: Annotated[int, typer.Option("--out-terms", help="Output singletons of a Mamdani system.")] = 7,
    and_op: Annotated[
        str, typer.Option("--and", help="AND operator: prod or min (PLC Basic level).")
    ] = "prod",
    shape: Annotated[
        str, typer.Option("--shape", help="Grid terms: triangle (points, PLC blocks) or gauss.")
    ] = "triangle",
    validation: ValidationOpt = 0.2,
    validation_data: ValidationDataOpt = None,
    seed: SeedOpt = 0,
    name: Annotated[
        str | None, typer.Option("--name", help="FUNCTION_BLOCK name (default: learned).")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print the errors as JSON.")] = False,
    type2: Annotated[
        bool,
        typer.Option(
            "--type2",
            help="Widen the learned system into interval type-2 (lower scale/lag fitted to the data).",
        ),
    ] = False,
) -> None:
    """Learn a fuzzy system from data: grid partition or clustering, consequents by least squares."""
    from fuzzyctl.cli.app import split_names
    from fuzzyctl.tune.learning import learn as run

    out = _output_file(output, old_out)
    names = split_names(inputs)
    if not names:
        raise typer.BadParameter("name at least one input column", param_hint="--inputs")
    result = run(
        data,
        inputs=names,
        output=target,
        method=method,
        kind=kind,
        terms=terms,
        out_terms=out_terms,
        and_op=and_op,
        validation=validation,
        validation_data=validation_data,
        seed=seed,
        name=name,
        shape=shape,
        type2=type2,
    )
    result.write_fcl(out)
    if as_json:
        typer.echo(json.dumps(result.to_dict(out)))
        return
    rows = [(k, v) for k, v in result.scores.items() if not k.endswith("rows")]
    _print_table(f"{out}: {result.kind} by {result.method}, {result.rules} rules", rows)
    for note in result.notes:
        typer.echo(note)


@app.command("tune")
def tune(
    file: Annotated[
        Path,
        typer.Argument(
            help=f"The fuzzy system to tune ({formats.names_text(' or ', upper=True)}).", show_default=False
        ),
    ],
    output: Annotated[
        Path | None,
        typer.Option("-o", "--output", help="Write the tuned system here (FCL).", show_default=False),
    ] = None,
    old_out: OldOutOpt = None,
    data: Annotated[
        Path | None,
        typer.Option("--data", help="CSV/Parquet of inputs and target outputs.", show_default=False),
    ] = None,
    target: Annotated[
        list[str] | None,
        typer.Option(
            "--target",
            help="Target column(s): a,b or 'a b' (default: every output in the data).",
            show_default=False,
        ),
    ] = None,
    plant_config: Annotated[
        Path | None,
        typer.Option(
            "--plant",
            help="A simulate configuration (TOML); cost and scenarios from its [tune] table.",
            show_default=False,
        ),
    ] = None,
    cost: Annotated[
        str | None,
        typer.Option(
            "--cost",
            help="Cost terms, e.g. settling_time=1,max:angle=0.5 (overrides [tune] cost).",
            show_default=False,
        ),
    ] = None,
    free: Annotated[
        str, typer.Option("--free", help="What moves: all, inputs, outputs, weights, VAR, VAR.TERM, -ITEM.")
    ] = "all",
    optimizer: Annotated[
        str | None,
        typer.Option(
            "--optimizer",
            help="cmaes, de, lsq or lbfgsb (default: lsq for data, cmaes for the plant).",
            show_default=False,
        ),
    ] = None,
    budget: Annotated[
        int, typer.Option("--budget", help="Evaluations (simulations per scenario, or passes over the data).")
    ] = 200,
    seed: SeedOpt = 0,
    loss: Annotated[str, typer.Option("--loss", help="Data loss: rmse, mae or max.")] = "rmse",
    validation: ValidationOpt = 0.2,
    validation_data: ValidationDataOpt = None,
    block: Annotated[
        str | None, typer.Option("--block", help="Function block to tune (default: the first).")
    ] = None,
    runtime: Annotated[
        str | None,
        typer.Option("--runtime", help="Run the controller in the loop on: engine, siemens, xfuz, native."),
    ] = None,
    keep_zero: Annotated[
        bool | None,
        typer.Option(
            "--keep-zero/--move-zero",
            help="Keep abscissae and singletons at 0 (default: yes with --plant, no with --data).",
            show_default=False,
        ),
    ] = None,
    workers: WorkersOpt = None,
    scheduler: SchedulerOpt = None,
    report: Annotated[
        Path | None, typer.Option("--report", help="Write a report directory (Markdown, JSON, PNG, HTML).")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print the result as JSON.")] = False,
    from_format: FromOpt = None,
    widen: Annotated[
        bool,
        typer.Option(
            "--widen",
            help="Make a type-1 system interval type-2 (lower = upper) and tune only the lower scale/lag.",
        ),
    ] = False,
) -> None:
    """Tune a fuzzy system against data or a closed-loop cost (Ctrl-C keeps the best so far)."""
    from fuzzyctl.cli.app import split_names
    from fuzzyctl.tune.api import tune as run

    out = _output_file(output, old_out)
    _check_tune(budget, workers, scheduler, data, plant_config)
    with _progress(f"tuning {file.name}", budget, hidden=as_json) as tick:
        result = run(
            file if from_format is None else _load(file, from_format),
            data=data,
            output=split_names(target) or None,
            plant_config=plant_config,
            cost=cost,
            free=free,
            optimizer=optimizer,
            budget=budget,
            seed=seed,
            loss=loss,
            validation=validation,
            validation_data=validation_data,
            block=block,
            workers=workers,
            scheduler=scheduler,
            runtime=runtime,
            keep_zero=keep_zero,
            progress=tick,
            widen=widen,
        )
    files = result.save(out, report=report)
    if as_json:
        typer.echo(json.dumps(result.to_dict(files)))
        return
    _print_tuned(result, out, report)


def _check_tune(budget: int, workers: int | None, scheduler: str | None, data: Any, plant: Any) -> None:
    if budget < 1:
        raise typer.BadParameter(f"must be at least 1, got {budget}", param_hint="--budget")
    if workers is not None and scheduler is not None:
        raise typer.BadParameter("give either --workers or --scheduler", param_hint="--scheduler")
    if (data is None) == (plant is None):
        raise typer.BadParameter("give either --data or --plant", param_hint="--data")


@contextmanager
def _progress(description: str, total: int, *, hidden: bool) -> Iterator[Callable[[int, int, float], None]]:
    """A progress bar on stderr (none with ``hidden``); yields the optimiser's callback."""
    from rich.progress import MofNCompleteColumn, TextColumn, TimeElapsedColumn

    with stderr_progress(
        MofNCompleteColumn(), TextColumn("best {task.fields[best]}"), TimeElapsedColumn(), hidden=hidden
    ) as progress:
        task = progress.add_task(description, total=total, best="-")

        def tick(done: int, total: int, best: float) -> None:
            progress.update(task, completed=done, total=total, best=_fmt(best))

        yield tick


def _print_tuned(result: Any, out: Path, report: Path | None) -> None:
    status = " (interrupted: best so far kept)" if result.interrupted else ""
    _print_table(
        f"{result.cost_name}: {_fmt(result.before)} -> {_fmt(result.after)}{status}",
        [(k, b, a) for k, b, a in result.table],
    )
    if result.changes:
        _print_table(f"{len(result.changes)} parameter(s) changed", list(result.changes))
    for note in result.notes:
        typer.echo(f"note: {note}")
    where = "this process" if result.workers == 0 else f"{result.workers} Dask worker(s)"
    typer.echo(f"{result.evaluations} evaluations on {where} in {result.seconds:.1f} s; wrote {out}")
    if report is not None:
        typer.echo(f"report: {report / 'report.md'}")
