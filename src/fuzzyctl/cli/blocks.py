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
    for d in loaded.diagnostics:
        if d.severity.value == "warning":
            err_console.print(d.render(), markup=False)
    return loaded.document


def _read_samples(path: Path) -> tuple[list[str], list[tuple[int, dict[str, str]]]]:
    from fuzzyctl.api import require_file

    require_file(path)
    text = path.read_text(encoding="utf-8-sig")
    reader = csv.reader(io.StringIO(text))
    rows = [(n, r) for n, r in enumerate(reader, start=1) if r and any(c.strip() for c in r)]
    if not rows:
        raise InputError(f"{path}: no header row")
    header = [c.strip() for c in rows[0][1]]
    if len(set(header)) != len(header):
        raise InputError(f"{path}:{rows[0][0]}: a column name appears twice")
    samples = []
    for lineno, row in rows[1:]:
        if len(row) > len(header):
            raise InputError(f"{path}:{lineno}: {len(row)} cells for {len(header)} columns")
        samples.append((lineno, {h: c.strip() for h, c in zip(header, row, strict=False) if c.strip()}))
    return header, samples


def _number(text: str, where: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise InputError(f"{where}: {text!r} is not a number") from None


def _integer(text: str, where: str) -> int:
    t = text.strip().upper()
    for prefix in ("W#16#", "B#16#", "16#", "0X"):
        if t.startswith(prefix):
            try:
                return int(t[len(prefix) :], 16)
            except ValueError:
                break
    try:
        value = float(t)
    except ValueError:
        raise InputError(f"{where}: {text!r} is not an integer") from None
    if not value.is_integer():
        raise InputError(f"{where}: {text!r} is not an integer")
    return int(value)


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
    header, rows = _read_samples(samples)
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
            fb.START_STOP = _integer(values.pop("START_STOP"), f"{where} START_STOP") & 0xFFFF
        fb.set_inputs({k: _number(v, f"{where} {k}") for k, v in values.items()})
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
    from fuzzyctl.blocks.schneider import XfuzFB
    from fuzzyctl.blocks.task import CyclicTask
    from fuzzyctl.formats.xfuz.reader import read_tables
    from fuzzyctl.formats.xfuz.writer import constants_from_model, slot_labels

    names: dict[str, str] = {}
    text = knowledge_base.read_text(encoding="utf-8-sig")
    if knowledge_base.suffix.lower() == ".xfuz":
        constants = read_tables(text, path=str(knowledge_base))
    else:
        document = _load(knowledge_base, from_format)
        constants, diags = constants_from_model(document)
        for d in diags:
            err_console.print(d.render(), markup=False)
        if any(d.is_error for d in diags):
            raise DiagnosticError([d for d in diags if d.is_error])
        names = slot_labels(document)
    fb = XfuzFB(constants, task_period=period, span_rule=not relaxed_span)
    for issue in fb.kb_issues:
        err_console.print(
            f"{knowledge_base}: STATUS bit {issue.bit}: {issue.location} {issue.message}".replace(
                ":  ", ": "
            ),
            markup=False,
        )
    header, rows = _read_samples(samples)
    for h in header:
        try:
            fb[names.get(h, h)]
        except KeyError:
            raise InputError(
                f"{samples}: unknown column {h!r} (INP1..INP8, "
                f"{', '.join(names) + ', ' if names else ''}INIT, MAN_AUTO, CONT_ASK, START, "
                "REFRESH, INHIB, COMMAND, T_OFB, Ii_SIM, Oi_MAN, Oi_DEF)"
            ) from None
    out_rows: list[dict[str, Any]] = []
    task = CyclicTask(period)
    pending: list[tuple[int, dict[str, str]]] = list(rows)

    def cycle(ctx: Any) -> None:
        lineno, values = pending[ctx.index]
        for key, raw in values.items():
            try:
                fb[names.get(key, key)] = _integer(raw, f"{samples}:{lineno} {key}")
            except KeyError as exc:
                raise InputError(f"{samples}:{lineno}: {exc.args[0]}") from None
        snap = fb.execute(ctx.period)
        row: dict[str, Any] = {"cycle": ctx.index, "time": round(ctx.index * ctx.period, 9)}
        row.update({f"OUT{i + 1}": v for i, v in enumerate(snap.out)})
        row.update({f"O{i + 1}_CALC": v for i, v in enumerate(snap.o_calc)})
        row.update(
            {
                "STATUS": snap.status,
                "STATUS_BITS": " ".join(map(str, fb.status_bits)),
                "ERROR": int(snap.error),
                "INFERRED": int(snap.inferred),
            }
        )
        if degre:
            row.update({f"DEGRE{k}": v for k, v in enumerate(snap.degre[: max(1, len(fb.kb.rules))])})
        out_rows.append(row)

    task.add(cycle)
    if pending:
        task.run(len(pending))
    columns = [
        "cycle",
        "time",
        *(f"OUT{i}" for i in range(1, 7)),
        *(f"O{i}_CALC" for i in range(1, 7)),
        "STATUS",
        "STATUS_BITS",
        "ERROR",
        "INFERRED",
    ]
    if degre:
        columns += [f"DEGRE{k}" for k in range(max(1, len(fb.kb.rules)))]
    _emit(out_rows, columns, output, as_json)
    if out_rows and out_rows[-1]["ERROR"]:
        bits = out_rows[-1]["STATUS_BITS"] or "none"
        err_console.print(
            f"error: the block ended in its error state (ERROR = 1, STATUS bits {bits}); "
            "see docs/blocks.md, STATUS",
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
