"""The connector interface every field protocol implements.

A *point* is one value in the field (an OPC UA node, a Modbus register pair, an S7 REAL
in a data block); its address is a frozen pydantic model owned by the protocol module, so
the runtime's configuration validates addresses with the protocol's own rules.  A
connector reads and writes *batches* of points so that each protocol can group them into
as few requests as it can.

Connectors are asyncio objects: the runtime runs them all on one I/O event loop, apart
from the real-time cycle thread, and talks to them only through its process image.
"""

from __future__ import annotations

import abc
import asyncio
import importlib
import queue
import threading
from collections.abc import Awaitable, Mapping, Sequence
from concurrent.futures import Executor, Future
from enum import StrEnum
from typing import Any, ClassVar, TypeVar

from pydantic import BaseModel, ConfigDict

from fuzzyctl.diagnostics import FuzzyctlError

T = TypeVar("T")

__all__ = [
    "CONNECTION_TYPES",
    "Connector",
    "DaemonExecutor",
    "LinkError",
    "LinkState",
    "Point",
    "bounded",
    "create_connector",
]


class LinkState(StrEnum):
    """State of a connection, as the runtime shows it."""

    DOWN = "down"
    """Not connected (never connected yet, or lost); the runtime retries with back-off."""
    UP = "up"
    """Connected, and the last batch went through."""
    CLOSED = "closed"
    """Closed on purpose (runtime stopping)."""


class LinkError(FuzzyctlError):
    """A connection failed (refused, timed out, lost, or the peer answered with an error
    for a whole batch).  The runtime then treats the link as down."""


class Point(BaseModel):
    """Base of the protocol address models.  Frozen and strict about unknown keys, so a
    misspelt key in a configuration file is reported instead of ignored."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    def describe(self) -> str:
        """A short human-readable address (``DB1.DBD8``, ``holding 40..41``)."""
        return repr(self)


class Connector(abc.ABC):
    """One connection to the field (client) or one endpoint the field talks to (server).

    Subclasses set :attr:`point_model` and implement the five coroutines.  ``read`` and
    ``write`` raise :class:`LinkError` when the connection is unusable; the runtime then
    closes the connector and reconnects with back-off."""

    point_model: ClassVar[type[Point]]
    """The pydantic model of this protocol's point addresses."""
    options_model: ClassVar[type[BaseModel]]
    """The pydantic model of the connection's options (host, port, ...)."""
    server: ClassVar[bool] = False
    """True for a connector that serves (the field connects to us)."""

    def __init__(self, name: str, options: Any) -> None:
        self.name = name
        self.options = options

    @classmethod
    def from_options(cls, name: str, options: Mapping[str, Any]) -> Connector:
        """Build from a mapping of options (raises pydantic's ValidationError)."""
        return cls(name, cls.options_model.model_validate(dict(options)))

    def parse_point(self, spec: Mapping[str, Any]) -> Point:
        """Validate an address given as a mapping (a TOML inline table); raises
        pydantic's ValidationError naming the key."""
        return self.point_model.model_validate(dict(spec))

    @abc.abstractmethod
    async def connect(self) -> None:
        """Open the connection (or start serving).  Raises LinkError."""

    @abc.abstractmethod
    async def read(self, points: Sequence[Point]) -> list[float]:
        """Read every point; one float per point (NaN where the field holds NaN)."""

    @abc.abstractmethod
    async def write(self, points: Sequence[Point], values: Sequence[float]) -> None:
        """Write ``values[i]`` to ``points[i]``."""

    @abc.abstractmethod
    async def close(self) -> None:
        """Close the connection (or stop serving); never raises."""

    def endpoint(self) -> str:
        """Where this connector connects or listens, for logs and the live table."""
        return self.name

    def live(self, link: T | None, state: str = "not connected") -> T:
        """``link`` (the client or server object of a subclass), or :class:`LinkError` naming
        :meth:`endpoint` when it is closed: ``read`` and ``write`` start with it."""
        if link is None:
            raise LinkError(f"{self.endpoint()}: {state}")
        return link


# type name in the configuration -> (module, factory function)
CONNECTION_TYPES: dict[str, tuple[str, str]] = {
    "opcua": ("fuzzyctl.io.opcua", "OpcUaClient"),
    "opcua-server": ("fuzzyctl.io.opcua", "OpcUaServer"),
    "modbus": ("fuzzyctl.io.modbus", "ModbusClient"),
    "modbus-server": ("fuzzyctl.io.modbus", "ModbusServer"),
    "s7": ("fuzzyctl.io.s7", "S7Client"),
}


def connector_class(kind: str) -> type[Connector]:
    """The connector class of a configuration ``type`` (imports its protocol library)."""
    try:
        module_name, attr = CONNECTION_TYPES[kind]
    except KeyError:
        raise LinkError(f"unknown connection type {kind!r} (one of {', '.join(CONNECTION_TYPES)})") from None
    cls = getattr(importlib.import_module(module_name), attr)
    assert isinstance(cls, type) and issubclass(cls, Connector)
    return cls


def create_connector(kind: str, name: str, options: Mapping[str, Any]) -> Connector:
    """Build a connector from its configuration ``type`` and options (validated by the
    connector's own ``Options`` model)."""
    return connector_class(kind).from_options(name, options)


async def bounded(awaitable: Awaitable[T], timeout: float, what: str, *, stated: float | None = None) -> T:
    """Await with a deadline that holds even when the awaited library swallows the
    cancellation (``asyncio.wait_for`` waits for the cancelled task to finish; a protocol
    stack stuck in its own retry loop would then hang the link).  The error names
    ``stated`` as the time allowed when given (the configured bound, of which ``timeout``
    is what was left)."""
    task = asyncio.ensure_future(awaitable)
    done, _ = await asyncio.wait({task}, timeout=timeout)
    if not done:
        task.cancel()
        task.add_done_callback(_consume)
        raise LinkError(f"{what}: no answer within {timeout if stated is None else stated:g} s")
    return task.result()


def _consume(task: asyncio.Future[Any]) -> None:
    if not task.cancelled():
        task.exception()  # retrieved, so asyncio does not log "exception never retrieved"


def chunks(items: Sequence[Any], size: int) -> list[Sequence[Any]]:
    return [items[i : i + size] for i in range(0, len(items), size)]


class DaemonExecutor(Executor):
    """Runs blocking protocol calls (python-snap7's sockets) on daemon
    threads, started as needed up to ``max_workers``.  Unlike the default executor, whose
    threads the interpreter joins at exit, a thread stuck on a dead peer until its socket
    timeout does not hold the process once the runtime has given up on it (:func:`bounded`,
    a link's ``stop_timeout``)."""

    def __init__(self, max_workers: int = 16, name: str = "fuzzyctl-io-call") -> None:
        self._max = max_workers
        self._name = name
        self._queue: queue.SimpleQueue[tuple[Future[Any], Any, tuple[Any, ...], dict[str, Any]] | None] = (
            queue.SimpleQueue()
        )
        self._lock = threading.Lock()
        self._idle = 0
        self._threads = 0
        self._closed = False

    def submit(self, fn: Any, /, *args: Any, **kwargs: Any) -> Future[Any]:
        future: Future[Any] = Future()
        with self._lock:
            if self._closed:
                raise RuntimeError("the executor is shut down")
            self._queue.put((future, fn, args, kwargs))
            if self._idle == 0 and self._threads < self._max:
                self._threads += 1
                threading.Thread(target=self._work, name=self._name, daemon=True).start()
        return future

    def _work(self) -> None:
        while True:
            with self._lock:
                self._idle += 1
            item = self._queue.get()
            with self._lock:
                self._idle -= 1
            if item is None:
                return
            future, fn, args, kwargs = item
            if not future.set_running_or_notify_cancel():
                continue
            try:
                future.set_result(fn(*args, **kwargs))
            except BaseException as exc:  # handed to the awaiting coroutine
                future.set_exception(exc)

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:
        """Ends the idle threads; a busy one ends after its call (never waited for)."""
        with self._lock:
            self._closed = True
            for _ in range(self._threads):
                self._queue.put(None)
