"""Sampled defuzzification (engine/reference/sampled.py): closed-form values."""

from __future__ import annotations

import pytest

from fuzzyctl.engine.reference.sampled import mean_of_maxima, sampled_centroid, weighted_mean


def test_sampled_centroid() -> None:
    # A ramp 0, .25, .75, 1, 1 on 2, 4, 6, 8, 10: (1 + 4.5 + 8 + 10) / 3 = 23.5 / 3
    assert sampled_centroid([2, 4, 6, 8, 10], [0, 0.25, 0.75, 1, 1]) == pytest.approx(23.5 / 3)
    assert sampled_centroid([0, 1, 2], [0.5, 0.5, 0.5]) == 1.0  # symmetric
    assert sampled_centroid([0, 1], [0, 0]) is None


def test_mean_of_maxima() -> None:
    assert mean_of_maxima([0, 2, 4, 6, 8, 10], [0, 0, 0.25, 0.75, 1, 1]) == 9.0
    assert mean_of_maxima([0, 5, 10], [0.2, 0.9, 0.1]) == 5.0
    assert mean_of_maxima([0, 1], [0, 0]) is None
    assert mean_of_maxima([], []) is None


def test_weighted_mean() -> None:
    assert weighted_mean([0, 1000], [0.25, 0.25]) == 500.0
    assert weighted_mean([1000, 0], [0.375, 0.125]) == 750.0
    assert weighted_mean([5.0], [0.0]) is None
