"""A cyclic task, as a PLC runs a cyclic interrupt organisation block: the blocks it
holds are called one after the other at a fixed period.

The clock is pluggable: :class:`SimulatedClock` is deterministic (tests, simulation, the
CLI), :class:`RealTimeClock` follows the wall clock (``time.perf_counter``).  Each cycle is
recorded: when it was due, when it started (the difference is the jitter), when it ended
(execution time) and whether it overran its period.  Like a PLC's cyclic interrupt, a
release that falls while the previous cycle is still running is lost: the task counts it
as skipped and resumes at the next release on the period grid.
"""

from __future__ import annotations

import itertools
import math
import statistics
import time
from collections import deque
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import NamedTuple, Protocol

__all__ = [
    "Clock",
    "CycleContext",
    "CycleRecord",
    "CyclicTask",
    "RealTimeClock",
    "SimulatedClock",
    "TaskStats",
]


class Clock(Protocol):
    """Time source of a task, in seconds."""

    def now(self) -> float: ...

    def sleep_until(self, deadline: float) -> None: ...

    def consume(self, seconds: float) -> None:
        """Account for ``seconds`` of execution (the simulated clock advances; a real
        clock ignores it, real execution takes the time it takes)."""
        ...


class SimulatedClock:
    """A deterministic clock: time only moves when the task sleeps or a block consumes.

    ``latency`` adds a wake-up delay after each sleep: a constant, a sequence used
    cyclically, or a function of the wake-up count, to simulate jitter."""

    def __init__(
        self, start: float = 0.0, *, latency: float | Sequence[float] | Callable[[int], float] = 0.0
    ) -> None:
        self._t = float(start)
        self._wakeups = 0
        self._latency = latency

    def now(self) -> float:
        return self._t

    def _next_latency(self) -> float:
        lat = self._latency
        k = self._wakeups
        self._wakeups += 1
        if callable(lat):
            return float(lat(k))
        if isinstance(lat, int | float):
            return float(lat)
        return float(lat[k % len(lat)]) if lat else 0.0

    def sleep_until(self, deadline: float) -> None:
        self._t = max(self._t, deadline) + self._next_latency()

    def consume(self, seconds: float) -> None:
        if seconds < 0:
            raise ValueError("execution time cannot be negative")
        self._t += seconds


class RealTimeClock:
    """The wall clock.  Sleeps with ``time.sleep`` and spins the last half millisecond,
    which keeps the jitter well under a millisecond on an idle machine."""

    spin = 0.0005

    def now(self) -> float:
        return time.perf_counter()

    def sleep_until(self, deadline: float) -> None:
        remaining = deadline - time.perf_counter()
        if remaining > self.spin:
            time.sleep(remaining - self.spin)
        while time.perf_counter() < deadline:
            pass

    def consume(self, seconds: float) -> None:
        """Real execution takes its own time; nothing to add."""


class CycleContext(NamedTuple):
    """What a block is told when the task calls it (immutable; a named tuple because the
    runtime makes ten thousand a second, and a frozen dataclass costs 5x as much)."""

    index: int  # type: ignore[assignment]  # the field hides tuple.index, which nobody calls here
    period: float
    scheduled: float
    start: float
    clock: Clock

    def consume(self, seconds: float) -> None:
        """Declare ``seconds`` of execution time (moves a simulated clock)."""
        self.clock.consume(seconds)


class CycleRecord(NamedTuple):
    """Timing of one cycle.  ``skipped`` counts the releases lost before the next one."""

    index: int  # type: ignore[assignment]  # (as in CycleContext)
    scheduled: float
    start: float
    end: float
    overrun: bool
    skipped: int = 0

    @property
    def jitter(self) -> float:
        """Start delay after the due time."""
        return self.start - self.scheduled

    @property
    def duration(self) -> float:
        """Execution time of the blocks."""
        return self.end - self.start


@dataclass
class TaskStats:
    """Running statistics of a task (all cycles, not only the kept records)."""

    period: float
    count: int = 0
    overruns: int = 0
    skipped: int = 0
    jitter_max: float = 0.0
    jitter_sum: float = 0.0
    duration_max: float = 0.0
    duration_sum: float = 0.0
    records: deque[CycleRecord] = field(default_factory=lambda: deque(maxlen=10_000))

    def add(self, rec: CycleRecord) -> None:
        self.count += 1
        self.overruns += rec.overrun
        self.skipped += rec.skipped
        self.jitter_max = max(self.jitter_max, rec.jitter)
        self.jitter_sum += rec.jitter
        self.duration_max = max(self.duration_max, rec.duration)
        self.duration_sum += rec.duration
        self.records.append(rec)

    @property
    def jitter_mean(self) -> float:
        return self.jitter_sum / self.count if self.count else 0.0

    @property
    def duration_mean(self) -> float:
        return self.duration_sum / self.count if self.count else 0.0

    @property
    def cycle_times(self) -> list[float]:
        """Start-to-start intervals of the kept records (the PLC's "cycle time")."""
        starts = [r.start for r in self.records]
        return [b - a for a, b in itertools.pairwise(starts)]

    def jitter_stdev(self) -> float:
        values = [r.jitter for r in self.records]
        return statistics.pstdev(values) if len(values) > 1 else 0.0

    def summary(self) -> dict[str, float | int]:
        return {
            "period": self.period,
            "cycles": self.count,
            "overruns": self.overruns,
            "skipped": self.skipped,
            "jitter_mean": self.jitter_mean,
            "jitter_max": self.jitter_max,
            "duration_mean": self.duration_mean,
            "duration_max": self.duration_max,
        }


Block = Callable[[CycleContext], object]


class CyclicTask:
    """Calls its blocks every ``period`` seconds, in the order they were added."""

    def __init__(
        self, period: float, blocks: Iterable[Block] = (), *, clock: Clock | None = None, keep: int = 10_000
    ) -> None:
        if not period > 0 or not math.isfinite(period):
            raise ValueError(f"period must be a positive number of seconds, not {period!r}")
        self.period = float(period)
        self.clock: Clock = clock if clock is not None else SimulatedClock()
        self.blocks: list[Block] = list(blocks)
        self.stats = TaskStats(self.period, records=deque(maxlen=keep))
        self._origin: float | None = None
        self._next_index = 0  # index of the next release on the grid origin + k * period
        self._cycle = 0

    def add(self, block: Block) -> Block:
        """Append a block (any callable taking a :class:`CycleContext`); returns it, so it
        can be used as a decorator."""
        self.blocks.append(block)
        return block

    @property
    def next_release(self) -> float:
        """When the next cycle is due (now, before the first one)."""
        if self._origin is None:
            return self.clock.now()
        return self._origin + self._next_index * self.period

    def step(self) -> CycleRecord:
        """Wait for the next release, run every block once, record the cycle."""
        if self._origin is None:
            self._origin = self.clock.now()
        due = self._origin + self._next_index * self.period
        self.clock.sleep_until(due)
        start = self.clock.now()
        ctx = CycleContext(self._cycle, self.period, due, start, self.clock)
        for block in self.blocks:
            block(ctx)
        end = self.clock.now()
        # Releases that fell before the end of this cycle are lost (cyclic interrupt semantics).
        following = self._next_index + 1
        resume = max(following, math.ceil((end - self._origin) / self.period - 1e-9))
        rec = CycleRecord(
            self._cycle, due, start, end, overrun=end > due + self.period, skipped=resume - following
        )
        self._next_index = resume
        self._cycle += 1
        self.stats.add(rec)
        return rec

    def run(
        self,
        cycles: int | None = None,
        *,
        duration: float | None = None,
        until: Callable[[], bool] | None = None,
    ) -> TaskStats:
        """Run ``cycles`` cycles, or the cycles due within ``duration`` seconds, or until
        ``until()`` is true (checked after each cycle); at least one limit is required."""
        if cycles is None and duration is None and until is None:
            raise ValueError("give cycles, duration or until")
        begin = self.clock.now() if self._origin is None else self.next_release
        done = 0
        while True:
            if cycles is not None and done >= cycles:
                break
            if duration is not None and self.next_release - begin >= duration - 1e-12:
                break
            self.step()
            done += 1
            if until is not None and until():
                break
        return self.stats
