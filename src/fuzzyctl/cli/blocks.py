"""``fuzzyctl blocks``: run the PLC function blocks from the command line.

Each row of a CSV file of samples is one call (one cycle) of the block; the output is one
row per cycle with the block's outputs and its INFO (Siemens) or STATUS/ERROR (XFUZ)."""

from __future__ import annotations

import csv
import io
import json
from dataclasses import replace
from pathlib import Path
from typing import Annotated, Any

import typer

from fuzzyctl.blocks.samples import integer, number, read_samples
from fuzzyctl.cli.app import FromOpt, app, err_console
from fuzzyctl.diagnostics import Diagnostic, DiagnosticError, InputError

blocks_app = typer.Typer(
    name="blocks",
    help=(
        "Run PLC fuzzy function blocks against a CSV of input samples, one row per cycle.\n\n"
        "siemens: the S7 FUZZY block (FB30) on an FPL/FCL/... controller; prints the outputs, "
        "INFO and ENO per cycle.  xfuz: the Schneider XFUZ block on ESV/FA/RG tables (.xfuz, "
        "JSON or CSV layout) or any controller it can hold; prints OUT1..6, STATUS and ERROR "
        "per cycle.  check: the siemens profile of a controller.\n\n"
        "Samples: a CSV file with a header row naming the columns; an empty cell keeps the "
        "previous value, as a PLC variable keeps its value between cycles."
    ),
    no_args_is_help=True,
)
app.add_typer(blocks_app, name="blocks")

SamplesArg = Annotated[
    Path,
    typer.Argument(help="CSV of samples: header row, then one row per cycle.", show_default=False),
]
OutputOpt = Annotated[
    Path | None,
    typer.Option(
        "--output",
        "-o",
        help="Write the results here (atomically) instead of standard output.",
        dir_okay=False,
    ),
]
JsonOpt = Annotated[bool, typer.Option("--json", help="Print a JSON list of cycles instead of CSV.")]


def _load(path: Path, fmt: str | None = None) -> Any:
    """A controller (Document) from any format the registry reads."""
    from fuzzyctl.api import require_file
    from fuzzyctl.formats import read_path

    require_file(path)
    loaded = read_path(path, fmt)
    from fuzzyctl.type2 import refuse

    refuse(loaded.document, "blocks")
    for d in loaded.diagnostics:
        if d.severity.value == "warning":
            err_console.print(d.render(), markup=False)
    return loaded.document


def _emit(rows: list[dict[str, Any]], columns: list[str], output: Path | None, as_json: bool) -> None:
    if as_json:
        text = json.dumps(rows, indent=1) + "\n"
    else:
        buf = io.StringIO()
        writer = csv.DictWriter(buf, fieldnames=columns, lineterminator="\n")
        writer.writeheader()
        writer.writerows(rows)
        text = buf.getvalue()
    if output is None:
        typer.echo(text, nl=False)
    else:
        from fuzzyctl.formats import write_atomic

        write_atomic(output, text)


@blocks_app.command("siemens")
def siemens(
    application: Annotated[
        Path,
        typer.Argument(
            help="Controller: .fpl, .fcl or any format fuzzyctl reads.",
            dir_okay=False,
            readable=True,
        ),
    ],
    samples: SamplesArg,
    output: OutputOpt = None,
    as_json: JsonOpt = False,
    no_profile: Annotated[
        bool,
        typer.Option(
            "--no-profile", help="Run a controller that breaks the siemens profile with its own semantics."
        ),
    ] = False,
    from_format: FromOpt = None,
) -> None:
    """Run the Siemens FUZZY block (FB30), one call per sample row.

    Columns: the controller's input names or INPUT1..INPUT8, and optionally START_STOP
    (0 stops processing: INFO 01, outputs keep their values; 16#FFFF or any non-zero value
    runs).  START_STOP starts at W#16#FFFF, as after a download by the configuration tool.
    Inputs outside [MIN, MAX] are clamped; an output for which no rule fires keeps its last
    value.  Output columns: cycle, the controller's outputs, INFO (hex), ENO (1 when INFO
    is 00)."""
    from fuzzyctl.blocks.siemens import FuzzyFB

    try:
        fb = FuzzyFB(_load(application, from_format), check_profile=not no_profile)
    except DiagnosticError as exc:
        raise _located(exc.diagnostics, application) from None
    for d in _located(fb.diagnostics, application).diagnostics:
        err_console.print(d.render(_source(application)), markup=False)
    header, rows = read_samples(samples)
    allowed = set(fb.input_names) | {f"INPUT{i}" for i in range(1, 9)} | {"START_STOP"}
    unknown = [h for h in header if h not in allowed]
    if unknown:
        raise InputError(
            f"{samples}: unknown column {unknown[0]!r} (inputs: {', '.join(fb.input_names)}, "
            "INPUT1..INPUT8, START_STOP)"
        )
    out_rows: list[dict[str, Any]] = []
    for cycle, (lineno, values) in enumerate(rows):
        where = f"{samples}:{lineno}"
        if "START_STOP" in values:
            fb.START_STOP = integer(values.pop("START_STOP"), f"{where} START_STOP") & 0xFFFF
        fb.set_inputs({k: number(v, f"{where} {k}") for k, v in values.items()})
        info = fb.execute()
        row: dict[str, Any] = {"cycle": cycle}
        row.update(fb.output_values())
        row.update({"INFO": f"{info:02X}", "ENO": int(fb.ENO)})
        out_rows.append(row)
    _emit(out_rows, ["cycle", *fb.output_names, "INFO", "ENO"], output, as_json)
    if out_rows and fb.INFO not in (0x00, 0x01):  # 01: stopped by START_STOP, as asked
        err_console.print(
            f"error: the block ended with INFO {fb.INFO:02X} (ENO 0): see docs/blocks.md", markup=False
        )
        raise typer.Exit(1)


@blocks_app.command("xfuz")
def xfuz(
    knowledge_base: Annotated[
        Path,
        typer.Argument(
            help="XFUZ tables (.xfuz: JSON or CSV layout) or a controller in any format fuzzyctl reads.",
            dir_okay=False,
            readable=True,
        ),
    ],
    samples: SamplesArg,
    output: OutputOpt = None,
    as_json: JsonOpt = False,
    period: Annotated[
        float,
        typer.Option(
            "--period", help="Task period in seconds (T_OFB is rounded to a multiple of it).", min=1e-6
        ),
    ] = 0.01,
    relaxed_span: Annotated[
        bool,
        typer.Option(
            "--relaxed-span",
            help="Do not enforce BorneSup - BorneInf >= "
            "2 (Discr - 1), which the manual's own example breaks.",
        ),
    ] = False,
    degre: Annotated[bool, typer.Option("--degre", help="Add the rule activation bytes DEGRE0..")] = False,
    from_format: FromOpt = None,
) -> None:
    """Run the Schneider XFUZ block, one call (task cycle) per sample row.

    Columns: INP1..INP8 (or the controller's input names) and any writable datum of the
    block: INIT, MAN_AUTO, CONT_ASK, START, REFRESH, INHIB, COMMAND, T_OFB, I1_SIM..I8_SIM,
    O1_MAN..O6_MAN, O1_DEF..O6_DEF.  The block starts from a cold restart: MANUAL mode,
    START = 0, on-demand mode unless CONTASK$ = 0.  Output columns: cycle, time, OUT1..OUT6,
    O1_CALC..O6_CALC, STATUS, STATUS_BITS, ERROR, INFERRED (1 when the rules ran)."""
    from fuzzyctl.blocks.samples import run_xfuz

    run = run_xfuz(
        knowledge_base,
        samples,
        period=period,
        span_rule=not relaxed_span,
        degre=degre,
        format=from_format,
        warn=lambda text: err_console.print(text, markup=False),
    )
    _emit(run.rows, run.columns, output, as_json)
    if run.failure is not None:
        err_console.print(
            f"error: the block ended in its error state ({run.failure}); see docs/blocks.md, STATUS",
            markup=False,
        )
        raise typer.Exit(1)


@blocks_app.command("check")
def check(
    application: Annotated[
        Path,
        typer.Argument(help="Controller in any format fuzzyctl reads.", show_default=False),
    ],
    as_json: JsonOpt = False,
    bipolar: Annotated[
        list[str] | None,
        typer.Option(
            "--bipolar",
            help="An input or output (name or INPUTn/OUTPUTn) wired to a bipolar FUZZY_AI/FUZZY_AO: "
            "its MIN and MAX must be symmetric (manual 3.2, 3.3).  Repeat for several.",
        ),
    ] = None,
    from_format: FromOpt = None,
) -> None:
    """Check a controller against the siemens profile (limits of the S7 FUZZY block).

    Exit status 1 when it does not fit (errors), 0 otherwise (warnings are printed)."""
    from fuzzyctl.blocks.siemens import check_siemens

    diags = _located(
        check_siemens(_load(application, from_format), bipolar=bipolar or ()), application
    ).diagnostics
    if as_json:
        typer.echo(json.dumps([d.to_dict() for d in diags], indent=1))
    else:
        for d in diags:
            err_console.print(d.render(_source(application)), markup=False)
        if not diags:
            typer.echo(f"{application}: fits the Siemens FUZZY block")
    if any(d.is_error for d in diags):
        raise typer.Exit(1)


def _source(path: Path) -> str | None:
    try:
        return path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError):
        return None


def _located(diags: list[Diagnostic], path: Path) -> DiagnosticError:
    """The diagnostics with the file they are about (the checks work on models)."""
    return DiagnosticError([d if d.file else replace(d, file=str(path)) for d in diags], _source(path))


__all__ = ["blocks_app", "check", "siemens", "xfuz"]
