"""``fuzzyctl codegen FILE --lang st|plcopen|c|fmu``: IEC 61131-3 Structured Text, the same
function blocks as PLCopen TC6 XML, C99, or an FMI 2/3 co-simulation FMU from a fuzzy system
(see docs/codegen.md)."""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path
from typing import Annotated, Any

import typer

from fuzzyctl.cli.app import FORCE_HINT, FromOpt, app, err_console


class Lang(StrEnum):
    st = "st"
    plcopen = "plcopen"
    c = "c"
    fmu = "fmu"


class Dialect(StrEnum):
    codesys = "codesys"
    twincat = "twincat"
    scl = "scl"
    iec = "iec"
    openplc = "openplc"


@app.command()
def codegen(
    source: Annotated[
        Path,
        typer.Argument(help="Fuzzy system to translate (FCL, FIS, FLL, ...).", show_default=False),
    ],
    lang: Annotated[
        Lang,
        typer.Option(
            "--lang",
            help="st: Structured Text; plcopen: the same as PLCopen TC6 XML; c: C99; "
            "fmu: an FMI co-simulation FMU (sources and this platform's binary).",
        ),
    ] = Lang.st,
    output: Annotated[
        Path | None,
        typer.Option(
            "-o",
            "--output",
            help="st, plcopen: the file (default: print); c: the directory for NAME.h, NAME.c (default: .); "
            "fmu: the .fmu file (default: NAME.fmu).",
        ),
    ] = None,
    dialect: Annotated[
        Dialect | None,
        typer.Option(
            "--dialect",
            help="st and plcopen: codesys (default), twincat, scl (TIA Portal, st only) or iec "
            "(strict IEC 61131-3 as OpenPLC's compiler matiec accepts it; alias openplc).",
        ),
    ] = None,
    lreal: Annotated[
        bool, typer.Option("--lreal", help="st and plcopen: compute in LREAL instead of REAL.")
    ] = False,
    single: Annotated[
        bool, typer.Option("--float", help="c only: compute in float instead of double.")
    ] = False,
    testbench: Annotated[
        int,
        typer.Option(
            "--testbench",
            min=0,
            help="Also write a test bench: N input vectors (every rule, the range ends, no rule fired, "
            "random) with the engine's outputs; st: a PROGRAM after the block, c: NAME_testbench.c.",
        ),
    ] = 0,
    block: Annotated[
        str | None, typer.Option("--block", help="Only this function block (default: every block).")
    ] = None,
    default: Annotated[
        str | None,
        typer.Option(
            "--default",
            help="What an output with DEFAULT := nan gives when no rule fires: a number, or 'hold' "
            "(keep the last value); INFO is 16#02 then.  Needed for ST (no NaN); C outputs NaN without it.",
        ),
    ] = None,
    as_json: Annotated[
        bool,
        typer.Option(
            "--json",
            help="Print a JSON report: the generated text (or the files written), the rename table, "
            "the --default choice and the quadrature bounds of smooth outputs.",
        ),
    ] = False,
    strict: Annotated[
        bool,
        typer.Option(
            "--strict",
            help="Refuse what a strict IEC 61131-7 reading refuses: names that are reserved keywords, "
            "an output without RANGE whose terms do not fall to 0.",
        ),
    ] = False,
    force: Annotated[
        bool, typer.Option("--force", help="Replace the files written even when they are read-only.")
    ] = False,
    fmi: Annotated[
        int | None,
        typer.Option("--fmi", help="fmu only: FMI version 2 or 3 (default: 3).", show_default=False),
    ] = None,
    no_binary: Annotated[
        bool, typer.Option("--no-binary", help="fmu only: sources only, no binary (no C compiler needed).")
    ] = False,
    from_format: FromOpt = None,
) -> None:
    """Generate a PLC function block (ST) or embedded C that computes exactly what the engine
    computes.  Anything the target cannot express is refused with a message naming it."""
    import fuzzyctl
    from fuzzyctl.codegen import generate_c, generate_st
    from fuzzyctl.files import check_writable
    from fuzzyctl.formats import write_atomic

    if lang is Lang.c and (dialect is not None or lreal):
        raise typer.BadParameter("--dialect and --lreal apply to --lang st and plcopen", param_hint="--lang")
    if lang is Lang.st and single:
        raise typer.BadParameter("--float applies to --lang c (use --lreal for ST)", param_hint="--lang")
    from fuzzyctl.codegen.api import Generated
    from fuzzyctl.codegen.defaults import parse_default
    from fuzzyctl.escape import CodegenError

    try:
        parse_default(default)
    except CodegenError as exc:
        raise typer.BadParameter(str(exc), param_hint="--default") from None
    if lang is not Lang.fmu and (fmi is not None or no_binary):
        raise typer.BadParameter("--fmi and --no-binary apply to --lang fmu", param_hint="--fmi")
    if lang is Lang.fmu:
        _check_fmu_options(fmi, dialect, lreal, single, testbench)
    doc = fuzzyctl.load(source, strict=strict, format=from_format)
    if lang is Lang.fmu:
        _fmu(doc, output, fmi or 3, block, strict, default, force, no_binary, as_json)
        return
    if lang is Lang.plcopen:
        _plcopen(doc, output, dialect, lreal, single, block, strict, default, force)
        return
    report: list[Generated] = []
    if lang is Lang.st:
        text = generate_st(
            doc,
            block=block,
            dialect=(dialect or Dialect.codesys).value,
            lreal=lreal,
            strict=strict,
            default=default,
            report=report,
            testbench=testbench,
        )
        if output is None:
            if as_json:
                _json_report(lang, report, text=text)
            else:
                typer.echo(text, nl=False)
            return
        write_atomic(output, text, force=force, hint=FORCE_HINT)
        _done(as_json, lang, report, [output])
        return
    files = generate_c(
        doc, block=block, single=single, strict=strict, testbench=testbench, default=default, report=report
    )
    out_dir = output or Path(".")
    if out_dir.exists() and not out_dir.is_dir():
        raise typer.BadParameter(f"{out_dir} is not a directory", param_hint="-o")
    out_dir.mkdir(parents=True, exist_ok=True)
    if not force:  # every file checked before any is written: no half-replaced set
        for name in files:
            check_writable(out_dir / name, hint=FORCE_HINT)
    for name, text in files.items():
        write_atomic(out_dir / name, text, force=force, hint=FORCE_HINT)
    _done(as_json, lang, report, [out_dir / n for n in files])


def _done(as_json: bool, lang: Lang, report: list[Any], written: list[Path]) -> None:
    if as_json:
        _json_report(lang, report, written=written)
    else:
        err_console.print(f"wrote {', '.join(str(p) for p in written)}", markup=False)
        for gen in report:
            for r in gen.renames:
                err_console.print(f"renamed {r.comment()}", markup=False)


def _json_report(
    lang: Lang, report: list[Any], text: str | None = None, written: list[Path] | None = None
) -> None:
    import json

    out: dict[str, Any] = {"lang": lang.value, "blocks": [g.to_dict() for g in report]}
    if text is not None:
        out["text"] = text
    if written is not None:
        out["written"] = [str(p) for p in written]
    typer.echo(json.dumps(out, indent=2))


def _plcopen(
    doc: Any,
    output: Path | None,
    dialect: Dialect | None,
    lreal: bool,
    single: bool,
    block: str | None,
    strict: bool,
    default: str | None = None,
    force: bool = False,
) -> None:
    """``--lang plcopen``: the ST blocks as one PLCopen TC6 XML project."""
    from fuzzyctl.codegen import generate_plcopen
    from fuzzyctl.formats import write_atomic

    if single:
        raise typer.BadParameter("--float applies to --lang c (use --lreal)", param_hint="--lang")
    if dialect is Dialect.scl:
        raise typer.BadParameter(
            "TIA Portal does not import PLCopen XML: use --lang st --dialect scl", param_hint="--dialect"
        )
    xml = generate_plcopen(
        doc,
        block=block,
        dialect=(dialect or Dialect.codesys).value,
        lreal=lreal,
        strict=strict,
        default=default,
    )
    if output is None:
        typer.echo(xml, nl=False)
        return
    write_atomic(output, xml, force=force, hint=FORCE_HINT)
    err_console.print(f"wrote {output}", markup=False)


def _check_fmu_options(fmi: int | None, dialect: Any, lreal: bool, single: bool, testbench: int) -> None:
    from fuzzyctl.codegen.fmu.description import FMI_VERSIONS

    if fmi is not None and fmi not in FMI_VERSIONS:
        raise typer.BadParameter(f"FMI version {fmi}: give 2 or 3", param_hint="--fmi")
    if dialect is not None or lreal or single or testbench:
        raise typer.BadParameter(
            "--dialect, --lreal, --float and --testbench do not apply to --lang fmu (it computes in double)",
            param_hint="--lang",
        )


def _fmu(
    doc: Any,
    output: Path | None,
    fmi: int,
    block: str | None,
    strict: bool,
    default: str | None,
    force: bool,
    no_binary: bool,
    as_json: bool,
) -> None:
    """``--lang fmu``: one function block (``--block``, default the first) as an FMU."""
    import json

    from fuzzyctl.codegen.fmu import generate_fmu
    from fuzzyctl.files import check_writable

    if output is not None and output.is_dir():
        raise typer.BadParameter(f"{output} is a directory: give the .fmu file to write", param_hint="-o")
    if output is not None and not force:
        check_writable(output, hint=FORCE_HINT)
    result = generate_fmu(
        doc, output, block=block, fmi=fmi, binary=not no_binary, default=default, strict=strict, force=force
    )
    if as_json:
        typer.echo(json.dumps({"lang": "fmu", **result.to_dict()}, indent=2))
        return
    built = f", binary {result.binary}" if result.binary else ", sources only"
    err_console.print(f"wrote {result.path} (FMI {fmi} co-simulation{built})", markup=False)
    for r in result.renames:
        err_console.print(f"renamed {r.comment()}", markup=False)
