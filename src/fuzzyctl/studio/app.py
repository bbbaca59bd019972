"""The studio's HTTP API (FastAPI) and its static front end.

The browser holds the model being edited (fuzzyctl's JSON form) and sends it with every
request; the server checks it, writes it as FCL, evaluates it with the engine, runs the
simulated process and talks to a running ``fuzzyctl serve``.  Files are read and written
only inside the project directory.  docs/studio.md is the user's guide.

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

import base64
import binascii
import hashlib
import math
from pathlib import Path
from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import FileResponse, JSONResponse, RedirectResponse, Response
from fastapi.staticfiles import StaticFiles

from fuzzyctl import __version__
from fuzzyctl.diagnostics import DiagnosticError, FuzzyctlError, InputError
from fuzzyctl.files import ReadOnlyError, check_writable
from fuzzyctl.model import Document, FunctionBlock
from fuzzyctl.studio import analysis, api_editing, findings, online, viewsettings
from fuzzyctl.studio.project import (
    MAX_FILE,
    FileProblem,
    PathError,
    ProjectDir,
    check_save_name,
    os_problem,
    save_atomically,
    sha256,
    split_settings,
)
from fuzzyctl.studio.schemas import (
    DownloadBody,
    ExplainBody,
    ExportBody,
    ImportBody,
    ModelBody,
    OnlineBody,
    OnlineCommandBody,
    PathBody,
    RecordBody,
    SaveBody,
    SimStartBody,
    SimStepBody,
    SurfaceBody,
    TextBody,
)
from fuzzyctl.studio.simulate import SimSessions, describe_configs
from fuzzyctl.webguard import LOOPBACK_NAMES, Guard, Refusal, bearer_token, token_matches

STATIC = Path(__file__).parent / "static"
MAX_BODY = 16 * 1024 * 1024
LOCAL_HOSTS = {"127.0.0.1", "localhost", "[::1]", "::1"}
COOKIE_PREFIX = "fuzzyctl_studio_"


def cookie_name(token: str) -> str:
    """The cookie holding ``token``: named after a digest of it, because browsers share
    cookies between the ports of a host (a second studio must not log the first one out)."""
    return COOKIE_PREFIX + hashlib.sha256(token.encode()).hexdigest()[:16]


def plotly_bundle() -> Path:
    """plotly.js as shipped inside the ``plotly`` Python package (offline, no CDN)."""
    import plotly

    path = Path(plotly.__file__).parent / "package_data" / "plotly.min.js"
    if not path.is_file():
        raise FuzzyctlError(f"plotly.min.js not found in the plotly package ({path})")
    return path


def _clean(obj: Any) -> Any:
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: _clean(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_clean(v) for v in obj]
    return obj


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
    cache = analysis.ControllerCache()
    sims = SimSessions()
    plotly_js = plotly_bundle()
    app = FastAPI(
        title="fuzzyctl studio",
        version=__version__,
        description="Edit, analyse, simulate and download fuzzy knowledge bases (docs/studio.md).",
        openapi_url="/api/openapi.json",
        docs_url="/api/docs" if api_docs else None,
        redoc_url=None,
    )

    @app.exception_handler(RequestValidationError)
    async def _invalid(_request: Request, exc: RequestValidationError) -> JSONResponse:
        # The field and the reason, never the value sent (which may be megabytes).
        errors = [
            {
                "type": e.get("type"),
                "loc": [str(x)[:64] for x in e.get("loc", ())],
                "msg": str(e.get("msg"))[:200],
            }
            for e in exc.errors()[:20]
        ]
        return JSONResponse({"detail": errors}, status_code=422)

    @app.exception_handler(PathError)
    async def _path_error(_request: Request, exc: PathError) -> JSONResponse:
        return JSONResponse({"detail": str(exc)}, status_code=403)

    @app.exception_handler(FileProblem)
    async def _file_problem(_request: Request, exc: FileProblem) -> JSONResponse:
        return JSONResponse({"detail": str(exc)}, status_code=exc.status)

    @app.exception_handler(ReadOnlyError)
    async def _read_only(_request: Request, exc: ReadOnlyError) -> JSONResponse:
        name = project.relative(exc.path)
        return JSONResponse(
            {
                "detail": f"{name} is read-only: not saved (make it writable, or save under another name)",
                "readonly": True,
            },
            status_code=403,
        )

    @app.exception_handler(OSError)
    async def _os_error(request: Request, exc: OSError) -> JSONResponse:
        # The routes that touch files say which file; this is the net under the others.
        problem = os_problem(exc, request.url.path, "answer")
        return JSONResponse({"detail": str(problem)}, status_code=problem.status)

    @app.exception_handler(online.OnlineError)
    async def _online_error(_request: Request, exc: online.OnlineError) -> JSONResponse:
        return JSONResponse(
            {"detail": str(exc), "status": exc.status, "runtime": _clean(exc.body)}, status_code=502
        )

    @app.exception_handler(DiagnosticError)
    async def _diagnostics(_request: Request, exc: DiagnosticError) -> JSONResponse:
        return JSONResponse(
            {"detail": exc.render(), "diagnostics": [d.to_dict() for d in exc.diagnostics]}, status_code=422
        )

    @app.exception_handler(FuzzyctlError)
    async def _error(_request: Request, exc: FuzzyctlError) -> JSONResponse:
        return JSONResponse({"detail": str(exc)}, status_code=422)

    # ------------------------------------------------------------------ helpers

    def model_of(body: ModelBody, *, validated: bool = True) -> tuple[Document, FunctionBlock]:
        document, _settings = split_settings(analysis.document_from_json(body.document, validated=validated))
        if not document.blocks:
            raise FuzzyctlError("the model has no function block")
        if body.block >= len(document.blocks):
            raise FuzzyctlError(f"block {body.block}: the model has {len(document.blocks)} function block(s)")
        return document, document.blocks[body.block]

    def settings_of(body: ModelBody) -> dict[str, Any]:
        return body.settings.model_dump(exclude_none=True)

    def opened(path: Path, text: str) -> dict[str, Any]:
        """What the browser gets for a file: the model, the settings, the check report."""
        from fuzzyctl.formats import read_text

        rel = project.relative(path)
        suffix = path.suffix.lower()
        if suffix == ".fcl":
            report = analysis.check_text(text, rel)
            if report.document is None:
                return {
                    "path": rel,
                    "text": text,
                    "sha256": sha256(text),
                    "document": None,
                    **report.to_dict(),
                }
            document, settings = split_settings(report.document)
            settings = viewsettings.merged(project.root, rel, settings)
        else:
            document, settings = split_settings(read_text(text, suffix.lstrip("."), path=rel).document)
            report = analysis.check_text(analysis.fcl_text(document), rel)
            return {
                "path": None,
                "imported_from": rel,
                "text": analysis.fcl_text(document),
                "sha256": None,
                "document": analysis.document_to_json(document),
                "settings": settings,
                **analysis.views(document, settings),
                **report.to_dict(),
            }
        return {
            "path": rel,
            "text": text,
            "sha256": sha256(text),
            "document": analysis.document_to_json(document),
            "settings": settings,
            **analysis.views(document, settings),
            **report.to_dict(),
        }

    # ------------------------------------------------------------------ files

    @app.get("/api/info")
    def info() -> dict[str, Any]:
        """Version, project directory, the file opened at start, formats, and the name limits
        of the S7 configuration tool its dialogs check (the siemens profile's)."""
        from fuzzyctl import formats
        from fuzzyctl.blocks.siemens.profile import LIMITS

        return {
            "version": __version__,
            "root": str(project.root),
            "file": file,
            "siemens_limits": {k: LIMITS[k] for k in ("project_name", "variable_name", "term_name")},
            "formats": [
                {
                    "name": f.name,
                    "extensions": list(f.extensions),
                    "read": f.read is not None,
                    "write": f.write is not None,
                    "description": f.description,
                }
                for f in formats.available()
            ],
        }

    @app.get("/api/files")
    def files() -> dict[str, Any]:
        """The files of the project directory the studio can open."""
        return {"root": str(project.root), "files": project.listing()}

    @app.post("/api/open")
    def open_file(body: PathBody) -> Any:
        """Read a project file (FCL), or import another format (it then has no path until
        it is saved as FCL)."""
        path = project.resolve(body.path, must_exist=True)
        from fuzzyctl.formats import decode

        try:
            size = path.stat().st_size
            if size > MAX_FILE:
                raise FileProblem(
                    413,
                    f"{body.path} is too big: {size / 2**20:.1f} MB, the studio opens files of up to "
                    f"{MAX_FILE // 2**20} MB",
                )
            data = path.read_bytes()
        except OSError as exc:
            raise os_problem(exc, body.path, "open") from None
        text = decode(data)
        return _clean(opened(path, text))

    @app.post("/api/save")
    def save(body: SaveBody) -> Any:
        """Write the model as FCL, atomically; the view settings go to a sidecar
        (studio/viewsettings.py), never into the file.  Refused when the file changed on
        disk since it was opened."""
        if not body.path.lower().endswith(".fcl"):
            raise PathError("projects are FCL files: the name must end in .fcl")
        check_save_name(body.path)
        path = project.resolve(body.path)
        check_save_name(project.relative(path))  # a symbolic link into .git/ is refused too
        document, _fb = model_of(body)
        text = analysis.fcl_text(document)  # the user's file only: view settings beside it
        try:
            result = saved(body, path, text)
        except OSError as exc:
            raise os_problem(exc, body.path, "save") from None
        if isinstance(result, dict):
            viewsettings.write_settings(project.root, project.relative(path), settings_of(body))
        return result

    def saved(body: SaveBody, path: Path, text: str) -> Any:
        check_writable(path)  # told at once, not after "Replace it?"
        if path.exists():
            current = sha256(path.read_text(encoding="utf-8", errors="replace"))
            if body.expected_sha256 is None and not body.overwrite:
                return JSONResponse({"detail": f"{body.path} exists", "exists": True}, status_code=409)
            if body.expected_sha256 is not None and body.expected_sha256 != current and not body.overwrite:
                return JSONResponse(
                    {"detail": f"{body.path} was changed on disk since it was opened", "changed": True},
                    status_code=409,
                )
        save_atomically(path, text)
        report = analysis.check_text(text, body.path)
        return {"path": project.relative(path), "sha256": sha256(text), "text": text, **report.to_dict()}

    # ------------------------------------------------------------------ checking

    @app.post("/api/check")
    def check(body: ModelBody) -> Any:
        """``fuzzyctl check`` of the model: diagnostics tied to elements, the conformance
        level, the FCL text, display ranges.  An invalid model (points out of order) is
        answered like any other: its report says why, tied to the term (the editor shows it);
        the FCL text goes through the same validation as every reader's."""
        document, fb = model_of(body, validated=False)
        text = analysis.fcl_text(document)
        report = analysis.check_text(text)
        ranges = analysis.display_ranges(fb, settings_of(body))
        return _clean(
            {
                "text": text,
                "ranges": ranges,
                "curves": analysis.curves(fb, ranges),
                "fcl_losses": analysis.fcl_losses(document),
                **report.to_dict(),
            }
        )

    @app.post("/api/parse")
    def parse(body: TextBody) -> Any:
        """The text editor: check FCL text; the model when it has no errors."""
        report = analysis.check_text(body.text)
        out: dict[str, Any] = report.to_dict()
        if report.document is not None:
            document, settings = split_settings(report.document)
            out["document"] = analysis.document_to_json(document)
            out["settings"] = settings
            out["ranges"] = analysis.display_ranges(document.main, settings)
        else:
            out["document"] = None
        return _clean(out)

    # ------------------------------------------------------------------ analysis

    @app.post("/api/surface")
    def surface(body: SurfaceBody) -> Any:
        """The 3D display: an output over two inputs (``evaluate_batch``), optionally one
        frame per step of a third input (4D); every grid point is a fresh evaluation."""
        _doc, fb = model_of(body)
        ranges = analysis.display_ranges(fb, settings_of(body))
        return analysis.surface(
            cache.get(analysis.pointwise(fb), "surface"),
            fb,
            x=body.x,
            y=body.y,
            z=body.z,
            fixed=body.fixed,
            ranges=ranges,
            points=body.points,
            animate=body.animate,
            step_percent=body.step_percent,
        )

    @app.post("/api/explain")
    def explain(body: ExplainBody) -> Any:
        """Term degrees, rule degrees, accumulated sets and outputs at one point."""
        _doc, fb = model_of(body)
        return analysis.explain(cache.get(fb, "explain"), body.inputs)

    @app.post("/api/record")
    def record(body: RecordBody) -> Any:
        """The curve recorder's off-line test: test signals at the given times and the
        outputs of successive evaluations (``reset`` starts a new recording)."""
        _doc, fb = model_of(body)
        ranges = analysis.display_ranges(fb, settings_of(body))
        signals = {k: v.model_dump() for k, v in body.signals.items()}
        return analysis.record(
            cache.get(fb, "recorder"),
            fb,
            signals=signals,
            times=body.times,
            length=body.length,
            ranges=ranges,
            reset=body.reset,
        )

    # ------------------------------------------------------------------ formats

    @app.post("/api/import")
    def import_file(body: ImportBody) -> Any:
        """Read an uploaded file in any format ``fuzzyctl convert`` knows."""
        from fuzzyctl import formats

        try:
            data = base64.b64decode(body.data_base64, validate=True)
        except (binascii.Error, ValueError):
            raise InputError("data_base64 is not base64") from None
        fmt = formats.get(body.format) if body.format else formats.for_path(body.filename)
        loaded = formats.read_text(formats.decode(data), fmt.name, path=body.filename)
        document, settings = split_settings(loaded.document)
        text = analysis.fcl_text(document)
        report = analysis.check_text(text)
        return _clean(
            {
                "format": fmt.name,
                "document": analysis.document_to_json(document),
                "settings": settings,
                "text": text,
                **analysis.views(document, settings),
                "warnings": [d.to_dict() for d in loaded.diagnostics],
                **report.to_dict(),
            }
        )

    @app.post("/api/export")
    def export(body: ExportBody) -> Any:
        """The model in another format.  Without ``lossy`` a format that cannot express
        everything answers ``losses`` and no text, so the browser can ask first."""
        from fuzzyctl import formats

        document, _fb = model_of(body)
        fmt = formats.get(body.format)
        if fmt.write is None:
            raise FuzzyctlError(f"format {fmt.name!r} can be read but not written")
        losses = [str(loss) for loss in fmt.losses(document)]
        if losses and not body.lossy:
            return {"format": fmt.name, "losses": losses, "text": None}
        text, _ = formats.convert(document, fmt.name, lossy=True)
        name = (document.main.name or "project") + fmt.extensions[0]
        return {"format": fmt.name, "losses": losses, "text": text, "filename": name}

    # ------------------------------------------------------------------ simulation

    @app.get("/api/sim/configs")
    def sim_configs(current: str | None = None) -> Any:
        """The loop configurations (TOML) in the project directory."""
        listing = [f["path"] for f in project.listing()]
        return {"configs": _clean(describe_configs(project.root, listing, current))}

    @app.post("/api/sim/start")
    def sim_start(body: SimStartBody) -> Any:
        """Build the loop of a configuration around the edited knowledge base."""
        path = project.resolve(body.config, must_exist=True)
        _doc, fb = model_of(body)
        _sid, result = sims.start(path, fb, parameters=body.parameters, setpoints=body.setpoints)
        return _clean(result)

    @app.post("/api/sim/step")
    def sim_step(body: SimStepBody) -> Any:
        """Run the next ``seconds`` of a loop; the rows recorded."""
        try:
            return sims.step(body.id, body.seconds)
        except KeyError:
            return JSONResponse(
                {"detail": "no such simulation (it was stopped or replaced)"}, status_code=404
            )

    @app.delete("/api/sim/{sid}")
    def sim_stop(sid: str) -> dict[str, bool]:
        return {"stopped": sims.stop(sid)}

    # ------------------------------------------------------------------ on line

    @app.post("/api/online/instances")
    def online_instances(body: OnlineBody) -> Any:
        """Connect: the runtime's health and instances."""
        health = online.call(body.url, "GET", "/health")
        instances = online.call(body.url, "GET", "/instances", token=body.token)
        return {"health": health, "instances": instances, "api": online.base_url(body.url)}

    @app.post("/api/online/read")
    def online_read(body: OnlineBody) -> Any:
        """Live values of the chosen instance."""
        if not body.instance:
            raise InputError("choose an instance")
        return online.call(body.url, "GET", f"/instances/{online.quote(body.instance)}", token=body.token)

    @app.post("/api/online/command")
    def online_command(body: OnlineCommandBody) -> Any:
        """START_STOP, MAN_AUTO, forcing and manual values (need the token)."""
        if not body.instance:
            raise InputError("choose an instance")
        base = f"/instances/{online.quote(body.instance)}"
        tok = body.token
        if body.action in ("start", "stop"):
            return online.call(
                body.url, "PUT", f"{base}/start_stop", token=tok, body={"running": body.action == "start"}
            )
        if body.action in ("auto", "manual"):
            return online.call(body.url, "PUT", f"{base}/mode", token=tok, body={"mode": body.action})
        if not body.target:
            raise InputError(f"{body.action}: name the input or output")
        target = online.quote(body.target)
        if body.action == "release":
            return online.call(body.url, "DELETE", f"{base}/force/{target}", token=tok)
        if body.value is None:
            raise InputError(f"{body.action}: give a value")
        where = "force" if body.action == "force" else "manual"
        return online.call(body.url, "PUT", f"{base}/{where}/{target}", token=tok, body={"value": body.value})

    @app.post("/api/online/diff")
    def online_diff(body: DownloadBody) -> Any:
        """The running knowledge base and the edited one, both as FCL (the confirm
        dialog of a download shows their difference)."""
        if not body.instance:
            raise InputError("choose an instance")
        running = online.knowledge_base_fcl(body.url, body.instance, token=body.token)
        _document, fb = model_of(body)
        return {"running": running, "edited": analysis.fcl_text(Document((fb,)))}

    @app.post("/api/online/download")
    def online_download(body: DownloadBody) -> Any:
        """Send the edited knowledge base (FCL, without the studio's settings)."""
        if not body.instance:
            raise InputError("choose an instance")
        _document, fb = model_of(body)
        text = analysis.fcl_text(Document((fb,)))
        return online.call(
            body.url,
            "PUT",
            f"/instances/{online.quote(body.instance)}/knowledge_base",
            token=body.token,
            body={"text": text, "format": "fcl"},
        )

    # ------------------------------------------------------------------ front end

    @app.get("/vendor/plotly.min.js", include_in_schema=False)
    def plotly_file() -> FileResponse:
        return FileResponse(
            plotly_js, media_type="text/javascript", headers={"Cache-Control": "max-age=86400"}
        )

    @app.get("/", include_in_schema=False)
    def index(request: Request) -> Response:
        if token is not None and "token" in request.query_params:
            # The front door checked it: keep it in a cookie, and take it out of the address bar.
            from urllib.parse import urlencode

            rest = [(k, v) for k, v in request.query_params.multi_items() if k != "token"]
            target = "/" + ("?" + urlencode(rest) if rest else "")
            response = RedirectResponse(target, status_code=303)
            response.set_cookie(cookie_name(token), token, httponly=True, samesite="strict", path="/")
            return response
        return FileResponse(STATIC / "index.html", headers={"Cache-Control": "no-cache"})

    app.include_router(api_editing.router(cache))
    app.include_router(findings.router())
    app.mount("/static", StaticFiles(directory=STATIC), name="static")
    return Guard(
        app,
        hosts=sorted(LOOPBACK_NAMES) if host in LOCAL_HOSTS else None,
        origin_on_reads=False,
        max_body=lambda _method, _path: MAX_BODY,
        authorize=None if token is None else studio_authorizer(token),
        json_only=lambda path: path.startswith("/api/"),
    )
