"""``fuzzyctl codegen FILE --lang st|plcopen|c``: IEC 61131-3 Structured Text, the same
function blocks as PLCopen TC6 XML, or C99 from a fuzzy system (see docs/codegen.md).

The ``--lang`` and ``--dialect`` choices, which options apply to which, and the function each
choice calls are the targets' capabilities records (:mod:`fuzzyctl.kinds.targets`)."""

from __future__ import annotations

import importlib
from collections.abc import Callable
from enum import StrEnum
from pathlib import Path
from typing import Annotated, Any

import typer

from fuzzyctl.cli.app import FORCE_HINT, FromOpt, app, err_console
from fuzzyctl.kinds import targets

#: ``--lang`` choices: the targets with a CLI choice, in registry order.
Lang = StrEnum("Lang", [(c, c) for c in targets.cli_choices()])  # type: ignore[misc]
#: ``--dialect`` choices: the Structured Text dialects and their aliases.
Dialect = StrEnum("Dialect", [(d, d) for d in targets.dialect_names()])  # type: ignore[misc]
_DEFAULT_LANG = Lang(targets.cli_choices()[0])
_DEFAULT_DIALECT = Dialect(next(iter(targets.DIALECTS)))


def _accepting(option: str) -> list[str]:
    """The --lang choices an option applies to."""
    return [t.cli for t in targets.TARGETS.values() if t.cli is not None and option in t.cli_options]


def _lang_help() -> str:
    return "; ".join(f"{t.cli}: {t.cli_help}" for t in targets.TARGETS.values() if t.cli is not None) + "."


def _dialect_help() -> str:
    helps = [d.cli_dialect_help for d in targets.DIALECTS.values()]
    return (
        f"{' and '.join(_accepting('dialect'))}: "
        + ", ".join(helps[:-1])
        + (" or " if len(helps) > 1 else "")
        + helps[-1]
        + "."
    )


@app.command()
def codegen(
    source: Annotated[
        Path,
        typer.Argument(help="Fuzzy system to translate (FCL, FIS, FLL, ...).", show_default=False),
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
            help="st, plcopen: the file (default: print); c: the directory for NAME.h, NAME.c (default: .).",
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
    from_format: FromOpt = None,
) -> None:
    """Generate a PLC function block (ST) or embedded C that computes exactly what the engine
    computes.  Anything the target cannot express is refused with a message naming it."""
    import fuzzyctl
    from fuzzyctl.files import check_writable
    from fuzzyctl.formats import write_atomic

    caps = targets.cli_target(lang.value)
    _check_options(caps, dialect, lreal, single)
    from fuzzyctl.codegen.api import Generated
    from fuzzyctl.codegen.defaults import parse_default
    from fuzzyctl.escape import CodegenError

    try:
        parse_default(default)
    except CodegenError as exc:
        raise typer.BadParameter(str(exc), param_hint="--default") from None
    doc = fuzzyctl.load(source, strict=strict, format=from_format)
    report: list[Generated] = []
    chosen = {"dialect": (dialect or _DEFAULT_DIALECT).value, "lreal": lreal, "single": single}
    kwargs: dict[str, Any] = {k: chosen[k] for k in ("dialect", "lreal") if k in caps.cli_options} | (
        {"single": single} if "float" in caps.cli_options else {}
    )
    if "testbench" in caps.cli_options:
        kwargs["testbench"] = testbench
    if caps.report:
        kwargs["report"] = report
    result = generator_of(caps)(doc, block=block, strict=strict, default=default, **kwargs)
    json_report = as_json and caps.report
    if isinstance(result, str):  # one text: printed, or written to -o
        if output is None:
            if json_report:
                _json_report(lang, report, text=result)
            else:
                typer.echo(result, nl=False)
            return
        write_atomic(output, result, force=force, hint=FORCE_HINT)
        _done(json_report, lang, report, [output])
        return
    out_dir = output or Path(".")  # several files: into the directory -o
    if out_dir.exists() and not out_dir.is_dir():
        raise typer.BadParameter(f"{out_dir} is not a directory", param_hint="-o")
    out_dir.mkdir(parents=True, exist_ok=True)
    if not force:  # every file checked before any is written: no half-replaced set
        for name in result:
            check_writable(out_dir / name, hint=FORCE_HINT)
    for name, text in result.items():
        write_atomic(out_dir / name, text, force=force, hint=FORCE_HINT)
    _done(json_report, lang, report, [out_dir / n for n in result])


def _check_options(caps: targets.Target, dialect: Any, lreal: bool, single: bool) -> None:
    """Refuse an option the chosen target does not take (and a dialect it cannot hold)."""
    if ("dialect" not in caps.cli_options and dialect is not None) or (
        "lreal" not in caps.cli_options and lreal
    ):
        langs = " and ".join(_accepting("dialect"))
        raise typer.BadParameter(f"--dialect and --lreal apply to --lang {langs}", param_hint="--lang")
    if "float" not in caps.cli_options and single:
        hint = " (use --lreal)" if "lreal" in caps.cli_options else ""
        raise typer.BadParameter(
            f"--float applies to --lang {' and '.join(_accepting('float'))}{hint}", param_hint="--lang"
        )
    refusal = targets.dialect(dialect.value).refused_by.get(caps.name) if dialect is not None else None
    if refusal is not None:
        raise typer.BadParameter(
            f"{refusal}: use --lang st --dialect {dialect.value}", param_hint="--dialect"
        )


def generator_of(caps: targets.Target) -> Callable[..., str | dict[str, str]]:
    """The function the record names (``module:function``), imported on use."""
    module, _, name = caps.generator.partition(":")
    fn: Callable[..., str | dict[str, str]] = getattr(importlib.import_module(module), name)
    return fn


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
