"""The process image and the I/O links that keep it up to date.

A :class:`Link` owns one connector and runs on the runtime's I/O event loop: every
``poll_interval`` it reads all the points bound to inputs (and parameters) of every
instance into their :class:`InCell`, then writes every output cell to the field, as a
PLC's process image is exchanged between cycles.  The cycle thread only reads and writes
cells (plain attribute access, atomic under the GIL), so a slow or dead connection never
delays a cycle.

On a failure the link goes down, closes the connector and reconnects with exponential
back-off from ``reconnect_min`` to ``reconnect_max``.  It is up again only after a
complete exchange, so an instance that sees the link up also sees fresh inputs.

When the runtime stops, the instances have put their safe values into the output cells;
each link then writes its output cells once more (connecting first if it is down) and
closes, all of it by ``stop_by`` (the stop plus the connection's ``stop_timeout``), and
logs what it wrote or why it could not (``stop-write``).
"""

from __future__ import annotations

import asyncio
import contextlib
import math
import time
from dataclasses import dataclass, field
from typing import Any

from fuzzyctl.io.base import Connector, LinkError, LinkState, Point, bounded
from fuzzyctl.runtime.config import ConnectionConfig
from fuzzyctl.runtime.events import EventLog, Level

__all__ = ["CLOSE_GRACE", "InCell", "Link", "OutCell"]

CLOSE_GRACE = 0.2
"""Seconds a link may take to close after its stop write (a peer that answered the write
closes at once; a dead one is not waited for)."""


class InCell:
    """One input point in the process image: the last value read and when."""

    __slots__ = ("stamp", "value")

    def __init__(self) -> None:
        self.value = math.nan
        self.stamp = 0.0


class OutCell:
    """One output point: the value the cycle wants in the field (None: nothing yet)."""

    __slots__ = ("last_send", "sent", "value")

    def __init__(self) -> None:
        self.value: float | None = None
        self.sent: float | None = None
        # (value, perf_counter after the write), one tuple so the cycle thread never sees
        # a value with another write's time; kept across reconnects, unlike ``sent``.
        self.last_send: tuple[float, float] | None = None


_Lists = tuple[list[Point], list[InCell], list[Point], list[OutCell], list[Point], list[OutCell]]


@dataclass
class LinkCounters:
    exchanges: int = 0
    failures: int = 0
    connects: int = 0
    last_exchange_ms: float = 0.0
    last_error: str | None = None
    since: float = field(default_factory=time.monotonic)


class Link:
    """One connection and the cells bound to it."""

    def __init__(self, name: str, connector: Connector, config: ConnectionConfig, events: EventLog) -> None:
        self.name = name
        self.connector = connector
        self.config = config
        self.events = events
        self._state = LinkState.DOWN
        self.up = False
        """Whether the link is up: a plain attribute, read several times per instance and
        cycle by the cycle thread."""
        self.counters = LinkCounters()
        self.deadline = config.effective_deadline
        self.last_exchange = 0.0
        """``time.perf_counter()`` at the end of the last complete exchange: an instance
        whose link has none for longer than ``deadline`` holds, before the protocol's timeout
        declares the link lost (a frozen peer)."""
        self._in: dict[Point, InCell] = {}
        self._out: dict[Point, OutCell] = {}
        self._mirror: dict[Point, OutCell] = {}
        self._lists: _Lists | None = None  # the bindings as parallel lists, made at the first exchange
        self.stop_by: float | None = None
        """The I/O loop's time by which the stop write must be done; set by the runtime
        before it sets the stop event (None: ``stop_timeout`` from when the loop ends).
        Once set, exchanges no longer write outputs: the stop write is the last one."""

    def _event(self, kind: str, message: str, *, level: Level = "info", **data: Any) -> None:
        """Logs an event of this link: its name heads the message and tags the event."""
        self.events.emit(kind, f"{self.name}: {message}", level=level, link=self.name, **data)

    # --- bindings (before start)
    def input(self, point: Point) -> InCell:
        """The cell of an input point (shared when several bindings read the same point)."""
        self._lists = None
        return self._in.setdefault(point, InCell())

    def output(self, point: Point) -> OutCell:
        """The cell of an output point, written every exchange."""
        if point in self._out or point in self._mirror:
            raise LinkError(f"{point.describe()} on {self.name} is written by two bindings")
        self._lists = None
        return self._out.setdefault(point, OutCell())

    def mirror(self, point: Point) -> OutCell:
        """The cell of a parameter's mirror, written only when its value changes (so a
        value a client writes is not overwritten before the runtime reads it)."""
        if point in self._out or point in self._mirror:
            raise LinkError(f"{point.describe()} on {self.name} is written by two bindings")
        self._lists = None
        return self._mirror.setdefault(point, OutCell())

    @property
    def points(self) -> list[Point]:
        return list({**self._in, **self._out, **self._mirror})

    @property
    def state(self) -> LinkState:
        return self._state

    @state.setter
    def state(self, state: LinkState) -> None:
        self._state = state
        self.up = state is LinkState.UP

    # --- the exchange
    async def exchange(self) -> None:
        """Read every input point, write every output (and changed mirror)."""
        t0 = time.perf_counter()
        lists = self._lists
        if lists is None:
            # Points hash slowly (pydantic models): walk parallel lists, not the dicts.
            lists = self._lists = (
                list(self._in), list(self._in.values()),
                list(self._out), list(self._out.values()),
                list(self._mirror), list(self._mirror.values()),
            )  # fmt: skip
        in_points, in_cells, out_points_all, out_cells, mirror_points, mirror_cells = lists
        if in_points:
            values = await self.connector.read(in_points)
            now = time.perf_counter()
            for in_cell, v in zip(in_cells, values, strict=True):
                in_cell.value, in_cell.stamp = v, now
        if self.stop_by is not None:
            return  # stopping: the outputs are written once more by the stop write only
        out_points: list[Point] = []
        out_values: list[float] = []
        sent: list[OutCell] = []
        for p, out_cell in zip(out_points_all, out_cells, strict=True):
            value = out_cell.value
            if value is not None:
                out_points.append(p)
                out_values.append(value)
                sent.append(out_cell)
        for p, out_cell in zip(mirror_points, mirror_cells, strict=True):
            value = out_cell.value
            if value is not None and value != out_cell.sent:
                out_points.append(p)
                out_values.append(value)
                sent.append(out_cell)
        if out_points:
            await self.connector.write(out_points, out_values)
            done = time.perf_counter()
            for out_cell, value in zip(sent, out_values, strict=True):
                out_cell.sent = value
                out_cell.last_send = (value, done)
        self.counters.exchanges += 1
        self.last_exchange = end = time.perf_counter()
        self.counters.last_exchange_ms = (end - t0) * 1e3

    async def write_outputs(self) -> dict[str, float]:
        """Write every output cell that has a value (not the parameter mirrors); returns
        what was written, by point."""
        items = [(p, c.value) for p, c in self._out.items() if c.value is not None]
        if items:
            await self.connector.write([p for p, _ in items], [v for _, v in items])
        return {p.describe(): v for p, v in items}

    async def _connect(self) -> None:
        await self.connector.connect()
        ensure = getattr(self.connector, "ensure", None)
        if ensure is not None:
            await ensure(self.points)
        for cell in self._mirror.values():
            cell.sent = None  # a new peer has not seen our values
        await self.exchange()

    def _set_state(self, state: LinkState) -> None:
        self.state = state
        self.counters.since = time.monotonic()

    async def run(self, stop: asyncio.Event) -> None:
        """Connect, exchange every poll interval, reconnect with back-off, until ``stop``."""
        cfg = self.config
        delay = cfg.reconnect_min
        attempt = 0
        loop = asyncio.get_running_loop()
        while not stop.is_set():
            if self.state is not LinkState.UP:
                attempt += 1
                try:
                    await self._connect()
                # A protocol library may raise more than LinkError on a broken peer; any of
                # them means "not connected", and the link must keep retrying.
                except Exception as exc:
                    self.counters.failures += 1
                    self.counters.last_error = str(exc)
                    await self.connector.close()
                    self._event(
                        "link-retry",
                        f"{describe(exc)}; next attempt in {delay:.3g} s",
                        level="warning",
                        attempt=attempt,
                        delay=delay,
                        error=describe(exc),
                    )
                    await _wait(stop, delay)
                    delay = min(delay * 2, cfg.reconnect_max)
                    continue
                self.counters.connects += 1
                self.counters.last_error = None
                self._set_state(LinkState.UP)
                self._event(
                    "link-up",
                    f"connected to {self.connector.endpoint()}",
                    endpoint=self.connector.endpoint(),
                    attempts=attempt,
                )
                delay, attempt = cfg.reconnect_min, 0
                continue
            start = loop.time()
            try:
                await self.exchange()
            except Exception as exc:  # as above: whatever broke, the link is down
                self.counters.failures += 1
                self.counters.last_error = describe(exc)
                self._set_state(LinkState.DOWN)
                self._event(
                    "link-lost",
                    describe(exc),
                    level="error",
                    error=describe(exc),
                )
                await self.connector.close()
                continue
            await _wait(stop, max(0.0, start + cfg.poll_interval - loop.time()))
        if self.stop_by is None:
            self.stop_by = loop.time() + cfg.stop_timeout
        await self._stop_write()
        with contextlib.suppress(LinkError):
            await bounded(self.connector.close(), max(self.stop_by - loop.time(), CLOSE_GRACE), "close")
        self._set_state(LinkState.CLOSED)

    async def _stop_write(self) -> None:
        """The last write of the output cells (the safe values), by ``stop_by``; a link
        that is down connects once first (a server that is not serving does not)."""
        if not self._out:
            return
        loop = asyncio.get_running_loop()
        assert self.stop_by is not None
        timeout = self.config.stop_timeout
        t0 = loop.time()

        async def go() -> dict[str, float]:
            if not self.up:
                if self.connector.server:
                    raise LinkError("not serving")
                await self.connector.close()
                await self.connector.connect()
            return await self.write_outputs()

        if timeout == 0:
            self._event(
                "stop-write",
                "at stop nothing written (stop_timeout = 0): the field keeps the last values",
                level="warning",
                written={},
            )
            return
        try:
            if self.stop_by - t0 <= 0:
                raise LinkError(f"no answer within {timeout:g} s")
            what = "connect and write" if not self.up else "write"
            written = await bounded(go(), self.stop_by - t0, what, stated=timeout)
        except Exception as exc:  # whatever the protocol raised: not written, and said so
            self.stop_failed(describe(exc))
            return
        shown = ", ".join(f"{k} = {v:g}" for k, v in written.items())
        self._event(
            "stop-write",
            f"at stop wrote {shown or 'nothing (no output has a value yet)'}",
            written=written,
            seconds=round(loop.time() - t0, 6),
        )

    async def stopped(self, task: asyncio.Task[None]) -> None:
        """Wait for :meth:`run` (``task``) to end after the stop event, at most until
        ``stop_by`` plus :data:`CLOSE_GRACE`: an exchange or a connection attempt in
        progress on a dead peer (bounded only by the protocol's timeout) is cut there."""
        loop = asyncio.get_running_loop()
        if self.stop_by is None:
            self.stop_by = loop.time() + self.config.stop_timeout
        # Past the close's own bound (stop_by, or CLOSE_GRACE after a late write): run() is stuck.
        done, _ = await asyncio.wait({task}, timeout=max(0.0, self.stop_by - loop.time()) + 2 * CLOSE_GRACE)
        if done:
            return
        task.cancel()
        self.stop_failed(f"no answer within {self.config.stop_timeout:g} s (an exchange was in progress)")
        with contextlib.suppress(Exception):  # closing a connection that hangs: not waited for
            await bounded(self.connector.close(), CLOSE_GRACE, "close")
        self._set_state(LinkState.CLOSED)

    def stop_failed(self, why: str) -> None:
        """Log that the stop write did not reach the field (``stop-write``, level error)."""
        self._event(
            "stop-write",
            f"at stop the safe values were NOT written: {why}",
            level="error",
            written={},
            error=why,
        )


def describe(exc: BaseException) -> str:
    """An exception as a message (the type when it says nothing else)."""
    text = str(exc)
    return text if isinstance(exc, LinkError) and text else f"{type(exc).__name__}: {text}".rstrip(": ")


async def _wait(stop: asyncio.Event, seconds: float) -> None:
    if seconds <= 0:
        await asyncio.sleep(0)
        return
    with contextlib.suppress(asyncio.TimeoutError):
        await asyncio.wait_for(stop.wait(), seconds)
