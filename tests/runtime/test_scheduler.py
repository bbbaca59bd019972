"""Automatic phase offsets: instances of one period dealt into slots at least a millisecond
apart (one wake-up per slot), fixed phases kept."""

from __future__ import annotations

from collections import Counter

import pytest

from fuzzyctl.runtime.scheduler import auto_phases


def test_a_hundred_10_ms_instances_are_ten_slots_of_ten() -> None:
    phases = auto_phases([0.01] * 100, [None] * 100)
    slots = Counter(round(p, 9) for p in phases)
    assert sorted(slots) == pytest.approx([k * 0.001 for k in range(10)])
    assert set(slots.values()) == {10}


def test_few_instances_spread_evenly_and_fixed_phases_are_kept() -> None:
    assert auto_phases([0.01] * 3, [None] * 3) == pytest.approx([0.0, 0.01 / 3, 0.02 / 3])
    assert auto_phases([0.002] * 5, [None] * 5) == pytest.approx([0.0, 0.001, 0.0, 0.001, 0.0])
    phases = auto_phases([0.01, 0.01, 0.05], [0.004, None, None])
    assert phases == pytest.approx([0.004, 0.0, 0.0])
    assert auto_phases([0.0005] * 4, [None] * 4) == [0.0] * 4  # shorter than a slot: one slot
