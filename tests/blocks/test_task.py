"""The cyclic task: fixed period, deterministic and real-time clocks, cycle time, jitter,
overruns (lost releases, as a PLC cyclic interrupt)."""

from __future__ import annotations

import pytest

from fuzzyctl.blocks.task import CycleContext, CyclicTask, RealTimeClock, SimulatedClock


def test_task_calls_blocks_in_order_at_the_period() -> None:
    calls: list[tuple[str, int, float]] = []
    task = CyclicTask(0.01)
    task.add(lambda ctx: calls.append(("a", ctx.index, ctx.start)))
    task.add(lambda ctx: calls.append(("b", ctx.index, ctx.start)))
    stats = task.run(4)
    assert [(n, i) for n, i, _ in calls] == [
        ("a", 0),
        ("b", 0),
        ("a", 1),
        ("b", 1),
        ("a", 2),
        ("b", 2),
        ("a", 3),
        ("b", 3),
    ]
    assert [t for n, _, t in calls if n == "a"] == pytest.approx([0.0, 0.01, 0.02, 0.03])
    assert stats.count == 4 and stats.overruns == 0 and stats.jitter_max == 0.0
    assert stats.cycle_times == pytest.approx([0.01] * 3)


def test_task_records_execution_time_and_jitter() -> None:
    clock = SimulatedClock(latency=[0.0, 0.002, 0.001])
    task = CyclicTask(0.01, clock=clock)
    task.add(lambda ctx: ctx.consume(0.003))
    stats = task.run(6)
    assert [r.jitter for r in stats.records] == pytest.approx([0.0, 0.002, 0.001, 0.0, 0.002, 0.001])
    assert all(r.duration == pytest.approx(0.003) for r in stats.records)
    assert stats.jitter_max == pytest.approx(0.002) and stats.jitter_mean == pytest.approx(0.001)
    assert stats.duration_mean == pytest.approx(0.003)
    assert stats.summary()["cycles"] == 6


def test_task_overrun_loses_the_releases_it_covers() -> None:
    durations = iter([0.004, 0.025, 0.004, 0.004])
    task = CyclicTask(0.01)
    task.add(lambda ctx: ctx.consume(next(durations)))
    stats = task.run(4)
    recs = list(stats.records)
    # Cycle 1 (due 0.01) runs until 0.035: the releases at 0.02 and 0.03 are lost.
    assert [r.overrun for r in recs] == [False, True, False, False]
    assert recs[1].skipped == 2 and stats.skipped == 2 and stats.overruns == 1
    assert [r.scheduled for r in recs] == pytest.approx([0.0, 0.01, 0.04, 0.05])


def test_task_runs_for_a_duration_or_until_a_condition() -> None:
    task = CyclicTask(0.02)
    seen: list[int] = []
    task.add(lambda ctx: seen.append(ctx.index))
    task.run(duration=0.1)
    assert seen == [0, 1, 2, 3, 4]
    task.run(until=lambda: len(seen) >= 8)
    assert len(seen) == 8
    with pytest.raises(ValueError):
        task.run()
    with pytest.raises(ValueError):
        CyclicTask(0.0)


def test_task_passes_its_period_to_the_blocks() -> None:
    got: list[CycleContext] = []
    CyclicTask(0.05, [got.append]).run(2)
    assert [c.period for c in got] == [0.05, 0.05] and got[1].scheduled == pytest.approx(0.05)


def test_task_real_time_clock_keeps_the_period() -> None:
    # The one real-time test: 20 cycles of 5 ms.  Bounds are loose (a loaded CI machine),
    # but a clock that did not wait, or waited a whole extra period, would fail.
    task = CyclicTask(0.005, clock=RealTimeClock())
    task.add(lambda ctx: None)
    stats = task.run(20)
    records = list(stats.records)
    elapsed = records[-1].start - records[0].start
    assert 0.094 <= elapsed <= 0.145 + 0.005 * stats.skipped
    assert all(r.jitter >= 0.0 for r in records)
    assert stats.count == 20
