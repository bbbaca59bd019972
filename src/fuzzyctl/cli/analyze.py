"""``fuzzyctl analyze FILE``: gaps, conflicts, redundancy, monotonicity and surface facts of a
rule base (docs/analyze.md).  The work is :func:`fuzzyctl.analyze`; this only prints it."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer

from fuzzyctl.cli.app import app


@app.command()
def analyze(
    file: Annotated[
        Path, typer.Argument(help="The fuzzy system (FCL, FIS, FLL, ...).", exists=True, dir_okay=False)
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
) -> None:
    """Find where no rule fires (gaps), rules that contradict each other, duplicate, subsumed
    and dead rules, unused terms, monotonicity violations and the output surface's range,
    slope and jumps, before the controller meets the plant."""
    import fuzzyctl
    from fuzzyctl.analysis import analyze as run

    result = run(fuzzyctl.load(file), block=block, epsilon=epsilon, delta=delta, monotone=monotone or ())
    if as_json:
        typer.echo(json.dumps(result.to_json(), allow_nan=False, default=str))
        return
    from rich.console import Console

    console = Console(highlight=False, soft_wrap=True)
    console.print(
        f"[bold]{file}[/bold]: block {result.block}, {result.cells} cells"
        + ("" if result.exact else " (not exact, see notes)")
    )
    for line in result.lines():
        console.print(line, markup=False)
