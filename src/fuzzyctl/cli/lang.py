"""``fuzzyctl check`` and ``fuzzyctl fmt``: validate FCL, report its conformance level and
data check list, print it in canonical form."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Annotated

import typer

from fuzzyctl.cli.app import EXIT_ERRORS, EXIT_OK, EXIT_USAGE, app, err_console


def _load(file: Path, strict: bool = False, compat: str = "iec"):  # type: ignore[no-untyped-def]
    """Load and check ``file``; when the language checks pass, add what the engine reports
    (features it will not evaluate, decisions worth knowing) so that ``check`` never says OK
    to a file ``eval`` refuses (with the same ``--strict`` and ``--compat``)."""
    from dataclasses import replace

    from fuzzyctl.diagnostics import has_errors
    from fuzzyctl.engine.support import unsupported
    from fuzzyctl.fcl import load_file

    result = load_file(file, strict=strict, compat=compat)
    if result.document is None or has_errors(result.diagnostics):
        return result
    # The engine validates models from every reader, so it re-finds some language errors;
    # keep only what the language checks did not already say about the same line.
    seen = {(d.code, d.span.line if d.span else None) for d in result.diagnostics}
    for fb in result.document.blocks:
        for d in unsupported(fb, compat=compat, strict=strict):
            if (d.code, d.span.line if d.span else None) not in seen:
                result.diagnostics.append(replace(d, file=d.file or result.source.path))
    return result


@app.command()
def check(
    file: Annotated[Path, typer.Argument(help="FCL file to check.", show_default=False)],
    checklist: Annotated[
        bool, typer.Option("--checklist", help="Print the data check list of IEC 61131-7 Table 11.")
    ] = False,
    as_json: Annotated[bool, typer.Option("--json", help="Diagnostics and report as JSON.")] = False,
    strict: Annotated[
        bool,
        typer.Option(
            "--strict",
            help="What a strict IEC 61131-7 tool refuses is an error: names that are reserved "
            "keywords (Table 7), an output without RANGE whose terms do not fall to 0.",
        ),
    ] = False,
    compat: Annotated[
        str,
        typer.Option(
            "--compat",
            help="Check for this engine profile (iec, fuzzylite, pyfuzzylite, jfuzzylogic); "
            "jfuzzylogic also warns about what jFuzzyLogic 3.3 would reject.",
        ),
    ] = "iec",
) -> None:
    """Validate an FCL file and report the conformance level it needs (exit 1 on errors)."""
    from rich.console import Console
    from rich.table import Table

    from fuzzyctl.diagnostics import DiagnosticError, Severity
    from fuzzyctl.engine.compile import COMPAT_PROFILES
    from fuzzyctl.fcl import conformance

    if compat not in COMPAT_PROFILES:
        raise typer.BadParameter(f"unknown profile {compat!r} (known: {', '.join(COMPAT_PROFILES)})")
    try:
        result = _load(file, strict, compat)
    except DiagnosticError as exc:
        if as_json:
            typer.echo(
                json.dumps(
                    {"file": str(file), "ok": False, "diagnostics": [d.to_dict() for d in exc.diagnostics]},
                    indent=2,
                )
            )
            raise typer.Exit(EXIT_ERRORS) from None
        raise
    doc = result.document
    feats = conformance.features(doc, result.spellings) if result.ok and doc is not None else []
    lvl = conformance.level(feats)
    if as_json:
        report: dict[str, object] = {
            "file": str(file),
            "ok": result.ok,
            "diagnostics": [d.to_dict() for d in result.diagnostics],
        }
        if result.ok and doc is not None:
            report["level"] = str(lvl)
            report["features"] = [f.__dict__ | {"level": str(f.level)} for f in feats]
            if checklist:
                report["checklist"] = {
                    fb.name or "": {
                        row.item: row.value
                        for row in conformance.checklist(fb, bool(doc.comments) or _has_comments(fb))
                    }
                    for fb in doc.blocks
                }
        typer.echo(json.dumps(report, indent=2, default=str))
        raise typer.Exit(EXIT_OK if result.ok else EXIT_ERRORS)

    for d in result.diagnostics:
        style = {Severity.ERROR: "red", Severity.WARNING: "yellow", Severity.NOTE: "cyan"}[d.severity]
        err_console.print(d.render(result.source.text), style=style, markup=False, highlight=False)
    if not result.ok or doc is None:
        errors = sum(1 for d in result.diagnostics if d.is_error)
        err_console.print(f"{file}: {errors} error(s)", markup=False)
        raise typer.Exit(EXIT_ERRORS)
    out = Console(highlight=False, soft_wrap=False, width=max(100, Console().width))
    warnings = sum(1 for d in result.diagnostics if d.severity is Severity.WARNING)
    names = ", ".join(fb.name or "(unnamed)" for fb in doc.blocks)
    out.print(f"{file}: OK ({warnings} warning(s)); function block(s): {names}", markup=False)
    out.print(f"Conformance level needed: {lvl}", markup=False)
    if feats:
        table = Table(title="Features beyond the Basic level (Table 8)", title_justify="left")
        table.add_column("level", overflow="fold")
        table.add_column("table", overflow="fold")
        table.add_column("language element", overflow="fold")
        table.add_column("detail", overflow="fold")
        for f in feats:
            table.add_row(str(f.level), f.table, f.element, f.detail)
        out.print(table)
    if checklist:
        for fb in doc.blocks:
            table = Table(title=f"Data check list (Table 11): {fb.name or '(unnamed)'}", title_justify="left")
            table.add_column("technical data", overflow="fold")
            table.add_column("this file", justify="right", overflow="fold")
            for row in conformance.checklist(fb, bool(doc.comments) or _has_comments(fb)):
                table.add_row(row.item, row.value)
            out.print(table)
        if any("*" in row.item for fb in doc.blocks for row in conformance.checklist(fb, False)):
            out.print("* parametric shapes count their parameters as points", markup=False)
    raise typer.Exit(EXIT_OK)


def _has_comments(fb: object) -> bool:
    from fuzzyctl.fcl.checks import term_blocks
    from fuzzyctl.model import FunctionBlock

    assert isinstance(fb, FunctionBlock)
    items: list[object] = [fb, *fb.variables, *fb.fuzzify, *fb.defuzzify, *fb.rule_blocks]
    for block in term_blocks(fb):
        items.extend(block.terms)
    for rb in fb.rule_blocks:
        items.extend(rb.rules)
    return any(getattr(i, "comments", ()) for i in items)


@app.command()
def fmt(
    file: Annotated[Path, typer.Argument(help="FCL file to format.", show_default=False)],
    output: Annotated[
        Path | None, typer.Option("-o", "--output", help="Write to this file instead of standard output.")
    ] = None,
    in_place: Annotated[bool, typer.Option("--in-place", "-i", help="Rewrite FILE itself.")] = False,
) -> None:
    """Print an FCL file in canonical IEC 61131-7 form (exit 1 if it does not load)."""
    from fuzzyctl.fcl import write

    if output is not None and in_place:
        err_console.print("error: use either --output or --in-place, not both", markup=False)
        raise typer.Exit(EXIT_USAGE)
    result = _load(file)
    document = result.raise_for_errors()
    text = write(document)
    target = file if in_place else output
    if target is None:
        sys.stdout.write(text)
        return
    from fuzzyctl.files import write_atomic

    write_atomic(target, text)
