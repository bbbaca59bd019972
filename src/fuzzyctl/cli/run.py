"""``fuzzyctl eval`` and ``fuzzyctl explain``: run a fuzzy controller on given inputs."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any

import typer

from fuzzyctl import formats
from fuzzyctl.cli.app import FromOpt, StrictOpt, app
from fuzzyctl.cli.eval_dask import DaskOpt, SchedulerOpt, WorkersOpt

SetOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--set",
        "-s",
        help="An input value, NAME=VALUE (repeat for each input).",
        show_default=False,
        metavar="NAME=VALUE",
    ),
]
BlockOpt = Annotated[str | None, typer.Option("--block", help="Function block to run (default: the first).")]
CompatOpt = Annotated[
    str, typer.Option("--compat", help="Semantics: iec (default), fuzzylite, pyfuzzylite, jfuzzylogic.")
]
ModelArg = Annotated[
    Path, typer.Argument(help=f"Fuzzy system ({formats.names_text(' or ', upper=True)}).", show_default=False)
]
OutOfRangeOpt = Annotated[
    str,
    typer.Option(
        "--out-of-range",
        help="An input outside its range (its RANGE, else its terms' span): warn (the result as "
        "computed, and a warning), clamp (limit it first), raise (an error) or ignore.",
    ),
]

SamplesOpt = Annotated[
    int | None,
    typer.Option(
        "--samples",
        metavar="N",
        help="Interval type-2 systems: sample each Mamdani output at N >= 2 points and run the "
        "compiled program, as the generated code does (default: the exact centroid where there is "
        "one, else 1001 samples). Refused for a type-1 system, whose outputs are integrated exactly.",
        show_default=False,
    ),
]


def _controller(
    file: Path,
    block: str | None,
    compat: str,
    strict: bool = False,
    fmt: str | None = None,
    samples: int | None = None,
) -> Any:
    import fuzzyctl
    from fuzzyctl.cli.app import err_console, usage_errors
    from fuzzyctl.type2 import check_samples

    with usage_errors():
        check_samples(samples)  # before the file is read
    doc = fuzzyctl.load(file, strict=strict, format=fmt, compat=compat)
    if samples is not None:
        chosen: Any
        try:
            chosen = doc.block(block)
        except KeyError:  # an unknown --block: compile() below says so
            chosen = doc
        with usage_errors():
            check_samples(samples, chosen)
    extra: dict[str, Any] = {} if samples is None else {"samples": samples}
    ctl = fuzzyctl.compile(doc, block=block, compat=compat, strict=strict, **extra)
    from fuzzyctl.diagnostics import render_all

    # what the engine settled with a warning (a universe from the terms, ...), capped: a file
    # that repeats a line thousands of times must not print thousands of warnings
    for line in render_all(ctl.warnings):
        err_console.print(line, style="yellow", markup=False, highlight=False)
    return ctl


def _parse_sets(pairs: list[str] | None) -> dict[str, float]:
    from fuzzyctl.diagnostics import FuzzyctlError

    values: dict[str, float] = {}
    for item in pairs or []:
        name, sep, raw = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise typer.BadParameter(f"expected NAME=VALUE, got {item!r}", param_hint="--set")
        try:
            values[name] = float(raw)
        except ValueError:
            raise FuzzyctlError(f"input {name!r}: {raw.strip()!r} is not a number") from None
    return values


def _checked_sets(ctl: Any, pairs: list[str] | None, mode: str) -> tuple[dict[str, float], str]:
    """The --set values and the mode to evaluate them with: with --out-of-range warn, the CLI
    prints a warning for each value outside its range and the controller says nothing more."""
    from fuzzyctl.engine.ranges import check_mode, outside_lines

    values = _parse_sets(pairs)
    if check_mode(mode) != "warn":
        return values, mode
    from fuzzyctl.cli.app import err_console

    for line in outside_lines(ctl.input_ranges, values):
        err_console.print(f"warning: {line}", style="yellow", markup=False, highlight=False)
    return values, "ignore"


def _fmt(v: float) -> str:
    return repr(float(v)) if math.isfinite(v) else ("nan" if math.isnan(v) else ("inf" if v > 0 else "-inf"))


@app.command("eval")
def eval_(
    file: ModelArg,
    set_: SetOpt = None,
    data: Annotated[
        str | None,
        typer.Option(
            "--data",
            "--csv",
            metavar="FILE",
            help="Evaluate every row of a CSV or Parquet file ('-': CSV on stdin). Every column is "
            "kept; the header names the inputs.",
            show_default=False,
        ),
    ] = None,
    output: Annotated[
        str | None,
        typer.Option(
            "--output",
            "-o",
            metavar="FILE",
            help="Write the rows here, atomically: .csv, .parquet or .jsonl by extension ('-': stdout).",
            show_default=False,
        ),
    ] = None,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the outputs as JSON (with --data: JSON lines).")
    ] = False,
    as_table: Annotated[
        bool, typer.Option("--table", help="With --data and no -o: print a table, not CSV.")
    ] = False,
    delimiter: Annotated[
        str | None,
        typer.Option(
            "--delimiter",
            help="CSV delimiter: a character or 'tab' (default: what the header uses).",
            show_default=False,
        ),
    ] = None,
    decimal: Annotated[
        str | None,
        typer.Option(
            "--decimal", help="Decimal mark of the CSV numbers: '.' (default) or ','.", show_default=False
        ),
    ] = None,
    on_error: Annotated[
        str,
        typer.Option(
            "--on-error",
            help="An empty, NaN or infinite input cell: 'nan' gives NaN outputs for its row and a "
            "count; 'fail' stops there.",
        ),
    ] = "nan",
    block: BlockOpt = None,
    compat: CompatOpt = "iec",
    strict: StrictOpt = False,
    out_of_range: OutOfRangeOpt = "warn",
    from_format: FromOpt = None,
    samples: SamplesOpt = None,
    dask_in: DaskOpt = None,
    workers: WorkersOpt = None,
    scheduler: SchedulerOpt = None,
) -> None:
    """Evaluate a controller once (--set), on every row of a data file (--data), or on a
    directory/glob of Parquet/CSV files on Dask (--dask DATA -o DIR)."""
    if dask_in is not None:
        if set_ or data is not None:
            raise typer.BadParameter("use --dask alone, without --set or --data", param_hint="--dask")
        if samples is not None:
            raise typer.BadParameter(
                "--samples goes with --set or --data, not --dask", param_hint="--samples"
            )
        from fuzzyctl.cli import eval_dask

        out_dir = Path(output) if output not in (None, "-") else None
        eval_dask.run(
            file, dask_in, out_dir, block=block, compat=compat, workers=workers, scheduler=scheduler
        )
        return
    _check_eval(workers, scheduler, data, set_, output, decimal, as_json, as_table)
    ctl = _controller(file, block, compat, strict, from_format, samples)
    if data is not None:
        from fuzzyctl.cli.app import err_console
        from fuzzyctl.cli.eval_data import evaluate_file

        evaluate_file(
            ctl,
            data,
            output,
            out_format="jsonl" if as_json and output in (None, "-") else None,
            delimiter=delimiter,
            decimal=decimal,
            on_error=on_error,
            out_of_range=out_of_range,
            as_table=as_table and output is None,
            warn=lambda text: err_console.print(f"warning: {text}", markup=False),
        )
        return
    values, mode = _checked_sets(ctl, set_, out_of_range)
    result = ctl.evaluate(values, out_of_range=mode)
    if as_json:
        typer.echo(json.dumps({k: (v if math.isfinite(v) else None) for k, v in result.items()}))
    else:
        _print_outputs(ctl.name or file.name, result)
    _fail_without_value(ctl, result, values)


def _check_eval(
    workers: int | None,
    scheduler: str | None,
    data: str | None,
    set_: list[str] | None,
    output: str | None,
    decimal: str | None,
    as_json: bool,
    as_table: bool,
) -> None:
    """The options of ``eval`` without --dask that do not go together."""
    if workers is not None or scheduler is not None:
        raise typer.BadParameter("--workers and --scheduler go with --dask", param_hint="--workers")
    if data is not None and set_:
        raise typer.BadParameter("use either --set or --data", param_hint="--set")
    if data is None and output is not None:
        raise typer.BadParameter("--output needs --data", param_hint="--output")
    if decimal not in (None, ".", ","):
        raise typer.BadParameter(f"expected '.' or ',', got {decimal!r}", param_hint="--decimal")
    if as_json and as_table:
        raise typer.BadParameter("use either --json or --table", param_hint="--table")


def _fired(ctl: Any, values: Mapping[str, float]) -> dict[str, bool]:
    """Whether any rule fired for each output: an explanation of the same inputs (it
    advances the NC state; the command ends after it)."""
    try:
        e = ctl.explain(values)
    except Exception:  # only the wording of an error depends on it
        return {}
    return {o.name: o.fired for o in e.outputs}


def _fail_without_value(ctl: Any, result: Mapping[str, float], values: Mapping[str, float]) -> None:
    """An output that is NaN or infinite is no value for a field device: say why and exit 1,
    so a script never takes ``null``/``nan`` for a result (issue 14.6)."""
    missing = [k for k, v in result.items() if not math.isfinite(v)]
    if not missing:
        return
    from fuzzyctl.cli.app import err_console

    fired = _fired(ctl, values)
    for name in missing:
        info = ctl.outputs.get(name)
        default = getattr(info, "default", None)
        why = (
            "no rule fired and its DEFAULT is NaN"
            if default is not None and math.isnan(default) and not fired.get(name, True)
            else "rules fired but the result is not a finite number (a term is NaN or infinite there)"
            if fired.get(name, False)
            else "the result is not a finite number"
        )
        err_console.print(f"error: output {name!r} has no value ({_fmt(result[name])}): {why}", markup=False)
    raise typer.Exit(1)


def _print_outputs(title: str, result: Mapping[str, float]) -> None:
    from rich.console import Console
    from rich.table import Table

    table = Table(title=title, show_lines=False)
    table.add_column("output", overflow="fold")
    table.add_column("value", justify="right", overflow="fold", no_wrap=False)
    for k, v in result.items():
        table.add_row(k, f"{v:.10g}")
    Console(highlight=False).print(table)


@app.command()
def explain(
    file: ModelArg,
    set_: SetOpt = None,
    png: Annotated[
        Path | None, typer.Option("--png", help="Also draw the accumulated output sets to a PNG file.")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="The whole explanation as JSON.")] = False,
    width: Annotated[int, typer.Option("--width", help="Width of the text plot.")] = 64,
    block: BlockOpt = None,
    compat: CompatOpt = "iec",
    strict: StrictOpt = False,
    out_of_range: OutOfRangeOpt = "warn",
    from_format: FromOpt = None,
    samples: SamplesOpt = None,
) -> None:
    """Evaluate once and show why: term degrees, rule degrees, accumulated sets, values."""
    ctl = _controller(file, block, compat, strict, from_format, samples)
    values, mode = _checked_sets(ctl, set_, out_of_range)
    e = ctl.explain(values, out_of_range=mode)
    from fuzzyctl.engine.type2 import Type2Explanation

    if isinstance(e, Type2Explanation):  # firing intervals and type-reduced intervals
        if png is not None:
            raise typer.BadParameter("--png draws type-1 sets; not for type-2 systems", param_hint="--png")
        typer.echo(json.dumps(e.to_dict(), indent=2) if as_json else e.text())
        return
    if png is not None:
        from fuzzyctl.engine.plot import save_png

        save_png(e, png)
    if as_json:
        typer.echo(json.dumps(e.to_dict(), indent=2))
        return
    from rich.console import Console

    from fuzzyctl.console import explanation_views

    Console(highlight=False).print(*explanation_views(e, width=width), sep="\n")
