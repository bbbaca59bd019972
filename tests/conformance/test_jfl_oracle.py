"""The jfuzzylogic profile against the live jFuzzyLogic 3.3 (extra suite ``jfl_oracle``).

Random systems of every feature both read (tests/conformance/randfcl.py), one family per
jFuzzyLogic behaviour, run through the oracle in one JVM: every sample must agree within 1e-9
of the output's range.  Each behaviour is also shown to matter: with the profile's handling
of it broken (a *mutation*), its family disagrees.  ``make test`` replays a fixed set;
``make fuzz`` (HYPOTHESIS_PROFILE=fuzz) draws fresh systems.  The corpus files both load run
through both too.  ``python -m tests.conformance.jfl_agreement N SEED`` prints the table of
docs/engine.md.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
import platform
from collections.abc import Callable, Iterator

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import fuzzyctl
from fuzzyctl.diagnostics import DiagnosticError
from fuzzyctl.engine import compile as compile_mod
from fuzzyctl.engine.compat import jfl, jfl_terms
from fuzzyctl.engine.lowering import jfl_rules as lower_jfl
from fuzzyctl.engine.semantics import operators as ops
from fuzzyctl.engine.semantics import universe
from fuzzyctl.fcl import load_file
from tests.conformance import jfl_agreement, jfl_corpus, jfl_oracle
from tests.conformance.jfl_agreement import Stats
from tests.conformance.jfl_oracle import Answer, Job
from tests.conformance.randfcl import FAMILIES, System

pytestmark = pytest.mark.extra("jfl_oracle")

FUZZ = os.environ.get("HYPOTHESIS_PROFILE") == "fuzz"
PER_FAMILY = 3  # the fixed set: 3 systems of ~50 rows per behaviour, one JVM


@pytest.fixture(scope="module")
def fixed() -> tuple[list[System], list[Answer]]:
    systems = jfl_agreement.systems(PER_FAMILY, seed=0)
    return systems, jfl_oracle.run([Job(s.text, s.rows, s.outputs) for s in systems], cache=True)


def _agreement(systems: list[System], answers: list[Answer]) -> dict[str, Stats]:
    stats: dict[str, Stats] = {}
    for system, answer in zip(systems, answers, strict=True):
        s = stats.setdefault(system.family, Stats())
        s.systems += 1
        jfl_agreement._compare(system, answer, s, "jfuzzylogic")
    return stats


@pytest.mark.parametrize("family", list(FAMILIES))
def test_every_sample_agrees_with_jfuzzylogic(family: str, fixed: tuple[list[System], list[Answer]]) -> None:
    systems, answers = fixed
    chosen = [(s, a) for s, a in zip(systems, answers, strict=True) if s.family == family]
    stats = _agreement([s for s, _ in chosen], [a for _, a in chosen])[family]
    assert stats.samples >= 100
    assert stats.within_1e9 == stats.samples, stats.failures


# ------------------------------------------------------------------ each behaviour matters


def _setattr(
    target: object, name: str, value: object
) -> Callable[[], contextlib.AbstractContextManager[None]]:
    @contextlib.contextmanager
    def patch() -> Iterator[None]:
        old = getattr(target, name)
        setattr(target, name, value)
        try:
            yield
        finally:
            setattr(target, name, old)

    return patch


def _dict_item(
    d: dict[str, object], key: str, value: object
) -> Callable[[], contextlib.AbstractContextManager[None]]:
    @contextlib.contextmanager
    def patch() -> Iterator[None]:
        old = d[key]
        d[key] = value
        try:
            yield
        finally:
            d[key] = old

    return patch


def _profile(**changes: object) -> Callable[[], contextlib.AbstractContextManager[None]]:
    base = compile_mod.COMPAT_PROFILES["jfuzzylogic"]
    return _dict_item(compile_mod.COMPAT_PROFILES, "jfuzzylogic", dataclasses.replace(base, **changes))  # type: ignore[arg-type]


def _iec_pwl(x: object, xs: list[object], ys: list[object]) -> object:
    """Our own points (sorted; the upper value on a vertical edge) instead of jFuzzyLogic's."""
    from fuzzyctl.engine.semantics import shapes

    pts = shapes.sort_points(list(zip(map(float, xs), map(float, ys), strict=True)))  # type: ignore[arg-type]
    return shapes.pwl_value_np(pts, np.asarray(x, dtype=np.float64))


def _wider(kind: str, params: object) -> tuple[float, float]:
    lo, hi = _span(kind, params)  # type: ignore[arg-type]
    return lo - 0.01 * (hi - lo), hi + 0.01 * (hi - lo)


_span = universe.span

MUTATIONS: dict[str, Callable[[], contextlib.AbstractContextManager[None]]] = {
    "span_universe": _setattr(universe, "span", _wider),
    "var_range": _profile(ignore_declared_range=False),
    "singletons_merged": _setattr(jfl, "_java_equal", lambda a, b: np.zeros(np.shape(a), dtype=bool)),
    "output_in_condition": _setattr(
        jfl.JflEvaluator, "_crisp_degree", lambda self, var, term, crisp, vals: np.zeros_like(crisp[0])
    ),
    "last_and_or": _setattr(lower_jfl, "operator_pair", lambda rb: ops.resolve_pair(rb.and_op, rb.or_op)),
    "per_block_accu": _setattr(lower_jfl, "accumulation", lambda rb: "MAX"),
    "nc_nan": _setattr(
        jfl.JflEvaluator,
        "_reset_value",
        lambda self, oi, state: (
            float(self.plan.outputs[oi].default)
            if self.plan.outputs[oi].default is not None and not self.plan.outputs[oi].no_change
            else (0.0 if state[oi] is None or math.isnan(state[oi]) else state[oi])  # type: ignore[arg-type]
        ),
    ),
    "vertical_edges": _setattr(jfl_terms, "_pwl", _iec_pwl),
    "riemann": _setattr(jfl, "SAMPLES", 999),
    "accu_default": _setattr(
        lower_jfl, "accumulation", lambda rb: ops.resolve_accu(rb.accu) if rb.accu else "MAX"
    ),
    "nsum": _setattr(
        lower_jfl,
        "accumulation",
        lambda rb, real=lower_jfl.accumulation: "SUM" if rb.accu == "NSUM" else real(rb),
    ),
    "precedence": _setattr(lower_jfl, "left_to_right", lambda c: c),
    "with": _profile(weight_whole_rule=False),
}


@pytest.mark.parametrize("family", [f for f in FAMILIES if f in MUTATIONS])
def test_breaking_the_behaviour_breaks_its_family(
    family: str, fixed: tuple[list[System], list[Answer]]
) -> None:
    """Each family does exercise its behaviour: without the profile's handling of it, some
    of its samples disagree with jFuzzyLogic."""
    systems, answers = fixed
    chosen = [(s, a) for s, a in zip(systems, answers, strict=True) if s.family == family]
    with MUTATIONS[family]():
        stats = _agreement([s for s, _ in chosen], [a for _, a in chosen])[family]
    assert stats.within_1e9 < stats.samples, family


# ------------------------------------------------------------------ fresh systems (make fuzz)


@settings(max_examples=20 if FUZZ else 1, deadline=None, database=None, derandomize=not FUZZ)
@given(seed=st.integers(1000, 2**31))
def test_fresh_random_systems_agree(seed: int) -> None:
    """``make fuzz``: fresh systems of every family (one per family per example), every
    sample within 1e-9."""
    systems = jfl_agreement.systems(1, seed)
    stats = jfl_agreement.compare(systems)
    for family, s in stats.items():
        assert s.within_1e9 == s.samples, (family, seed, s.failures)


def _differ(a: float | str, b: float | str, tol: float) -> bool:
    if isinstance(a, str) or isinstance(b, str):
        return a != b
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) != math.isnan(b)
    return abs(a - b) > tol


def test_hotspot_intrinsics_move_jfuzzylogic_itself_exactly_where_we_differ() -> None:
    """On x86-64, HotSpot's default ``Math.exp``/``cos``/``pow`` are Intel intrinsics, not
    fdlibm.  jFuzzyLogic's own answers then change where a last bit decides a tie of MM, LM,
    RM or COA (and in what reads that output's value); those are exactly the samples where
    our profile (fdlibm, as StrictMath) differs from that JVM."""
    systems = jfl_agreement.systems(20, 5000)
    families = ("span_universe", "output_in_condition", "nc_nan", "precedence")
    systems = [s for s in systems if s.family in families]
    jobs = [Job(s.text, s.rows, s.outputs) for s in systems]
    strict = jfl_oracle.run(jobs, cache=True)
    intrinsic = jfl_oracle.run(jobs, cache=True, libm="intrinsic")
    moved = 0
    for system, a, b in zip(systems, strict, intrinsic, strict=True):
        got, scale, _ = jfl_agreement.ours(system)
        assert got is not None
        for k, name in enumerate(b.outputs):
            for i, (ra, rb) in enumerate(zip(a.rows, b.rows, strict=True)):
                tol = 1e-9 * scale[name][0]
                java_moved = _differ(ra[k], rb[k], tol)
                assert java_moved == _differ(float(got[name][i]), rb[k], tol), (system.seed, name, i)
                moved += java_moved
    if platform.machine().lower() in ("x86_64", "amd64"):
        assert moved > 0  # the intrinsics exist there; elsewhere both JVM settings may agree


# ------------------------------------------------------------------ the corpus


@pytest.mark.extra("corpus", "jfl_oracle")
def test_corpus_files_both_run_agree() -> None:
    """Every corpus file both load and jFuzzyLogic can evaluate gives jFuzzyLogic's numbers;
    the files the profile refuses although jFuzzyLogic loads them are exactly those it then
    throws on at every evaluation (singletons under its default COG, terms it lacks)."""
    stats, refused, cannot = jfl_corpus.compare_corpus(jfl_corpus.corpus_files())
    print(f"\ncorpus: {stats.systems} files both run, {stats.samples} samples, worst {stats.worst:.2g}")
    assert stats.systems >= 150 and stats.samples >= 3000
    assert stats.within_1e9 == stats.samples, stats.failures
    files = [f for f in jfl_corpus.corpus_files() if f.name in refused]
    answers = jfl_oracle.run([Job(f, all_inputs=1.0) for f in files], cache=True)
    for f, answer in zip(files, answers, strict=True):
        cells = [v for row in answer.rows for v in row]
        assert cells and all(isinstance(v, str) for v in cells), (f.name, answer)
    # and `check --compat jfuzzylogic` says why jFuzzyLogic cannot run the others
    for name in cannot:
        result = load_file(jfl_corpus.corpus_dir() / name, compat="jfuzzylogic")
        assert any(d.code == "jfl-fails" for d in result.diagnostics), name


def test_the_profile_refuses_what_jfuzzylogic_throws_on() -> None:
    """Singletons under jFuzzyLogic's default COG: it throws at the first rule, we refuse."""
    text = (
        "FUNCTION_BLOCK f\nVAR_INPUT x : REAL; END_VAR\nVAR_OUTPUT y : REAL; END_VAR\n"
        "FUZZIFY x\n  TERM a := (0, 0) (1, 1);\nEND_FUZZIFY\n"
        "DEFUZZIFY y\n  TERM s := 1;\nEND_DEFUZZIFY\n"
        "RULEBLOCK r\n  RULE 1 : IF x IS a THEN y IS s;\nEND_RULEBLOCK\nEND_FUNCTION_BLOCK\n"
    )
    (answer,) = jfl_oracle.run([Job(text, [{"x": 0.5}])])
    assert isinstance(answer.rows[0][0], str) and "discrete" in answer.rows[0][0]
    with pytest.raises(DiagnosticError, match="COG"):
        fuzzyctl.compile(fuzzyctl.load(text), compat="jfuzzylogic")


def test_gauss2_of_nan_and_an_output_no_rule_concludes() -> None:
    """Two readings found by fresh systems: jFuzzyLogic's GAUSS2 gives 1 at NaN (an NC output
    before its first value), and a condition may test an output that no rule concludes on
    (its crisp value is its DEFAULT)."""
    text = (
        "FUNCTION_BLOCK f\nVAR_INPUT x : REAL; END_VAR\nVAR_OUTPUT y : REAL; z : REAL; END_VAR\n"
        "FUZZIFY x\n  TERM a := (0, 0) (10, 1);\nEND_FUZZIFY\n"
        "DEFUZZIFY y\n  TERM g := GAUSS2 4 1 6 1;\n  TERM h := (0, 0) (2, 1) (3, 0);\n  METHOD : COG;\n"
        "  RANGE := (0 .. 10);\nEND_DEFUZZIFY\n"
        "DEFUZZIFY z\n  TERM lo := TRAPE 0 0 2 4;\n  TERM hi := TRAPE 3 5 10 10;\n  METHOD : COG;\n"
        "  DEFAULT := 1;\n  RANGE := (0 .. 10);\nEND_DEFUZZIFY\n"
        "RULEBLOCK r\n  AND : MIN;\n  ACT : MIN;\n  ACCU : MAX;\n  RULE 1 : IF y IS g THEN y IS h;\n"
        "  RULE 2 : IF x IS a AND z IS lo THEN y IS g;\nEND_RULEBLOCK\nEND_FUNCTION_BLOCK\n"
    )
    rows = [{"x": 2.0}, {"x": 7.0}, {"x": 9.5}]
    (answer,) = jfl_oracle.run([Job(text, rows)])
    assert answer.clean and answer.outputs == ["y", "z"]
    c = fuzzyctl.compile(fuzzyctl.load(text), compat="jfuzzylogic")
    got = [c.evaluate(r) for r in rows]
    for want, mine in zip(answer.rows, got, strict=True):
        assert isinstance(want[0], float) and abs(mine["y"] - want[0]) <= 1e-9 * 10, (want, mine)
        assert mine["z"] == want[1] == 1.0
    assert not math.isnan(got[0]["y"])  # with GAUSS2(NaN) = NaN, the first set would be all NaN
