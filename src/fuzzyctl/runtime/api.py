"""The runtime's local HTTP + WebSocket API (FastAPI), for the studio and for scripts.

Everything is under ``/api/v1``; the OpenAPI description is at ``/api/v1/openapi.json``
and browsable at ``/api/v1/docs``.  Reading needs nothing; every request that changes
something needs ``Authorization: Bearer <token>`` (the token file is written at the
first start with mode 0600).  Request bodies are pydantic models: a wrong type, a missing
or unknown field is a 422 naming it.  Errors are ``{"detail": "..."}``: 400 a value the
block refuses, 401 a missing or wrong token, 404 an unknown instance, 409 an operation
the block style does not have, 422 an invalid request or knowledge base (with
``diagnostics``).

docs/runtime.md has the reference with curl examples.
"""

# No `from __future__ import annotations`: FastAPI resolves the Annotated aliases defined
# inside create_app() at run time.

import asyncio
import contextlib
import math
import secrets
import time
from typing import TYPE_CHECKING, Annotated, Any, Literal

from fastapi import Depends, FastAPI, HTTPException, Path, Query, Request, WebSocket, WebSocketDisconnect
from fastapi.encoders import jsonable_encoder
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from fastapi.security import HTTPAuthorizationCredentials, HTTPBearer
from pydantic import BaseModel, ConfigDict, Field

from fuzzyctl import __version__
from fuzzyctl.diagnostics import DiagnosticError, FuzzyctlError, InputError
from fuzzyctl.runtime.adapters import NotSupported

if TYPE_CHECKING:
    from fuzzyctl.runtime.core import Runtime
    from fuzzyctl.runtime.instance import Instance

__all__ = ["API_PREFIX", "create_app"]

API_PREFIX = "/api/v1"
Number = float | int | None


def clean(obj: Any) -> Any:
    """JSON-safe: NaN and infinities become null (JSON has no NaN)."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: clean(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [clean(v) for v in obj]
    return obj


# ---------------------------------------------------------------------------- models


class _Body(BaseModel):
    model_config = ConfigDict(extra="forbid")


class StartStopBody(_Body):
    running: bool = Field(description="true: START_STOP = 16#FFFF (siemens) / START = 1 (xfuz); false: 0")


class ParametersBody(_Body):
    values: dict[str, float] = Field(
        min_length=1, description='parameters by manual name, e.g. {"START_STOP": 65535} or {"MAN_AUTO": 1}'
    )


class ModeBody(_Body):
    mode: Literal["auto", "manual"]


class ValueBody(_Body):
    value: float = Field(allow_inf_nan=False)


class DownloadBody(_Body):
    text: str = Field(min_length=1, max_length=5_000_000, description="the knowledge base source")
    format: str = Field(default="fcl", description="fcl, fpl, xfuz, fis, fll or json")


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


def create_app(runtime: "Runtime") -> FastAPI:
    """The API of a runtime (its token must be set: ``runtime.token``)."""
    app = FastAPI(
        title="fuzzyctl runtime",
        version=__version__,
        description="Live view and control of the fuzzy function blocks run by `fuzzyctl serve`.",
        openapi_url=f"{API_PREFIX}/openapi.json",
        docs_url=f"{API_PREFIX}/docs",
        redoc_url=None,
    )
    started = time.monotonic()
    bearer = HTTPBearer(auto_error=False, description="the token from the runtime's token file")

    def require_token(
        creds: Annotated[HTTPAuthorizationCredentials | None, Depends(bearer)],
    ) -> None:
        expected = runtime.token
        if (
            expected is None
            or creds is None
            or creds.scheme.lower() != "bearer"
            or not secrets.compare_digest(creds.credentials.encode(), expected.encode())
        ):
            raise HTTPException(
                status_code=401,
                detail="a valid token is required: Authorization: Bearer <token from the token file>",
                headers={"WWW-Authenticate": "Bearer"},
            )

    Writer = Annotated[None, Depends(require_token)]
    InstanceName = Annotated[str, Path(description="instance name (the [instances.<name>] table)")]

    def get_instance(name: str) -> "Instance":
        if name not in runtime.instances:
            raise HTTPException(404, f"no instance {name!r}")
        return runtime.instances[name]

    @app.exception_handler(RequestValidationError)
    async def _invalid_request(_request: Request, exc: RequestValidationError) -> JSONResponse:
        # FastAPI's own handler echoes the input, which may be NaN (not JSON): clean it.
        return JSONResponse({"detail": clean(jsonable_encoder(exc.errors()))}, status_code=422)

    @app.exception_handler(InputError)
    async def _input_error(_request: Request, exc: InputError) -> JSONResponse:
        return JSONResponse({"detail": str(exc)}, status_code=409 if isinstance(exc, NotSupported) else 400)

    @app.exception_handler(DiagnosticError)
    async def _diag_error(_request: Request, exc: DiagnosticError) -> JSONResponse:
        return JSONResponse(
            {"detail": exc.render(), "diagnostics": [d.to_dict() for d in exc.diagnostics]}, status_code=422
        )

    @app.exception_handler(FuzzyctlError)
    async def _fuzzyctl_error(_request: Request, exc: FuzzyctlError) -> JSONResponse:
        return JSONResponse({"detail": str(exc)}, status_code=422)

    # --- reading -------------------------------------------------------------------

    @app.get(f"{API_PREFIX}/health", response_model=Health, tags=["read"])
    def health() -> dict[str, Any]:
        """Liveness: the runtime answers."""
        return {
            "status": "ok",
            "version": __version__,
            "instances": len(runtime.instances),
            "uptime": time.monotonic() - started,
        }

    @app.get(f"{API_PREFIX}/instances", response_model=list[InstanceSummary], tags=["read"])
    def list_instances() -> list[dict[str, Any]]:
        """Every instance with its state, INFO/STATUS and link states."""
        out = []
        for inst in runtime.instances.values():
            s = inst.snapshot()
            out.append(
                {
                    "name": s["name"],
                    "style": s["style"],
                    "period": s["period"],
                    "state": s["state"],
                    "status": s["status"],
                    "cycles": s["cycles"],
                    "overruns": s["overruns"],
                    "last_duration": s["last_cycle"]["duration"] if s["last_cycle"] else None,
                    "links": s["links"],
                    "error": s["error"],
                }
            )
        return out

    @app.get(f"{API_PREFIX}/instances/{{name}}", response_model=InstanceDetail, tags=["read"])
    def read_instance(name: InstanceName) -> Any:
        """Live values of one instance, consistent with one cycle boundary."""
        return clean(get_instance(name).snapshot())

    @app.get(f"{API_PREFIX}/instances/{{name}}/statistics", response_model=Statistics, tags=["read"])
    def read_statistics(name: InstanceName) -> Any:
        """Cycle statistics (seconds): counts over the run, percentiles over the last
        2000 cycles."""
        return get_instance(name).statistics()

    @app.get(f"{API_PREFIX}/statistics", response_model=dict[str, Statistics], tags=["read"])
    def read_all_statistics() -> Any:
        return {n: i.statistics() for n, i in runtime.instances.items()}

    @app.get(f"{API_PREFIX}/links", response_model=dict[str, LinkInfo], tags=["read"])
    def read_links() -> Any:
        """Every connection: state, endpoint, counters, last error."""
        return runtime.links_state()

    @app.get(f"{API_PREFIX}/events", response_model=EventPage, tags=["read"])
    def read_events(
        after: Annotated[int, Query(ge=0, description="only events with a larger seq")] = 0,
        limit: Annotated[int, Query(ge=1, le=10000)] = 1000,
        kind: Annotated[list[str] | None, Query(description="only these kinds")] = None,
    ) -> Any:
        """The event log, oldest first; page with ``after`` = the last seq you have."""
        events = runtime.events.since(after, limit, set(kind) if kind else None)
        return {
            "first_seq": runtime.events.first_seq,
            "last_seq": runtime.events.last_seq,
            "events": [clean(e.to_dict()) for e in events],
        }

    # --- writing -------------------------------------------------------------------

    @app.put(f"{API_PREFIX}/instances/{{name}}/start_stop", tags=["write"])
    def start_stop(name: InstanceName, body: StartStopBody, _: Writer) -> dict[str, int]:
        """Siemens: START_STOP = 16#FFFF or 0.  XFUZ: START = 1 or 0."""
        inst = get_instance(name)
        if inst.adapter.style == "siemens":
            return {"START_STOP": inst.set_parameter("START_STOP", 0xFFFF if body.running else 0)}
        return {"START": inst.set_parameter("START", 1 if body.running else 0)}

    @app.patch(f"{API_PREFIX}/instances/{{name}}/parameters", tags=["write"])
    def set_parameters(name: InstanceName, body: ParametersBody, _: Writer) -> dict[str, int]:
        """Write block parameters by manual name (validated by the block style; all or
        nothing is checked first)."""
        return get_instance(name).set_parameters(body.values)

    @app.put(f"{API_PREFIX}/instances/{{name}}/mode", tags=["write"])
    def set_mode(name: InstanceName, body: ModeBody, _: Writer) -> dict[str, int]:
        """XFUZ MAN_AUTO (manual: OUTi = Oi_MAN; auto: OUTi = Oi_CALC)."""
        inst = get_instance(name)
        inst.set_mode(body.mode == "auto")
        return {"MAN_AUTO": int(body.mode == "auto")}

    @app.put(f"{API_PREFIX}/instances/{{name}}/force/{{input}}", tags=["write"])
    def force(name: InstanceName, input: str, body: ValueBody, _: Writer) -> dict[str, float]:
        """Force an input (XFUZ: Ii_SIM and COMMAND bit; Siemens: the runtime's force
        table).  Returns every forced input."""
        return get_instance(name).force(input, body.value)

    @app.delete(f"{API_PREFIX}/instances/{{name}}/force/{{input}}", tags=["write"])
    def release(name: InstanceName, input: str, _: Writer) -> dict[str, float]:
        """Release a forced input."""
        return get_instance(name).force(input, None)

    @app.put(f"{API_PREFIX}/instances/{{name}}/manual/{{output}}", tags=["write"])
    def manual(name: InstanceName, output: str, body: ValueBody, _: Writer) -> dict[str, float]:
        """XFUZ Oi_MAN, the output value in manual mode."""
        get_instance(name).set_manual(output, body.value)
        return {output: body.value}

    @app.put(
        f"{API_PREFIX}/instances/{{name}}/knowledge_base",
        response_model=DownloadResult,
        tags=["write"],
        responses={422: {"description": "the knowledge base cannot be used (diagnostics included)"}},
    )
    def download(name: InstanceName, body: DownloadBody, _: Writer) -> Any:
        """Online download: replace the knowledge base while the instance runs (Siemens:
        stop, transfer, restart; XFUZ: REFRESH), atomically between two cycles."""
        get_instance(name)
        return runtime.download(name, body.text, body.format, origin="api")

    # --- live ----------------------------------------------------------------------

    @app.websocket(f"{API_PREFIX}/live")
    async def live(
        ws: WebSocket,
        rate: Annotated[float, Query(gt=0, le=20)] = 10.0,
        instances: Annotated[str | None, Query(description="comma-separated names (default all)")] = None,
        events: Annotated[bool, Query(description="also push new events")] = True,
    ) -> None:
        """Pushes ``{"type": "snapshot", "time", "instances": {name: detail}, "events": [...]}``
        ``rate`` times a second (at most 20)."""
        names = list(runtime.instances) if not instances else [n for n in instances.split(",") if n]
        unknown = [n for n in names if n not in runtime.instances]
        await ws.accept()
        if unknown:
            await ws.send_json({"type": "error", "detail": f"no instance {', '.join(map(repr, unknown))}"})
            await ws.close(code=1008)
            return
        rate = min(rate, runtime.config.api.live_rate_max)
        last_seq = runtime.events.last_seq
        loop = asyncio.get_running_loop()
        next_time = loop.time()
        try:
            while True:
                message: dict[str, Any] = {
                    "type": "snapshot",
                    "time": time.time(),
                    "instances": {n: runtime.instances[n].snapshot() for n in names},
                }
                if events:
                    new = runtime.events.since(last_seq, 1000)
                    if new:
                        last_seq = new[-1].seq
                    message["events"] = [e.to_dict() for e in new]
                await ws.send_json(clean(message))
                next_time += 1.0 / rate
                delay = next_time - loop.time()
                if delay < 0:
                    next_time = loop.time()
                    delay = 0
                with contextlib.suppress(asyncio.TimeoutError):
                    await asyncio.wait_for(ws.receive_text(), delay)
        except WebSocketDisconnect:
            return

    return app
