"""Starting the studio (what ``fuzzyctl studio`` does): the project directory and the file
opened at start, the token, the listening socket, the URL to open and the warnings the
user must see; then :func:`run` serves it until Ctrl-C."""

from __future__ import annotations

import socket
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fuzzyctl.diagnostics import FuzzyctlError, OptionError

LOOPBACK = ("127.0.0.1", "localhost", "::1")
MIN_TOKEN = 16


@dataclass
class Launch:
    """A studio ready to serve: the app, the socket it listens on (accepting at once), the
    URL with the token, and the warnings to print before it."""

    app: Any
    sock: socket.socket
    url: str
    root: Path
    warnings: list[str] = field(default_factory=list)


def project(file: Path | None, root: Path | None) -> tuple[Path, str | None]:
    """The project directory (``root``, else the file's directory, else the current one) and
    ``file`` relative to it; a missing file or one outside the directory is an error."""
    project_root = (root or (file.parent if file is not None else Path.cwd())).resolve()
    if file is None:
        return project_root, None
    full = file.resolve()
    if not full.is_file():
        raise FuzzyctlError(f"{file}: no such file")
    if not full.is_relative_to(project_root):
        raise FuzzyctlError(f"{file} is not inside the project directory {project_root}")
    return project_root, full.relative_to(project_root).as_posix()


def studio_token(token: str | None, no_token: bool) -> str | None:
    """The token every request needs: the one given, a fresh random one (none given, or
    ``auto``, what the default was called before), or None with ``no_token``."""
    import secrets

    if no_token and token is not None:
        raise OptionError("give either --token or --no-token", "--no-token")
    if no_token:
        return None
    if token is None or token == "auto":
        return secrets.token_urlsafe(24)
    if len(token) < MIN_TOKEN:
        raise OptionError(f"a token has at least {MIN_TOKEN} characters", "--token")
    return token


def prepare(
    file: Path | None = None,
    *,
    root: Path | None = None,
    host: str = "127.0.0.1",
    port: int = 0,
    token: str | None = None,
    no_token: bool = False,
    view: str | None = None,
    api_docs: bool = False,
) -> Launch:
    """The studio for ``file`` (or the project directory ``root``), listening on
    ``host``:``port`` (0: any free port)."""
    import urllib.parse

    from fuzzyctl.studio import create_app

    project_root, relative = project(file, root)
    token = studio_token(token, no_token)
    application = create_app(project_root, file=relative, host=host, token=token, api_docs=api_docs)
    sock = _listen(host, port)
    shown = "127.0.0.1" if host in ("127.0.0.1", "0.0.0.0") else host
    query = ([("view", view)] if view else []) + ([("token", token)] if token else [])
    url = f"http://{shown}:{sock.getsockname()[1]}/" + (f"?{urllib.parse.urlencode(query)}" if query else "")
    return Launch(application, sock, url, project_root, _warnings(host, token, project_root, api_docs))


def _listen(host: str, port: int) -> socket.socket:
    sock = socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind((host, port))
        sock.listen(128)  # the URL printed accepts connections at once (queued until uvicorn runs)
    except OSError as exc:
        raise FuzzyctlError(f"cannot listen on {host}:{port}: {exc.strerror or exc}") from None
    return sock


def _warnings(host: str, token: str | None, root: Path, api_docs: bool) -> list[str]:
    loopback = host in LOOPBACK
    out = []
    if token is None:
        where = "on this machine" if loopback else f"that reaches {host}"
        out.append(f"--no-token: any program or user {where} can read and write {root} through the studio")
    elif not loopback:
        out.append(f"listening on {host}: whoever has the URL (its token) can read and write {root}")
    if api_docs:
        out.append(
            "--api-docs: the page at /api/docs loads Swagger UI from a CDN (third-party code in a page "
            "of the studio)"
        )
    return out


def run(launch: Launch) -> None:
    """Serve until Ctrl-C."""
    import uvicorn

    config = uvicorn.Config(launch.app, log_level="warning", lifespan="off")
    uvicorn.Server(config).run(sockets=[launch.sock])
