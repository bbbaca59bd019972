"""``fuzzyctl studio [FILE]``: the browser configuration tool (docs/studio.md)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from fuzzyctl.cli.app import app, err_console


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
            help="require this token (at least 16 characters), or 'auto' for a random one; "
            "default: a random one when listening beyond loopback, none on loopback",
        ),
    ] = None,
    open_browser: Annotated[bool, typer.Option("--open/--no-open", help="open a web browser")] = False,
) -> None:
    """Start the studio: edit, analyse, simulate and download fuzzy knowledge bases in a
    web browser.  Prints its URL; Ctrl-C stops it."""
    import secrets
    import socket
    import urllib.parse

    import uvicorn

    from fuzzyctl.diagnostics import FuzzyctlError
    from fuzzyctl.studio import create_app

    project_root = root or (file.parent if file is not None else Path.cwd())
    project_root = project_root.resolve()
    relative = None
    if file is not None:
        full = file.resolve()
        if not full.is_file():
            raise FuzzyctlError(f"{file}: no such file")
        if not full.is_relative_to(project_root):
            raise FuzzyctlError(f"{file} is not inside the project directory {project_root}")
        relative = full.relative_to(project_root).as_posix()
    loopback = host in ("127.0.0.1", "localhost", "::1")
    if token == "auto" or (token is None and not loopback):
        token = secrets.token_urlsafe(24)
    elif token is not None and len(token) < 16:
        raise typer.BadParameter(
            "a token has at least 16 characters (or use --token auto)", param_hint="--token"
        )
    application = create_app(project_root, file=relative, host=host, token=token)
    sock = socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind((host, port))
        sock.listen(128)  # the URL printed below accepts connections at once (queued until uvicorn runs)
    except OSError as exc:
        raise FuzzyctlError(f"cannot listen on {host}:{port}: {exc.strerror or exc}") from None
    bound = sock.getsockname()[1]
    shown = "127.0.0.1" if host in ("127.0.0.1", "0.0.0.0") else host
    url = f"http://{shown}:{bound}/" + (f"?token={urllib.parse.quote(token)}" if token else "")
    if not loopback:
        err_console.print(
            f"warning: listening on {host}: whoever has the URL (its token) can read and write "
            f"{project_root}",
            markup=False,
        )
    elif token is None:
        err_console.print(
            "warning: the studio has no token: any program or user on this machine can use it "
            "(--token auto requires one)",
            markup=False,
        )
    typer.echo(f"fuzzyctl studio on {url}  (project directory {project_root}; Ctrl-C stops)", err=False)
    if open_browser:
        import webbrowser

        webbrowser.open(url)
    config = uvicorn.Config(application, log_level="warning", lifespan="off")
    server = uvicorn.Server(config)
    server.run(sockets=[sock])
