"""The runtime's HTTP + WebSocket API (FastAPI), for the studio and for scripts.

Everything is under ``/api/v1``; the OpenAPI description is at ``/api/v1/openapi.json``,
and browsable at ``/api/v1/docs`` when ``[api] docs = true`` (off by default: that page
loads Swagger UI from a CDN - no installed package ships it - into the page where the token
is typed).  Every request but ``/health`` and the API description needs
``Authorization: Bearer <token>`` (unless ``serve --no-token``): the write token (file
``api-token``) for everything, or the read-only token (file ``api-token-read``) for
reading; the WebSocket also takes ``?token=``.  The front door (:mod:`fuzzyctl.webguard`)
refuses a foreign Host (DNS rebinding), a foreign Origin (cross-origin reads, cross-site
WebSocket), a missing token before the body is read, and a body over the limit
(Content-Length or chunked).

Request bodies are strict pydantic models: a wrong type (``"yes"`` for a boolean, ``"1"``
for a number), a missing or unknown field is a 422 naming it, never echoing the value.
Errors are ``{"detail": "..."}``: 400 a value the block refuses, 401 no or a wrong token,
403 a refused host, origin or token, 404 an unknown instance, 409 an operation the block
style does not have, 413 a body too large, 422 an invalid request or knowledge base (with
``diagnostics``).

The app talks to the runtime through a backend: in ``fuzzyctl serve`` the API runs in its
own process (:mod:`.apiserver`) and the backend forwards each call over a local socket
(:mod:`.rpc`), so that no HTTP work runs on the interpreter of the cycle thread;
:class:`LocalBackend` calls a :class:`~.service.Service` in the same process (tests).

docs/runtime.md has the reference with curl examples.
"""

# No `from __future__ import annotations`: FastAPI resolves the Annotated aliases defined
# inside create_app() at run time.

import asyncio
import contextlib
from dataclasses import dataclass, field
from typing import Annotated, Any, Literal, Protocol

import anyio
from fastapi import Depends, FastAPI, Path, Query, Request, WebSocket
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from fastapi.security import HTTPAuthorizationCredentials, HTTPBearer
from pydantic import BaseModel, ConfigDict, Field, StringConstraints

from fuzzyctl import __version__, formats
from fuzzyctl.runtime.service import Service, ServiceError, short
from fuzzyctl.webguard import LOOPBACK_NAMES, Guard, Refusal, bearer_token, token_matches

__all__ = ["API_PREFIX", "ApiSettings", "Backend", "LocalBackend", "create_app"]

API_PREFIX = "/api/v1"
OPEN_PATHS = frozenset(
    f"{API_PREFIX}/{p}" for p in ("health", "openapi.json", "docs", "docs/oauth2-redirect")
)
SMALL_BODY = 64 * 1024  # every request body but a knowledge base
Number = float | int | None
Name = Annotated[str, StringConstraints(min_length=1, max_length=64)]


class Backend(Protocol):
    """How the app reaches the runtime: one awaitable call per operation of
    :class:`~fuzzyctl.runtime.service.Service`."""

    async def call(self, op: str, **args: Any) -> Any: ...


class LocalBackend:
    """A :class:`Service` in this process, called on a worker thread."""

    def __init__(self, service: Service) -> None:
        self.service = service

    async def call(self, op: str, **args: Any) -> Any:
        return await anyio.to_thread.run_sync(lambda: self.service.call(op, args))


@dataclass(frozen=True)
class ApiSettings:
    """What the app needs to know besides the backend."""

    token: str | None
    """The write token; None: no token at all (``serve --no-token``), every request passes."""
    read_token: str | None = None
    hosts: list[str] | None = field(default_factory=lambda: sorted(LOOPBACK_NAMES))
    """Host names answered (None: any); see :func:`allowed_hosts`."""
    origins: list[str] = field(default_factory=list)
    max_body: int = 8 * 1024 * 1024
    live_rate_max: float = 20.0
    live_clients_max: int = 8
    docs: bool = False
    """Serve Swagger UI at ``/api/v1/docs`` (its scripts come from a CDN)."""


# ---------------------------------------------------------------------------- models


class _Body(BaseModel):
    # strict: "yes" is not a boolean, "1" not a number (JSON's own types only)
    model_config = ConfigDict(extra="forbid", strict=True)


class StartStopBody(_Body):
    running: bool = Field(description="true: START_STOP = 16#FFFF (siemens) / START = 1 (xfuz); false: 0")


class ParametersBody(_Body):
    values: dict[Name, float] = Field(
        min_length=1,
        max_length=64,
        description='parameters by manual name, e.g. {"START_STOP": 65535} or {"MAN_AUTO": 1}',
    )


class ModeBody(_Body):
    mode: Literal["auto", "manual"]


class ValueBody(_Body):
    value: float = Field(allow_inf_nan=False)


class DownloadBody(_Body):
    text: str = Field(min_length=1, max_length=5_000_000, description="the knowledge base source")
    format: str = Field(default="fcl", max_length=16, description=formats.names_text(" or "))


class Health(BaseModel):
    status: Literal["ok"]
    version: str
    instances: int
    uptime: float


class InstanceSummary(BaseModel):
    name: str
    style: str
    period: float
    state: str
    status: dict[str, int]
    cycles: int
    overruns: int
    last_duration: float | None
    links: dict[str, str]
    error: str | None


class LastCycle(BaseModel):
    start: float
    duration: float
    jitter: float


class KnowledgeBaseInfo(BaseModel):
    origin: str
    format: str
    sha256: str
    inputs: list[str]
    outputs: list[str]


class InstanceDetail(BaseModel):
    name: str
    style: str
    period: float
    state: Literal["run", "hold", "safe"]
    state_since: float
    problems: dict[str, list[str]]
    error: str | None
    status: dict[str, int]
    inputs: dict[str, Number]
    outputs: dict[str, Number]
    field_outputs: dict[str, Number]
    parameters: dict[str, Number]
    forced: dict[str, float]
    cycles: int
    overruns: int
    last_cycle: LastCycle | None
    links: dict[str, str]
    knowledge_base: KnowledgeBaseInfo
    downloads: int


class Statistics(BaseModel):
    period: float
    cycles: int
    overruns: int
    skipped: int
    jitter_mean: float
    jitter_max: float
    duration_mean: float
    duration_max: float
    kept: int
    jitter_p50: float
    jitter_p95: float
    jitter_p99: float
    duration_p50: float
    duration_p99: float
    last_duration: float
    interval_mean: float


class EventModel(BaseModel):
    seq: int
    time: str
    mono: float
    kind: str
    level: str
    message: str
    instance: str | None
    link: str | None
    data: dict[str, Any]


class EventPage(BaseModel):
    first_seq: int = Field(description="oldest event still in memory (older ones are in the event file)")
    last_seq: int
    events: list[EventModel]


class LinkInfo(BaseModel):
    type: str
    endpoint: str
    state: str
    exchanges: int
    failures: int
    connects: int
    last_exchange_ms: float
    last_error: str | None
    points: int


class KnowledgeBaseText(BaseModel):
    format: str
    origin: str
    sha256: str
    text: str


class DownloadResult(BaseModel):
    format: str
    origin: str
    sha256: str
    inputs: list[str]
    outputs: list[str]
    source: str
    procedure: str
    time: float


# ---------------------------------------------------------------------------- app


def authorizer(settings: ApiSettings) -> Any:
    """The token check of the front door: the write token for everything, the read-only
    token for GET/HEAD and the WebSocket; ``/health`` and the API description are open."""

    def authorize(scope: dict[str, Any], headers: dict[str, str]) -> Refusal | None:
        path = scope["path"]
        if path in OPEN_PATHS or settings.token is None:
            return None
        given = bearer_token(headers)
        reading = scope["type"] == "websocket" or scope.get("method") in ("GET", "HEAD")
        if given is None and scope["type"] == "websocket":
            from urllib.parse import parse_qs

            values = parse_qs(scope.get("query_string", b"").decode("latin-1")).get("token")
            given = values[0] if values else None
        if token_matches(given, settings.token):
            return None
        if token_matches(given, settings.read_token):
            if reading:
                return None
            return Refusal(403, "the read-only token cannot change anything; use the write token")
        return Refusal(
            401,
            "a valid token is required: Authorization: Bearer <token from the token file>",
            (("WWW-Authenticate", "Bearer"),),
        )

    return authorize


def _errors(exc: RequestValidationError) -> list[dict[str, Any]]:
    """Validation errors naming the field, never the value sent (no "input", no "ctx")."""
    return [
        {
            "type": e.get("type"),
            "loc": [short(str(x), 64) if isinstance(x, str) else x for x in e.get("loc", ())],
            "msg": short(str(e.get("msg", "")), 200),
        }
        for e in exc.errors()[:20]
    ]


# The front door has checked the token already; this declares it in the OpenAPI
# description (the lock in /api/v1/docs).
_bearer = HTTPBearer(auto_error=False, description="the write token, or the read-only token for reading")


def _documented(_creds: Annotated[HTTPAuthorizationCredentials | None, Depends(_bearer)]) -> None:
    return None


Token = Annotated[None, Depends(_documented)]
InstanceName = Annotated[
    str, Path(description="instance name (the [instances.<name>] table)", max_length=200)
]
PointName = Annotated[str, Path(description="an input or output name", max_length=64)]


def create_app(backend: Backend, settings: ApiSettings) -> Any:
    """The API (an ASGI app: FastAPI behind :class:`~fuzzyctl.webguard.Guard`)."""
    app = FastAPI(
        title="fuzzyctl runtime",
        version=__version__,
        description="Live view and control of the fuzzy function blocks run by `fuzzyctl serve`.",
        openapi_url=f"{API_PREFIX}/openapi.json",
        docs_url=f"{API_PREFIX}/docs" if settings.docs else None,
        redoc_url=None,
    )

    @app.exception_handler(RequestValidationError)
    async def _invalid_request(_request: Request, exc: RequestValidationError) -> JSONResponse:
        return JSONResponse({"detail": _errors(exc)}, status_code=422)

    @app.exception_handler(ServiceError)
    async def _refused(_request: Request, exc: ServiceError) -> JSONResponse:
        body: dict[str, Any] = {"detail": exc.detail}
        if exc.diagnostics is not None:
            body["diagnostics"] = exc.diagnostics
        return JSONResponse(body, status_code=exc.status)

    _reading(app, backend)
    _writing(app, backend)
    _live(app, backend, settings)

    def max_body(_method: str, path: str) -> int:
        return settings.max_body if path.endswith("/knowledge_base") else SMALL_BODY

    return Guard(
        app,
        hosts=settings.hosts,
        origins=settings.origins,
        origin_on_reads=True,
        max_body=max_body,
        authorize=authorizer(settings),
        json_only=lambda path: path.startswith(API_PREFIX),
    )


def _reading(app: FastAPI, backend: Backend) -> None:
    @app.get(f"{API_PREFIX}/health", response_model=Health, tags=["read"])
    async def health() -> Any:
        """Liveness: the runtime answers (no token needed)."""
        return await backend.call("health")

    @app.get(f"{API_PREFIX}/instances", response_model=list[InstanceSummary], tags=["read"])
    async def list_instances(_: Token) -> Any:
        """Every instance with its state, INFO/STATUS and link states."""
        return await backend.call("instances")

    @app.get(f"{API_PREFIX}/instances/{{name}}", response_model=InstanceDetail, tags=["read"])
    async def read_instance(name: InstanceName, _: Token) -> Any:
        """Live values of one instance, consistent with one cycle boundary."""
        return await backend.call("instance", name=name)

    @app.get(f"{API_PREFIX}/instances/{{name}}/statistics", response_model=Statistics, tags=["read"])
    async def read_statistics(name: InstanceName, _: Token) -> Any:
        """Cycle statistics (seconds): counts over the run, percentiles over the last
        2000 cycles."""
        return await backend.call("statistics", name=name)

    @app.get(f"{API_PREFIX}/statistics", response_model=dict[str, Statistics], tags=["read"])
    async def read_all_statistics(_: Token) -> Any:
        return await backend.call("all_statistics")

    @app.get(
        f"{API_PREFIX}/instances/{{name}}/knowledge_base", response_model=KnowledgeBaseText, tags=["read"]
    )
    async def read_knowledge_base(name: InstanceName, _: Token) -> Any:
        """The knowledge base the instance runs, as it was loaded or downloaded (the
        studio shows its difference to the edited one before a download)."""
        return await backend.call("knowledge_base", name=name)

    @app.get(f"{API_PREFIX}/links", response_model=dict[str, LinkInfo], tags=["read"])
    async def read_links(_: Token) -> Any:
        """Every connection: state, endpoint, counters, last error."""
        return await backend.call("links")

    @app.get(f"{API_PREFIX}/events", response_model=EventPage, tags=["read"])
    async def read_events(
        _: Token,
        after: Annotated[int, Query(ge=0, description="only events with a larger seq")] = 0,
        limit: Annotated[int, Query(ge=1, le=10000)] = 1000,
        kind: Annotated[list[str] | None, Query(description="only these kinds", max_length=50)] = None,
    ) -> Any:
        """The event log, oldest first; page with ``after`` = the last seq you have."""
        return await backend.call("events", after=after, limit=limit, kinds=kind)


def _writing(app: FastAPI, backend: Backend) -> None:
    @app.put(f"{API_PREFIX}/instances/{{name}}/start_stop", tags=["write"])
    async def start_stop(name: InstanceName, body: StartStopBody, _: Token) -> Any:
        """Siemens: START_STOP = 16#FFFF or 0.  XFUZ: START = 1 or 0."""
        return await backend.call("start_stop", name=name, running=body.running)

    @app.patch(f"{API_PREFIX}/instances/{{name}}/parameters", tags=["write"])
    async def set_parameters(name: InstanceName, body: ParametersBody, _: Token) -> Any:
        """Write block parameters by manual name (validated by the block style; all or
        nothing is checked first)."""
        return await backend.call("set_parameters", name=name, values=body.values)

    @app.put(f"{API_PREFIX}/instances/{{name}}/mode", tags=["write"])
    async def set_mode(name: InstanceName, body: ModeBody, _: Token) -> Any:
        """XFUZ MAN_AUTO (manual: OUTi = Oi_MAN; auto: OUTi = Oi_CALC)."""
        return await backend.call("set_mode", name=name, mode=body.mode)

    @app.put(f"{API_PREFIX}/instances/{{name}}/force/{{input}}", tags=["write"])
    async def force(name: InstanceName, input: PointName, body: ValueBody, _: Token) -> Any:
        """Force an input (XFUZ: Ii_SIM and COMMAND bit; Siemens: the runtime's force
        table).  Returns every forced input.  A value the input's type cannot hold (a
        Siemens REAL: |x| < 3.4e38; an XFUZ word: an integer -32768..32767) is a 400."""
        return await backend.call("force", name=name, input=input, value=body.value)

    @app.delete(f"{API_PREFIX}/instances/{{name}}/force/{{input}}", tags=["write"])
    async def release(name: InstanceName, input: PointName, _: Token) -> Any:
        """Release a forced input."""
        return await backend.call("release", name=name, input=input)

    @app.put(f"{API_PREFIX}/instances/{{name}}/manual/{{output}}", tags=["write"])
    async def manual(name: InstanceName, output: PointName, body: ValueBody, _: Token) -> Any:
        """XFUZ Oi_MAN, the output value in manual mode (an integer -32768..32767)."""
        return await backend.call("manual", name=name, output=output, value=body.value)

    @app.put(
        f"{API_PREFIX}/instances/{{name}}/knowledge_base",
        response_model=DownloadResult,
        tags=["write"],
        responses={422: {"description": "the knowledge base cannot be used (diagnostics included)"}},
    )
    async def download(name: InstanceName, body: DownloadBody, _: Token) -> Any:
        """Online download: replace the knowledge base while the instance runs (Siemens:
        stop, transfer, restart; XFUZ: REFRESH), atomically between two cycles."""
        return await backend.call("download", name=name, text=body.text, format=body.format)


def _live(app: FastAPI, backend: Backend, settings: ApiSettings) -> None:
    clients = [0]  # WebSocket clients now

    @app.websocket(f"{API_PREFIX}/live")
    async def live(
        ws: WebSocket,
        rate: Annotated[float, Query(gt=0, le=20)] = 10.0,
        instances: Annotated[
            str | None, Query(description="comma-separated names (default all)", max_length=10000)
        ] = None,
        events: Annotated[bool, Query(description="also push new events")] = True,
    ) -> None:
        """Pushes ``{"type": "snapshot", "time", "instances": {name: detail}, "events": [...]}``
        ``rate`` times a second (at most 20).  Messages from the client are ignored (text or
        binary); the token is the Authorization header or ``?token=``."""
        if clients[0] >= settings.live_clients_max:
            await ws.close(code=1013)  # try again later (refused at the handshake)
            return
        clients[0] += 1
        try:
            await _stream(ws, rate, instances, events)
        finally:
            clients[0] -= 1

    async def _stream(ws: WebSocket, rate: float, instances: str | None, events: bool) -> None:
        wanted = [n for n in (instances or "").split(",") if n]
        await ws.accept()
        try:
            start = await backend.call("live_start", names=wanted)
        except ServiceError as exc:
            await ws.send_json({"type": "error", "detail": exc.detail})
            await ws.close(code=1008)
            return
        names, last_seq = start["names"], start["last_seq"]
        rate = min(rate, settings.live_rate_max)
        loop = asyncio.get_running_loop()
        next_time = loop.time()
        receiver = asyncio.ensure_future(ws.receive())
        try:
            while True:
                try:
                    message = await backend.call("live", names=names, after=last_seq, events=events)
                except ServiceError:
                    await ws.close(code=1012)  # the runtime is stopping
                    return
                last_seq = message.pop("last_seq")
                await ws.send_json(message)
                next_time = max(next_time + 1.0 / rate, loop.time())
                # Wait for the next tick; whatever the client sends (text, bytes) is ignored.
                while True:
                    done, _ = await asyncio.wait({receiver}, timeout=max(0.0, next_time - loop.time()))
                    if not done:
                        break
                    if receiver.result()["type"] == "websocket.disconnect":
                        return
                    receiver = asyncio.ensure_future(ws.receive())
        except (ConnectionError, RuntimeError):  # the client vanished mid-send
            return
        finally:
            if not receiver.done():
                receiver.cancel()
                with contextlib.suppress(BaseException):
                    await receiver
