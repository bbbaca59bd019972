"""The real-time thread that runs every instance's task.

One thread calls the tasks in the order their releases fall due (earliest first; on a tie
the shorter period first, as rate-monotonic priorities would), like the cyclic interrupts
of a single-CPU PLC without preemption.  Each task keeps its own period grid and records
its own jitter, execution time and overruns (:class:`fuzzyctl.blocks.task.CyclicTask`).

Tasks of the same period are spread over the period by default (``phase = "auto"``, the
"phase offset" of S7 cyclic interrupts, which is given in whole milliseconds), so that a
hundred 10 ms instances do not all wake at the same instant: they are dealt into slots
one millisecond apart (ten slots of ten instances), and the instances of a slot run back
to back after one wake-up.  Every wake-up costs the thread a sleep and a context switch
(tens of microseconds on a virtual machine, as much as a cycle of a small block), so one
wake-up per instance would spend a quarter of a core on sleeping alone.
"""

from __future__ import annotations

import heapq
import os
import threading
import time
from collections.abc import Callable, Sequence

from fuzzyctl.blocks.task import CycleRecord, CyclicTask

__all__ = ["RuntimeClock", "Scheduler", "auto_phases", "set_fifo"]


def set_fifo(priority: int) -> str | None:
    """SCHED_FIFO at ``priority`` for the calling thread (Linux); returns why not, when it
    could not."""
    setter = getattr(os, "sched_setscheduler", None)
    if setter is None:
        return "real-time scheduling is not available on this system"
    try:
        # pid 0 is the calling thread on Linux: only this thread is raised.
        setter(0, os.SCHED_FIFO, os.sched_param(priority))
    except OSError as exc:
        return f"cannot use SCHED_FIFO priority {priority}: {exc.strerror or exc}"
    return None


class RuntimeClock:
    """The wall clock (``time.perf_counter``) with an interruptible sleep: ``sleep_until``
    returns early when the runtime stops.  ``spin`` seconds before a release are
    busy-waited (0 by default: on Linux ``time.sleep`` wakes within ~0.1 ms, and a
    spinning thread would hold the GIL that the I/O thread needs)."""

    def __init__(self, stop: threading.Event, spin: float = 0.0) -> None:
        self._stop = stop
        self.spin = spin

    def now(self) -> float:
        return time.perf_counter()

    def sleep_until(self, deadline: float) -> None:
        remaining = deadline - time.perf_counter()
        if remaining > 0.05:
            # Long waits in an Event so that stop() is not held up by a 60 s period.
            if self._stop.wait(remaining - 0.02):
                return
            remaining = deadline - time.perf_counter()
        if remaining > self.spin:
            time.sleep(remaining - self.spin)
        while time.perf_counter() < deadline and not self._stop.is_set():
            pass

    def consume(self, seconds: float) -> None:
        """Real execution takes its own time."""


PHASE_STEP = 0.001  # the granularity of automatic phase offsets (S7: whole milliseconds)


def auto_phases(periods: Sequence[float], fixed: Sequence[float | None]) -> list[float]:
    """Phase offsets: a fixed one where given; tasks of equal period without one are dealt
    round-robin into slots spread evenly over the period, at most one slot per
    :data:`PHASE_STEP` (a 10 ms period has 10 slots; 100 tasks put 10 in each)."""
    groups: dict[float, list[int]] = {}
    for i, (p, f) in enumerate(zip(periods, fixed, strict=True)):
        if f is None:
            groups.setdefault(p, []).append(i)
    phases = [f if f is not None else 0.0 for f in fixed]
    for period, members in groups.items():
        slots = max(1, min(len(members), int(period / PHASE_STEP + 1e-9)))
        for k, i in enumerate(members):
            phases[i] = period * (k % slots) / slots
    return phases


class Scheduler:
    """Runs tasks on one thread until :meth:`stop`."""

    def __init__(
        self,
        tasks: Sequence[CyclicTask],
        phases: Sequence[float],
        clock: RuntimeClock,
        stop: threading.Event,
        *,
        on_cycle: Sequence[Callable[[CycleRecord], None]] | None = None,
        start_delay: float = 0.02,
        priority: int = 0,
        on_start: Callable[[str | None], None] | None = None,
    ) -> None:
        self.tasks = list(tasks)
        self.phases = list(phases)
        self.clock = clock
        self._stop = stop
        self._on_cycle = list(on_cycle) if on_cycle else [lambda _r: None] * len(self.tasks)
        self._start_delay = start_delay
        self._thread: threading.Thread | None = None
        self.error: BaseException | None = None
        self.origin = 0.0
        self.priority = priority
        self._on_start = on_start

    def start(self) -> None:
        self._thread = threading.Thread(target=self._run, name="fuzzyctl-cycles", daemon=True)
        self._thread.start()

    def join(self, timeout: float | None = None) -> None:
        if self._thread is not None:
            self._thread.join(timeout)

    @property
    def alive(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def _raise_priority(self) -> str | None:
        """SCHED_FIFO for this thread when asked; returns why not, when it could not."""
        if not self.priority:
            return None
        return set_fifo(self.priority)

    def _run(self) -> None:
        problem = self._raise_priority()
        if self._on_start is not None:
            self._on_start(problem)
        try:
            self.origin = self.clock.now() + self._start_delay
            heap = [
                (self.origin + phase, task.period, i)
                for i, (task, phase) in enumerate(zip(self.tasks, self.phases, strict=True))
            ]
            heapq.heapify(heap)
            while heap and not self._stop.is_set():
                due, period, i = heap[0]
                self.clock.sleep_until(due)
                if self._stop.is_set():
                    break
                task = self.tasks[i]
                self._on_cycle[i](task.step())
                heapq.heapreplace(heap, (task.next_release, period, i))
        except (
            BaseException
        ) as exc:  # recorded for the runtime to report; the thread must not vanish silently
            self.error = exc
            raise
