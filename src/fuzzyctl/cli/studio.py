"""``fuzzyctl studio [FILE]``: the browser configuration tool (docs/studio.md)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from fuzzyctl.cli.app import app, err_console, usage_errors


@app.command()
def studio(
    file: Annotated[
        Path | None,
        typer.Argument(help="FCL file to open (its directory is the project directory).", show_default=False),
    ] = None,
    root: Annotated[
        Path | None,
        typer.Option("--root", help="project directory (default: FILE's directory, else the current one)"),
    ] = None,
    host: Annotated[
        str, typer.Option("--host", help="address to listen on; anything but 127.0.0.1 exposes your files")
    ] = "127.0.0.1",
    port: Annotated[int, typer.Option("--port", min=0, max=65535, help="0 picks a free port")] = 8770,
    token: Annotated[
        str | None,
        typer.Option(
            "--token",
            help="require this token (at least 16 characters); default: a random one, in the URL printed",
        ),
    ] = None,
    no_token: Annotated[
        bool,
        typer.Option(
            "--no-token",
            help="require no token: any program or user on this machine (or the network) can use the studio",
        ),
    ] = False,
    view: Annotated[
        str | None, typer.Option("--view", help="the view the printed URL opens (e.g. recorder)")
    ] = None,
    api_docs: Annotated[
        bool,
        typer.Option(
            "--api-docs",
            help="serve the API description at /api/docs (Swagger UI, whose scripts come from a CDN)",
        ),
    ] = False,
    open_browser: Annotated[bool, typer.Option("--open/--no-open", help="open a web browser")] = False,
) -> None:
    """Start the studio: edit, analyse, simulate and download fuzzy knowledge bases in a
    web browser.  Prints its URL (with the token the browser needs); Ctrl-C stops it."""
    from fuzzyctl.studio.launch import prepare, run

    with usage_errors():
        launch = prepare(
            file,
            root=root,
            host=host,
            port=port,
            token=token,
            no_token=no_token,
            view=view,
            api_docs=api_docs,
        )
    for warning in launch.warnings:
        err_console.print(f"warning: {warning}", markup=False)
    typer.echo(f"fuzzyctl studio on {launch.url}  (project directory {launch.root}; Ctrl-C stops)", err=False)
    if open_browser:
        import webbrowser

        webbrowser.open(launch.url)
    run(launch)
