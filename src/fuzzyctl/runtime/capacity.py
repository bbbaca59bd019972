"""How much of the cycle thread a configuration needs, estimated before it runs
(``fuzzyctl serve --check``), against what the runtime was measured to hold.

The estimate runs each instance's cycle (its real knowledge base, the task's bookkeeping
included) a few hundred times in a tight loop, in CPU time (so that a busy machine does not
inflate it), and adds up ``cycle time / period`` over the instances: the fraction of one
core the cycles need on *this* machine.  The capacity is
the same estimate for the largest configuration of ``benchmarks/runtime_jitter.py`` that
kept the jitter p99 under 2 ms at SCHED_FIFO (docs/runtime.md, "Timing"):
both are fractions of one core measured the same way, so the comparison carries over,
roughly, to a faster or slower machine (not its own stalls: see the docs).  In a running
runtime a cycle costs about twice the tight-loop time (caches emptied by other work
between releases), and the thread also sleeps and wakes: that is in the calibration, not
in the estimate.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from fuzzyctl.runtime.events import EventLog

if TYPE_CHECKING:
    from fuzzyctl.runtime.core import Runtime

__all__ = ["CAPACITY", "CapacityEstimate", "check", "estimate", "warnings"]

CAPACITY = 0.30
"""The estimated load (fraction of one core, as :func:`estimate` computes it) up to which
the jitter p99 stayed under 2 ms at SCHED_FIFO on the project's loaded 2-core machine:
50 FPLTEST instances at 10 ms (24 %) did in every run, 100 (47 %) only in calm minutes
(docs/runtime.md, "Timing"); 30 % is about 60 instances."""

BUDGET = 10_000  # cycles timed per repetition in all (about a second at most)


@dataclass(frozen=True)
class CapacityEstimate:
    cycle_time: dict[str, float]
    """Seconds one cycle of each instance takes (tight loop, bookkeeping included)."""
    load: float
    """Sum of cycle time / period: the fraction of one core the cycles need."""


def estimate(runtime: Runtime, cycles: int = 150) -> CapacityEstimate:
    """Time the cycles of a runtime that is built but not started.  Its instances are
    used up (their blocks have run): estimate on a runtime you then discard."""
    if runtime.started:
        raise RuntimeError("estimate() runs the cycles itself: call it on a runtime that is not started")
    n = max(20, min(cycles, BUDGET // max(1, len(runtime.instances))))
    quiet = EventLog(None)
    times: dict[str, float] = {}
    for name, inst in runtime.instances.items():
        inst.events = quiet  # nothing of this goes to the event file
        task = inst.task
        task.step()  # the first cycle (start-up event) is not typical
        best = float("inf")
        for _ in range(2):
            t0 = time.thread_time()  # CPU time: what other processes do does not count
            for _ in range(n):
                task._origin = time.perf_counter() - 1e6  # always due: no sleep, the grid is irrelevant
                task._next_index = 0
                rec = task.step()
                inst.after_cycle(rec)
            best = min(best, (time.thread_time() - t0) / n)
        times[name] = best
    load = sum(times[n] / i.config.period for n, i in runtime.instances.items())
    return CapacityEstimate(times, load)


def warnings(runtime: Runtime, est: CapacityEstimate) -> list[str]:
    """What ``serve --check`` says about the timing of a configuration."""
    out = []
    if est.load > CAPACITY:
        out.append(
            f"the cycles need about {est.load:.1%} of one core (estimated); the runtime was measured "
            f"to keep jitter p99 < 2 ms up to {CAPACITY:.0%} (docs/runtime.md, Timing): "
            "expect more jitter and overruns; use fewer instances per runtime or longer periods"
        )
    if not runtime.config.runtime.realtime_priority and est.load > 0.05:
        out.append(
            "realtime_priority is 0: the cycle thread competes with every process on the machine, "
            "and on a loaded machine its jitter reaches tens of milliseconds (docs/runtime.md, Timing)"
        )
    return out


def check(config: str | Path) -> tuple[str, list[str]]:
    """``fuzzyctl serve --check``: read and check ``config`` (a :class:`ConfigError` lists
    every problem), time its cycles, and say what it needs - one line, and the warnings."""
    from fuzzyctl.runtime.config import ConfigError
    from fuzzyctl.runtime.core import Runtime, check_config

    checked, problems = check_config(config)
    if problems:
        raise ConfigError(problems)
    assert checked is not None
    runtime = Runtime(checked, api=False, event_log=None)
    est = estimate(runtime)  # times the cycles: a runtime that is then dropped
    runtime.stop()
    summary = (
        f"{config}: OK: {len(checked.instances)} instance(s), {len(checked.connections)} connection(s); "
        f"the cycles need about {est.load:.1%} of one core (capacity {CAPACITY:.0%})"
    )
    return summary, warnings(runtime, est)
