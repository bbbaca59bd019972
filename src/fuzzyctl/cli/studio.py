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
    if no_token and token is not None:
        raise typer.BadParameter("give either --token or --no-token", param_hint="--no-token")
    if no_token:
        token = None
    elif token is None or token == "auto":  # 'auto': what the default was called before
        token = secrets.token_urlsafe(24)
    elif len(token) < 16:
        raise typer.BadParameter("a token has at least 16 characters", param_hint="--token")
    application = create_app(project_root, file=relative, host=host, token=token, api_docs=api_docs)
    sock = socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind((host, port))
        sock.listen(128)  # the URL printed below accepts connections at once (queued until uvicorn runs)
    except OSError as exc:
        raise FuzzyctlError(f"cannot listen on {host}:{port}: {exc.strerror or exc}") from None
    bound = sock.getsockname()[1]
    shown = "127.0.0.1" if host in ("127.0.0.1", "0.0.0.0") else host
    query = ([("view", view)] if view else []) + ([("token", token)] if token else [])
    url = f"http://{shown}:{bound}/" + (f"?{urllib.parse.urlencode(query)}" if query else "")
    if token is None:
        where = "on this machine" if loopback else f"that reaches {host}"
        err_console.print(
            f"warning: --no-token: any program or user {where} can read and write {project_root} "
            "through the studio",
            markup=False,
        )
    elif not loopback:
        err_console.print(
            f"warning: listening on {host}: whoever has the URL (its token) can read and write "
            f"{project_root}",
            markup=False,
        )
    if api_docs:
        err_console.print(
            "warning: --api-docs: the page at /api/docs loads Swagger UI from a CDN (third-party "
            "code in a page of the studio)",
            markup=False,
        )
    typer.echo(f"fuzzyctl studio on {url}  (project directory {project_root}; Ctrl-C stops)", err=False)
    if open_browser:
        import webbrowser

        webbrowser.open(url)
    config = uvicorn.Config(application, log_level="warning", lifespan="off")
    server = uvicorn.Server(config)
    server.run(sockets=[sock])
