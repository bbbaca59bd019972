"""The norms registry (fuzzyctl/kinds/norms.py): an entry for every AND, OR, activation and
accumulation name the model and the operators table know, each entry complete, and each
property it states true of the operator's formula (checked on a grid of degrees against the
operators table, the definitions the engine runs)."""

from __future__ import annotations

import itertools
import typing

import pytest

from fuzzyctl import model
from fuzzyctl.engine.semantics import operators as ops
from fuzzyctl.kinds import norms as N

LEVELS = set(typing.get_args(N.Level))
GRID = [0.0, 0.1, 0.25, 0.4, 0.5, 0.6, 0.75, 0.9, 1.0]
PAIRS = list(itertools.product(GRID, GRID))


def test_every_operator_name_has_an_entry() -> None:
    assert set(N.TNORMS) == set(ops.TNORMS) == model.AND_OPERATORS == model.ACT_METHODS
    assert set(N.SNORMS) == set(ops.SNORMS) == model.OR_OPERATORS
    assert set(N.ACCUMULATIONS) == set(ops.ACCU_NAMES) == model.ACCU_METHODS
    # the aliases resolve to entries
    assert set(ops.AND_ALIASES.values()) | set(ops.ACT_ALIASES.values()) <= set(N.TNORMS)
    assert set(ops.OR_ALIASES.values()) <= set(N.SNORMS)
    assert set(ops.ACCU_ALIASES.values()) <= set(N.ACCUMULATIONS)


@pytest.mark.parametrize("name", sorted(N.TNORMS))
def test_every_tnorm_entry_is_complete_and_true(name: str) -> None:
    e = N.TNORMS[name]
    assert e.name == name and e.title
    assert {e.and_conformance, e.act_conformance} <= LEVELS
    f = ops.TNORMS[name].scalar
    assert e.idempotent == all(f(a, a) == a for a in GRID), "idempotent: T(a, a) = a"
    assert e.product == all(f(a, b) == a * b for a, b in PAIRS), "product: T(a, b) = ab"
    assert e.clips == e.idempotent and e.scales == e.product
    assert e.fixed in (None, "min", "product", "bounded_difference")
    if e.fixed == "min":
        assert all(f(a, b) == min(a, b) for a, b in PAIRS)
    if e.fixed == "bounded_difference":
        assert all(f(a, b) == max(0.0, a + b - 1.0) for a, b in PAIRS)
    assert e.fixed != "product" or e.product
    # XFUZ's OP_ET / OP_IMPL constants: 0 minimum, 1 product (Schneider's XFUZ block)
    assert e.xfuz == {"MIN": 0, "PROD": 1}.get(name)
    assert N.xfuz_code(name) == e.xfuz


@pytest.mark.parametrize("name", sorted(N.SNORMS))
def test_every_snorm_entry_is_complete_and_true(name: str) -> None:
    e = N.SNORMS[name]
    assert e.name == name and e.title and e.or_conformance in LEVELS
    f = ops.SNORMS[name].scalar
    assert e.idempotent == all(f(a, a) == a for a in GRID), "idempotent: S(a, a) = a"
    expected = {
        "max": max,
        "probabilistic_sum": lambda a, b: a + b - a * b,
        "bounded_sum": lambda a, b: min(1.0, a + b),
    }
    assert e.fixed is None or e.fixed in expected
    if e.fixed is not None:
        assert all(f(a, b) == pytest.approx(expected[e.fixed](a, b), abs=1e-15) for a, b in PAIRS)


@pytest.mark.parametrize("name", sorted(N.ACCUMULATIONS))
def test_every_accumulation_entry_is_complete_and_true(name: str) -> None:
    e = N.ACCUMULATIONS[name]
    assert e.name == name and e.title and e.conformance in LEVELS
    f = lambda a, b: ops.accumulate(name, a, b)  # noqa: E731
    assert e.idempotent == all(f(a, a) == a for a in GRID)
    assert e.additive == all(f(a, b) == a + b for a, b in PAIRS)
    assert e.bounded == all(f(a, b) == min(1.0, a + b) for a, b in PAIRS)
    assert e.probabilistic == all(f(a, b) == a + b - a * b for a, b in PAIRS)
    # saturates: reaches 1 from two degrees below 1 (a bound or a jump)
    assert e.saturates == all(f(a, a) == 1.0 for a in (0.6, 0.7, 0.9))
    assert e.jumps_to_one == (e.saturates and not e.bounded)
    # picks the largest: the value is one of the two sets wherever it is below 1
    if e.picks_largest:
        assert all(f(a, b) in (a, b) for a, b in PAIRS if f(a, b) < 1.0)
    assert e.branch_tests <= set(typing.get_args(N.BranchTest))
    # exact: piecewise linear or polynomial on linear pieces (max, sums, a + b - ab)
    closed = (max, lambda a, b: a + b, lambda a, b: min(1.0, a + b), lambda a, b: a + b - a * b)
    assert e.exact == any(all(f(a, b) == g(a, b) for a, b in PAIRS) for g in closed)
    assert e.jfl in N.ACCUMULATIONS and N.ACCUMULATIONS[e.jfl].stand_in is None
    if e.stand_in is not None:
        # the same defuzzified value: the stand-in's formula on the sets
        assert e.stand_in in N.ACCUMULATIONS and N.ACCUMULATIONS[e.stand_in].stand_in is None
        assert all(f(a, b) == ops.accumulate(e.stand_in, a, b) for a, b in PAIRS)
    assert e.normalised == (e.stand_in is not None)


def test_conformance_levels() -> None:
    """IEC 61131-7 Tables 3-5: the basic level is MIN/MAX; PROD/ASUM, BDIF/BSUM, ACT PROD,
    ACCU BSUM/NSUM are extensions; other tools' operators are open."""
    assert N.conformance("AND", None) == N.conformance("ACCU", "MAX") == "basic"
    assert [N.conformance("AND", n) for n in ("MIN", "PROD", "BDIF", "EINSTEIN")] == [
        "basic",
        "extension",
        "extension",
        "open",
    ]
    assert [N.conformance("OR", n) for n in ("ASUM", "BSUM", "NIPMAX")] == ["extension", "extension", "open"]
    assert [N.conformance("ACT", n) for n in ("MIN", "PROD", "BDIF")] == ["extension", "extension", "open"]
    assert [N.conformance("ACCU", n) for n in ("BSUM", "NSUM", "SUM", "PROBOR")] == [
        "extension",
        "extension",
        "open",
        "open",
    ]
    assert N.conformance("ACCU", "NOT_A_NORM") == "open"


def test_the_helpers_read_canonical_names_only() -> None:
    assert N.is_min("MIN") and not N.is_min(None) and not N.is_min("NMIN")
    assert N.is_prod("PROD") and not N.is_prod("ALGEBRAIC_PRODUCT")
    assert N.is_max("MAX") and not N.is_max("SUM") and not N.is_max(None)
    assert N.accumulates_by_max(None) and N.accumulates_by_max("") and not N.accumulates_by_max("BSUM")
    assert N.stand_in("NSUM") == "SUM" and N.stand_in("SUM") is None and N.stand_in(None) is None
