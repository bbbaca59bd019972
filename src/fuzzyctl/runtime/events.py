"""The runtime's structured event log.

Every event gets the next sequence number (1, 2, 3, ... with no gaps), a wall-clock time
and a monotonic time, a kind, a level, the instance and/or link it concerns, a message
for people and a data mapping for tools.  Nothing is dropped: the events stay in memory
(the last ``keep``, 100 000 by default, for the API) and every one is appended to a
JSON-lines file by a writer thread, so the real-time cycle never waits for the disk.

Kinds (docs/runtime.md lists their data): ``runtime-start``, ``runtime-stop``,
``link-up``, ``link-lost``, ``link-retry``, ``hold-start``, ``hold-end``, ``safe-enter``,
``safe-exit``, ``input-invalid``, ``input-valid``, ``download``, ``download-applied``,
``download-refused``, ``parameter``, ``force``, ``error``, ``error-cleared``, ``overrun``,
``realtime``.
"""

from __future__ import annotations

import itertools
import json
import queue
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any, Literal

__all__ = ["Event", "EventLog"]

Level = Literal["info", "warning", "error"]


@dataclass(frozen=True)
class Event:
    seq: int
    time: str
    """UTC wall-clock time, ISO 8601."""
    mono: float
    """``time.monotonic()`` when it happened (orders events of one run)."""
    kind: str
    level: Level
    message: str
    instance: str | None = None
    link: str | None = None
    data: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


class EventLog:
    """Thread-safe, gap-free event log with an optional JSON-lines file."""

    def __init__(
        self,
        path: Path | None = None,
        *,
        keep: int = 100_000,
        thread_setup: Callable[[], object] | None = None,
    ) -> None:
        self._lock = threading.Lock()
        self._events: deque[Event] = deque(maxlen=keep)
        self._seq = 0
        self._listeners: list[Callable[[Event], None]] = []
        self.path = path
        self._queue: queue.SimpleQueue[Event | None] = queue.SimpleQueue()
        self._writer: threading.Thread | None = None
        self._thread_setup = thread_setup
        if path is not None:
            path.parent.mkdir(parents=True, exist_ok=True)
            self._file = path.open("a", encoding="utf-8")
            self._writer = threading.Thread(target=self._write_loop, name="fuzzyctl-events", daemon=True)
            self._writer.start()

    def emit(
        self,
        kind: str,
        message: str,
        *,
        level: Level = "info",
        instance: str | None = None,
        link: str | None = None,
        **data: Any,
    ) -> Event:
        with self._lock:
            self._seq += 1
            event = Event(
                self._seq,
                datetime.now(UTC).isoformat(timespec="microseconds"),
                time.monotonic(),
                kind,
                level,
                message,
                instance,
                link,
                data,
            )
            self._events.append(event)
            listeners = list(self._listeners)
        if self._writer is not None:
            self._queue.put(event)
        for listener in listeners:
            listener(event)
        return event

    def subscribe(self, listener: Callable[[Event], None]) -> Callable[[], None]:
        """Call ``listener(event)`` for every new event (from the emitting thread; keep it
        quick).  Returns a function that unsubscribes."""
        with self._lock:
            self._listeners.append(listener)

        def unsubscribe() -> None:
            with self._lock:
                if listener in self._listeners:
                    self._listeners.remove(listener)

        return unsubscribe

    @property
    def last_seq(self) -> int:
        return self._seq

    def since(self, after: int = 0, limit: int | None = None, kinds: set[str] | None = None) -> list[Event]:
        """Events with ``seq > after`` (oldest first), at most ``limit``."""
        with self._lock:
            # The emitting cycle thread waits for this lock: copy only the new events (they
            # are at the right end, sequence numbers have no gaps), not the whole log.
            n_new = self._seq - after
            if n_new <= 0:
                return []
            if n_new < len(self._events):
                events = list(itertools.islice(reversed(self._events), n_new))
                events.reverse()
            else:
                events = list(self._events)
        if kinds is not None:
            events = [e for e in events if e.kind in kinds]
        return events if limit is None else events[:limit]

    @property
    def first_seq(self) -> int:
        """The oldest sequence number still in memory (older ones are in the file)."""
        with self._lock:
            return self._events[0].seq if self._events else self._seq + 1

    def _write_loop(self) -> None:
        if self._thread_setup is not None:
            self._thread_setup()  # (the runtime: real-time below the cycle thread, see core)
        while True:
            event = self._queue.get()
            if event is None:
                break
            self._file.write(json.dumps(event.to_dict(), ensure_ascii=False, default=str) + "\n")
            if self._queue.empty():
                self._file.flush()
        self._file.flush()

    def close(self) -> None:
        """Write out what is queued and close the file."""
        if self._writer is not None:
            self._queue.put(None)
            self._writer.join(timeout=10)
            self._writer = None
            self._file.close()
