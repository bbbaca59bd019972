"""The studio's HTTP API (FastAPI) and its static front end.

The browser holds the model being edited (fuzzyctl's JSON form) and sends it with every
request; the server checks it, writes it as FCL, evaluates it with the engine, runs the
simulated process and talks to a running ``fuzzyctl serve``.  Files are read and written
only inside the project directory.  docs/studio.md is the user's guide.  The routes live
in :mod:`fuzzyctl.studio.routes`, one router per area; this module assembles them behind
the front door.

The front door (:mod:`fuzzyctl.webguard`) refuses, before the app sees them: another Host
than the loopback names when bound to loopback (DNS rebinding), writes from another
origin (CSRF), bodies over 16 MB (announced or chunked), and - unless the studio was
started without a token (``--no-token``) - every request without it, on loopback too
(another user of the machine must not read and write your files through it).  The browser
gets the token once from the URL printed at start (``/?token=...``), which sets an
HttpOnly, SameSite=Strict cookie named after the token (two studios on two ports of one
host do not overwrite each other's cookie).

A file the studio cannot read or write answers a status and a message the user can act
on (:class:`~fuzzyctl.studio.project.FileProblem`): 400 a name too long or a path through
a file, 403 a read-only file or directory, 404, 413 a file too big, 507 a full disk.  The
API description (Swagger UI at ``/api/docs``) is off unless ``api_docs``: the page loads
Swagger UI from a CDN, third-party code in a page that holds the token.
"""

# No `from __future__ import annotations`: FastAPI reads the annotations at run time.

from pathlib import Path
from typing import Any

from fastapi import FastAPI
from fastapi.staticfiles import StaticFiles

from fuzzyctl import __version__
from fuzzyctl.studio import findings
from fuzzyctl.studio.project import ProjectDir
from fuzzyctl.studio.routes import analysis, editing, errors, files, front, online, simulation
from fuzzyctl.studio.routes.front import STATIC, cookie_name, plotly_bundle
from fuzzyctl.studio.routes.state import Studio
from fuzzyctl.webguard import LOOPBACK_NAMES, Guard, Refusal, bearer_token, token_matches

MAX_BODY = 16 * 1024 * 1024
LOCAL_HOSTS = {"127.0.0.1", "localhost", "[::1]", "::1"}
ROUTERS = (files, editing, analysis, findings, simulation, online, front)
"""One router per area, in the order they are matched."""


def _cookie_token(headers: dict[str, str], name: str) -> str | None:
    for part in headers.get("cookie", "").split(";"):
        key, _, value = part.strip().partition("=")
        if key == name:
            return value
    return None


def studio_authorizer(token: str) -> Any:
    """Every request needs the token: ``Authorization: Bearer``, the cookie, or (for the
    page itself, ``GET /``) ``?token=``."""

    cookie = cookie_name(token)

    def authorize(scope: dict[str, Any], headers: dict[str, str]) -> Refusal | None:
        given = bearer_token(headers) or _cookie_token(headers, cookie)
        if given is None and scope["path"] == "/":
            from urllib.parse import parse_qs

            values = parse_qs(scope.get("query_string", b"").decode("latin-1")).get("token")
            given = values[0] if values else None
        if token_matches(given, token):
            return None
        return Refusal(
            401,
            "this studio needs its token: open the URL it printed at start (/?token=...)",
            (("WWW-Authenticate", "Bearer"),),
        )

    return authorize


def create_app(
    root: str | Path,
    *,
    file: str | None = None,
    host: str = "127.0.0.1",
    token: str | None,
    api_docs: bool = False,
) -> Any:
    """The studio for the project directory ``root``; ``file`` (relative to it) is opened
    at start.  Bound to loopback, requests naming another host are refused (DNS
    rebinding); writes from another origin are refused (CSRF); with ``token``, every
    request needs it - a caller says ``token=None`` explicitly to serve without one
    (docs/studio.md, "Security").  ``api_docs`` serves Swagger UI at ``/api/docs`` (it
    loads its scripts from a CDN)."""
    project = ProjectDir.at(root)
    if file is not None:
        project.resolve(file)
    app = FastAPI(
        title="fuzzyctl studio",
        version=__version__,
        description="Edit, analyse, simulate and download fuzzy knowledge bases (docs/studio.md).",
        openapi_url="/api/openapi.json",
        docs_url="/api/docs" if api_docs else None,
        redoc_url=None,
    )
    app.state.studio = Studio(project, file, token, plotly_bundle())
    errors.add_handlers(app)
    for area in ROUTERS:
        app.include_router(area.router)
    app.mount("/static", StaticFiles(directory=STATIC), name="static")
    return Guard(
        app,
        hosts=sorted(LOOPBACK_NAMES) if host in LOCAL_HOSTS else None,
        origin_on_reads=False,
        max_body=lambda _method, _path: MAX_BODY,
        authorize=None if token is None else studio_authorizer(token),
        json_only=lambda path: path.startswith("/api/"),
    )
