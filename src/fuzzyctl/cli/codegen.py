"""``fuzzyctl codegen FILE --lang st|plcopen|c|fmu``: IEC 61131-3 Structured Text, the same
function blocks as PLCopen TC6 XML, C99, or an FMI 2/3 co-simulation FMU from a fuzzy system
(see docs/codegen.md).

The ``--lang`` and ``--dialect`` choices, which options apply to which, and the function each
choice calls are the targets' capabilities records (:mod:`fuzzyctl.kinds.targets`)."""

from __future__ import annotations

import json
from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer

from fuzzyctl import formats
from fuzzyctl.cli.app import FORCE_HINT, FromOpt, StrictOpt, app, err_console, usage_errors
from fuzzyctl.codegen.emit import accepting, generator_of
from fuzzyctl.kinds import arith as arith_kinds
from fuzzyctl.kinds import targets

__all__ = ["Arith", "Dialect", "Lang", "codegen", "generator_of"]

#: ``--lang`` choices: the targets with a CLI choice, in registry order.
Lang = StrEnum("Lang", [(c, c) for c in targets.cli_choices()])  # type: ignore[misc]
#: ``--dialect`` choices: the Structured Text dialects and their aliases.
Dialect = StrEnum("Dialect", [(d, d) for d in targets.dialect_names()])  # type: ignore[misc]
#: ``--arith`` choices: the arithmetic records.
Arith = StrEnum("Arith", [(a, a) for a in arith_kinds.choices()])  # type: ignore[misc]
_DEFAULT_ARITH = Arith(arith_kinds.DEFAULT)
#: ``--int-output`` choices
IntOutput = StrEnum("IntOutput", [(a, a) for a in arith_kinds.INT_OUTPUTS])  # type: ignore[misc]
_DEFAULT_LANG = Lang(targets.cli_choices()[0])


def _lang_help() -> str:
    return "; ".join(f"{t.cli}: {t.cli_help}" for t in targets.TARGETS.values() if t.cli is not None) + "."


def _dialect_help() -> str:
    helps = [d.cli_dialect_help for d in targets.DIALECTS.values()]
    return (
        f"{' and '.join(accepting('dialect'))}: "
        + ", ".join(helps[:-1])
        + (" or " if len(helps) > 1 else "")
        + helps[-1]
        + "."
    )


@app.command()
def codegen(
    source: Annotated[
        Path,
        typer.Argument(
            help=f"Fuzzy system to translate ({formats.names_text(' or ', upper=True)}).", show_default=False
        ),
    ],
    lang: Annotated[
        Lang,
        typer.Option("--lang", help=_lang_help()),
    ] = _DEFAULT_LANG,
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
            help=_dialect_help(),
        ),
    ] = None,
    lreal: Annotated[
        bool, typer.Option("--lreal", help="st and plcopen: compute in LREAL instead of REAL.")
    ] = False,
    single: Annotated[
        bool, typer.Option("--float", help="c only: compute in float instead of double.")
    ] = False,
    arith: Annotated[
        Arith,
        typer.Option(
            "--arith",
            help=f"{' and '.join(accepting('arith'))}: the arithmetic; "
            + "; ".join(f"{a.name}: {a.help}" for a in arith_kinds.ARITH.values())
            + ".",
        ),
    ] = _DEFAULT_ARITH,
    int_output: Annotated[
        IntOutput | None,
        typer.Option(
            "--int-output",
            help="--arith int16/int32: how each output is stored (value = stored * scale + offset, both "
            "in the header and --json); "
            + "; ".join(f"{k}: {v}" for k, v in arith_kinds.INT_OUTPUTS.items())
            + ".",
            show_default=False,
        ),
    ] = None,
    term_tolerance: Annotated[
        str | None,
        typer.Option(
            "--term-tolerance",
            help="--arith int16/int32: how far (in degrees) the chords computing a smooth input term "
            "(Gaussian, bell, sigmoid, ...) may deviate from it; proven, and counted in each output's error "
            "bound (default 2.5e-4 in int16, 1e-5 in int32).",
            show_default=False,
        ),
    ] = None,
    lookup: Annotated[
        bool,
        typer.Option(
            "--lookup",
            help=f"{' and '.join(accepting('lookup'))}: the block as a lookup table (1 to 3 inputs) with "
            "multi-linear interpolation and a proven error bound in its header.",
        ),
    ] = False,
    tolerance: Annotated[
        str | None,
        typer.Option(
            "--tolerance",
            help="--lookup: the error allowed, as a percentage of each output's range (default 0.1%) "
            "or a fraction (0.001).",
            show_default=False,
        ),
    ] = None,
    max_bytes: Annotated[
        int | None,
        typer.Option(
            "--max-bytes", help="--lookup: the largest table, in bytes (default 16384).", show_default=False
        ),
    ] = None,
    testbench: Annotated[
        int,
        typer.Option(
            "--testbench",
            min=0,
            help="Also write a test bench: N input vectors (every rule, the range ends, no rule fired, "
            "random) with the engine's outputs; st: a PROGRAM after the block, c: NAME_testbench.c.",
        ),
    ] = 0,
    samples: Annotated[
        int | None,
        typer.Option(
            "--samples",
            metavar="N",
            help="Interval type-2 systems: sample each Mamdani output at N >= 2 points (default 101, "
            "stated in the header). Refused for a type-1 system.",
            show_default=False,
        ),
    ] = None,
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
    strict: StrictOpt = False,
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
    from fuzzyctl.codegen.emit import emit

    with usage_errors():
        emitted = emit(
            source,
            lang.value,
            output,
            dialect=None if dialect is None else dialect.value,
            lreal=lreal,
            single=single,
            testbench=testbench,
            block=block,
            default=default,
            strict=strict,
            force=force,
            hint=FORCE_HINT,
            format=from_format,
            fmi=fmi,
            binary=not no_binary,
            arith=arith.value,
            lookup=lookup,
            tolerance=tolerance,
            max_bytes=max_bytes,
            int_output=None if int_output is None else int_output.value,
            samples=samples,
            term_tolerance=term_tolerance,
        )
    if as_json and emitted.reports:
        typer.echo(json.dumps(emitted.to_dict(), indent=2))
    elif emitted.text is not None:
        typer.echo(emitted.text, nl=False)
    else:
        err_console.print(emitted.wrote(), markup=False)
        for r in emitted.renames:
            err_console.print(f"renamed {r.comment()}", markup=False)
