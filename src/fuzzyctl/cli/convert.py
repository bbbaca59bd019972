"""``fuzzyctl convert IN OUT``: move a fuzzy system between FCL, FIS, FLL, FPL, XFUZ, JSON."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from fuzzyctl import formats
from fuzzyctl.cli.app import FORCE_HINT, app, err_console


@app.command()
def convert(
    source: Annotated[Path, typer.Argument(help="File to read.", show_default=False)],
    target: Annotated[Path, typer.Argument(help="File to write (replaced atomically).", dir_okay=False)],
    from_format: Annotated[
        str | None,
        typer.Option("--from", help=f"Format of SOURCE ({formats.names_text()}); default: its extension."),
    ] = None,
    to_format: Annotated[
        str | None, typer.Option("--to", help="Format of TARGET; default: its extension.")
    ] = None,
    lossy: Annotated[
        bool,
        typer.Option(
            "--lossy", help="Write even when the target cannot express everything; list what was dropped."
        ),
    ] = False,
    force: Annotated[bool, typer.Option("--force", help="Replace TARGET even when it is read-only.")] = False,
    type1: Annotated[
        bool,
        typer.Option(
            "--type1",
            help="Write an interval type-2 system as type-1: each term its upper function (listed).",
        ),
    ] = False,
) -> None:
    """Convert a fuzzy system to another format.

    A conversion that would change what the system computes fails and lists, one line each,
    what the target format cannot express; --lossy writes it anyway without those elements."""
    from fuzzyctl.api import require_file

    require_file(source)  # before the extension is read: "no such file", not "unknown format"
    loaded = formats.read_path(source, from_format)
    for diagnostic in loaded.diagnostics:
        err_console.print(diagnostic.render(), markup=False)
    fmt = formats.get(to_format) if to_format else formats.for_path(target)
    document, dropped = loaded.document, list[formats.Loss]()
    if type1:
        from fuzzyctl.formats.common.type2 import drop_type2

        document, dropped = drop_type2(document, "a type-1 system")
    text, losses = formats.convert(document, fmt.name, lossy=lossy)
    losses = dropped + losses
    formats.write_atomic(target, text, force=force, hint=FORCE_HINT)
    for note in fmt.notes(loaded.document):
        err_console.print(f"warning: {note}", markup=False)
    for loss in losses:
        err_console.print(f"dropped: {loss}", markup=False)
    typer.echo(f"wrote {target} ({fmt.name}{', lossy' if losses else ''})")
