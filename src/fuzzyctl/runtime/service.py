"""What the runtime API can do, as plain calls on a running :class:`Runtime` that return
JSON-ready data or raise :class:`ServiceError` with the HTTP status to answer.

The HTTP server does not run in the runtime's process (:mod:`.apiserver`): it forwards
each request that passed its checks (host, origin, token, size, schema) as one call
``Service.call(op, args)`` over a local socket (:mod:`.rpc`).  So the work done here on
the runtime's interpreter, beside the cycle thread, is small and bounded: no request
parsing, no JSON of a whole request, no waiting on a client.  Snapshots are shared for
``SNAPSHOT_TTL`` so that several live clients cost as much as one.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from fuzzyctl import __version__
from fuzzyctl.diagnostics import DiagnosticError, FuzzyctlError, InputError
from fuzzyctl.jsonsafe import clean

if TYPE_CHECKING:
    from fuzzyctl.runtime.core import Runtime
    from fuzzyctl.runtime.instance import Instance

__all__ = ["MAX_DIAGNOSTICS", "SNAPSHOT_TTL", "Service", "ServiceError", "short"]

SNAPSHOT_TTL = 0.04  # s: live clients at 20 Hz share one snapshot per instance and tick
MAX_DIAGNOSTICS = 50  # diagnostics returned for a refused download
MAX_TEXT = 300  # characters of a message that may quote what a client sent


class ServiceError(FuzzyctlError):
    """A refusal with its HTTP status (400 a value the block refuses, 404 no such
    instance, 409 an operation the block style lacks or a download in progress, 422 a
    knowledge base that cannot be used, 500 a bug)."""

    def __init__(self, status: int, detail: str, diagnostics: list[dict[str, Any]] | None = None) -> None:
        super().__init__(detail)
        self.status = status
        self.detail = detail
        self.diagnostics = diagnostics

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"status": self.status, "detail": self.detail}
        if self.diagnostics is not None:
            out["diagnostics"] = self.diagnostics
        return out


def short(text: str, limit: int = MAX_TEXT) -> str:
    """At most ``limit`` characters (a message may quote a name a client sent)."""
    return text if len(text) <= limit else text[: limit - 1] + "…"


def as_service_error(exc: BaseException) -> ServiceError:
    """The refusal for an exception raised by the runtime."""
    if isinstance(exc, ServiceError):
        return exc
    if isinstance(exc, DiagnosticError):
        diags = exc.diagnostics[:MAX_DIAGNOSTICS]
        lines = [short(f"{d.location()}: {d.severity.value}: {d.message}") for d in diags]
        if len(exc.diagnostics) > MAX_DIAGNOSTICS:
            lines.append(f"... {len(exc.diagnostics) - MAX_DIAGNOSTICS} more")
        # The messages and places only: no source excerpt, nothing of the sent text echoed.
        return ServiceError(
            422,
            "\n".join(lines),
            [{**d.to_dict(), "message": short(d.message), "hint": d.hint and short(d.hint)} for d in diags],
        )
    from fuzzyctl.runtime.adapters import NotSupported  # here: the API process never needs it

    if isinstance(exc, NotSupported):
        return ServiceError(409, short(str(exc)))
    if isinstance(exc, InputError):
        return ServiceError(400, short(str(exc), 1000))
    if isinstance(exc, FuzzyctlError):
        return ServiceError(422, short(str(exc), 1000))
    return ServiceError(500, f"internal error: {type(exc).__name__}")


class Service:
    """The operations of the API on one runtime (thread-safe)."""

    def __init__(self, runtime: Runtime) -> None:
        self.runtime = runtime
        self.started = time.monotonic()
        self._cache: dict[str, tuple[float, dict[str, Any]]] = {}
        self._cache_lock = threading.Lock()
        self._download_lock = threading.Lock()
        self._ops: dict[str, Callable[..., Any]] = {
            name: getattr(self, name)
            for name in (
                "health", "instances", "instance", "statistics", "all_statistics", "knowledge_base",
                "links", "events", "live_start", "live", "start_stop", "set_parameters", "set_mode",
                "force", "release", "manual", "download",
            )
        }  # fmt: skip

    def call(self, op: str, args: dict[str, Any]) -> Any:
        """Run one operation; every failure is a :class:`ServiceError`."""
        method = self._ops.get(op)
        if method is None:
            raise ServiceError(500, f"internal error: no operation {short(op, 40)!r}")
        try:
            return method(**args)
        except TypeError as exc:
            raise ServiceError(500, f"internal error: bad arguments for {op}") from exc
        except Exception as exc:
            raise as_service_error(exc) from exc

    # ------------------------------------------------------------------ helpers

    def _instance(self, name: str) -> Instance:
        inst = self.runtime.instances.get(name)
        if inst is None:
            raise ServiceError(404, f"no instance {short(name, 64)!r}")
        return inst

    def _snapshot(self, name: str) -> dict[str, Any]:
        now = time.monotonic()
        with self._cache_lock:
            hit = self._cache.get(name)
        if hit is not None and now - hit[0] < SNAPSHOT_TTL:
            return hit[1]
        snap: dict[str, Any] = clean(self._instance(name).snapshot())
        with self._cache_lock:
            self._cache[name] = (now, snap)
        return snap

    # ------------------------------------------------------------------ reading

    def health(self) -> dict[str, Any]:
        return {
            "status": "ok",
            "version": __version__,
            "instances": len(self.runtime.instances),
            "uptime": time.monotonic() - self.started,
        }

    def instances(self) -> list[dict[str, Any]]:
        out = []
        for name in self.runtime.instances:
            s = self._snapshot(name)
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

    def instance(self, name: str) -> dict[str, Any]:
        self._instance(name)
        return self._snapshot(name)

    def statistics(self, name: str) -> dict[str, Any]:
        stats: dict[str, Any] = self._instance(name).statistics()
        return stats

    def all_statistics(self) -> dict[str, Any]:
        return {n: i.statistics() for n, i in self.runtime.instances.items()}

    def knowledge_base(self, name: str) -> dict[str, Any]:
        source = self._instance(name).knowledge_base_source()
        return {
            "format": source.format,
            "origin": source.origin,
            "sha256": source.sha256,
            "text": source.text,
        }

    def links(self) -> dict[str, Any]:
        return self.runtime.links_state()

    def events(self, after: int, limit: int, kinds: list[str] | None) -> dict[str, Any]:
        log = self.runtime.events
        found = log.since(after, limit, set(kinds) if kinds else None)
        return {
            "first_seq": log.first_seq,
            "last_seq": log.last_seq,
            "events": [clean(e.to_dict()) for e in found],
        }

    def live_start(self, names: list[str]) -> dict[str, Any]:
        """Check the instances of a live stream; the event sequence it starts after."""
        unknown = [n for n in names if n not in self.runtime.instances]
        if unknown:
            raise ServiceError(404, "no instance " + ", ".join(repr(short(n, 64)) for n in unknown[:5]))
        return {"names": names or list(self.runtime.instances), "last_seq": self.runtime.events.last_seq}

    def live(self, names: list[str], after: int, events: bool) -> dict[str, Any]:
        """One message of the live stream: snapshots, and the events after ``after``."""
        out: dict[str, Any] = {
            "type": "snapshot",
            "time": time.time(),
            "instances": {n: self._snapshot(n) for n in names if n in self.runtime.instances},
        }
        last = after
        if events:
            new = self.runtime.events.since(after, 1000)
            if new:
                last = new[-1].seq
            out["events"] = [clean(e.to_dict()) for e in new]
        out["last_seq"] = last
        return out

    # ------------------------------------------------------------------ writing

    def _changed(self, name: str) -> None:
        with self._cache_lock:
            self._cache.pop(name, None)  # the next read shows the change

    def start_stop(self, name: str, running: bool) -> dict[str, int]:
        inst = self._instance(name)
        if inst.adapter.style == "siemens":
            out = {"START_STOP": inst.set_parameter("START_STOP", 0xFFFF if running else 0)}
        else:
            out = {"START": inst.set_parameter("START", 1 if running else 0)}
        self._changed(name)
        return out

    def set_parameters(self, name: str, values: dict[str, float]) -> dict[str, int]:
        out = self._instance(name).set_parameters(values)
        self._changed(name)
        return out

    def set_mode(self, name: str, mode: str) -> dict[str, int]:
        self._instance(name).set_mode(mode == "auto")
        self._changed(name)
        return {"MAN_AUTO": int(mode == "auto")}

    def force(self, name: str, input: str, value: float) -> dict[str, float]:
        out = self._instance(name).force(input, value)
        self._changed(name)
        return out

    def release(self, name: str, input: str) -> dict[str, float]:
        out = self._instance(name).force(input, None)
        self._changed(name)
        return out

    def manual(self, name: str, output: str, value: float) -> dict[str, float]:
        self._instance(name).set_manual(output, value)
        self._changed(name)
        return {output: value}

    def download(self, name: str, text: str, format: str) -> dict[str, Any]:
        self._instance(name)
        # One at a time: a download parses and builds outside the cycle, on this process.
        if not self._download_lock.acquire(blocking=False):
            raise ServiceError(409, "another download is in progress; try again when it is done")
        try:
            result = self.runtime.download(name, text, format, origin="api")
        finally:
            self._download_lock.release()
        self._changed(name)
        return result
