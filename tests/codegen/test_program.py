"""The program builder: features beyond the example files (hedges, singleton LM/RM/MoM,
Takagi-Sugeno, degree outputs, the compat switches) through the native backend against the
Python core, and the refusals."""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl import model as m
from fuzzyctl.codegen import CodegenError, generate_c
from fuzzyctl.engine import native
from fuzzyctl.engine.native import NativeController
from fuzzyctl.engine.plan import Options, Plan
from fuzzyctl.ir.programs.plc_block import build_program
from tests.codegen import systems as S
from tests.engine.builders import is_, pts, rule, shape, single, terms, then, var_in, var_out


@pytest.fixture(scope="module", autouse=True)
def private_cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    old = os.environ.get("FUZZYCTL_CACHE_DIR")
    os.environ["FUZZYCTL_CACHE_DIR"] = str(tmp_path_factory.mktemp("cache"))
    yield
    if old is None:
        del os.environ["FUZZYCTL_CACHE_DIR"]
    else:
        os.environ["FUZZYCTL_CACHE_DIR"] = old


def _agree(plan: Plan, n: int = 400, tol: float = 1e-12) -> float:
    ctl = NativeController(plan, native.build(plan))
    data = np.random.default_rng(1).uniform(-1.0, 11.0, (n, len(plan.inputs)))
    for i, inp in enumerate(plan.inputs):
        if inp.degree:
            data[:, i] = np.clip(data[:, i] / 10.0, 0.0, 1.0)
    got = ctl.evaluate_batch({inp.name: data[:, i] for i, inp in enumerate(plan.inputs)})
    cols = [got[o.name] for o in plan.outputs if o.is_output]
    err = S.max_error(plan, np.column_stack(cols), S.reference(plan, data, "scalar"))
    assert err <= tol, err
    return err


def _block(
    method: str, accu: str, out_terms: tuple[m.Term, ...], hedges: tuple[str, ...] = ()
) -> m.FunctionBlock:
    return m.FunctionBlock(
        "hb",
        variables=var_in("x", "w") + var_out("y", "d"),
        fuzzify=(
            m.FuzzifyBlock(
                "x", terms(lo=pts((0, 1), (6, 0)), mid=shape("gaussian", 5, 2), hi=shape("sigmoid", 6, 1.5))
            ),
        ),
        defuzzify=(m.DefuzzifyBlock("y", out_terms, m.Range(0, 10), method, m.Default(None, True)),),
        rule_blocks=(
            m.RuleBlock(
                "r",
                (
                    rule("1", is_("x", "lo", hedges=hedges[:1]), then("y", "a")),
                    rule("2", is_("x", "mid", hedges=hedges[1:2]), then("y", "b", m.Ref("w"))),
                    rule("3", is_("x", "hi", negated=True, hedges=hedges[2:]), then("y", "c", 0.7)),
                    rule("4", m.Degree("w"), then("d")),
                ),
                "MIN",
                None,
                "MIN",
                accu,
            ),
        ),
    )


SINGLETONS = terms(a=single(2.0), b=single(5.0), c=m.SingletonsMF((m.Point(7.0, 1.0), m.Point(9.0, 0.5))))
TS = terms(a=shape("constant", 2.0), b=shape("linear", 0.5, -1.0, 3.0), c=shape("constant", 8.0))


@pytest.mark.parametrize("method", ["COGS", "LM", "RM", "MOM"])
@pytest.mark.parametrize("accu", ["MAX", "SUM", "PROBOR", "EINSTEIN"])
def test_singleton_outputs_hedges_and_degree_outputs(method: str, accu: str) -> None:
    fb = _block(method, accu, SINGLETONS, ("very", "seldom", "pow:2.5"))
    _agree(fuzzyctl.compile(fb, backend="interpreted").plan)


@pytest.mark.parametrize("method", ["WTAVER", "WTSUM"])
@pytest.mark.parametrize("accu", [None, "MAX", "HAMACHER"])
def test_takagi_sugeno_outputs(method: str, accu: str | None) -> None:
    fb = _block(method, accu or "MAX", TS, ("somewhat", "extremely", "any"))
    if accu is None:
        fb = dataclasses.replace(fb, rule_blocks=(dataclasses.replace(fb.rule_blocks[0], accu=None),))
    _agree(fuzzyctl.compile(fb, backend="interpreted").plan)


def test_the_jfuzzylogic_profile_is_not_generated() -> None:
    """That profile reproduces jFuzzyLogic's 1000-point arithmetic for cross-checks."""
    fb = fuzzyctl.load(
        """FUNCTION_BLOCK j VAR_INPUT x : REAL; END_VAR VAR_OUTPUT y : REAL; END_VAR
        FUZZIFY x TERM lo := (0, 1) (10, 0); TERM hi := (0, 0) (10, 1); END_FUZZIFY
        DEFUZZIFY y TERM a := 2; TERM b := 7; METHOD : COGS; DEFAULT := 0; END_DEFUZZIFY
        RULEBLOCK r AND : MIN; ACCU : MAX; RULE 1 : IF x IS lo THEN y IS a; RULE 2 : IF x IS hi THEN y IS b;
        END_RULEBLOCK END_FUNCTION_BLOCK"""
    )
    plan = fuzzyctl.compile(fb, backend="interpreted", compat="jfuzzylogic").plan
    with pytest.raises(CodegenError, match=r"jfuzzylogic profile .* iec profile"):
        build_program(plan, "c")


@pytest.mark.parametrize("compat", ["fuzzylite", "pyfuzzylite"])
def test_compat_switches(compat: str) -> None:
    for out in (
        SINGLETONS,
        terms(a=shape("triangle", 0, 2, 5), b=shape("trapezoid", 3, 4, 6, 8), c=pts((6, 0), (9, 1))),
    ):
        method = "COGS" if out is SINGLETONS else "COG"
        fb = _block(method, "MAX", out, ("very", "", "")[:1])
        _agree(fuzzyctl.compile(fb, backend="interpreted", compat=compat).plan)


def test_refusals_name_what_cannot_be_generated() -> None:
    tsukamoto = _block(
        "WTAVER", "MAX", terms(a=shape("ramp", 0, 5), b=shape("ramp", 10, 5), c=shape("ramp", 2, 9))
    )
    plan = fuzzyctl.compile(tsukamoto, backend="interpreted").plan
    with pytest.raises(CodegenError, match=r"term y\.a: Tsukamoto"):
        build_program(plan, "c")
    smooth = _block(
        "COG", "MAX", terms(a=shape("gaussian", 2, 1), b=shape("gaussian", 5, 1), c=shape("bell", 8, 1, 2))
    )
    assert "Gauss-Kronrod" in generate_c(smooth)["hb.h"]  # the quadrature bound in the header
    coa = _block(  # every method of smooth sets is generated (tests/codegen/test_smooth_plc.py)
        "COA", "MAX", terms(a=shape("gaussian", 2, 1), b=shape("gaussian", 5, 1), c=shape("gaussian", 8, 1))
    )
    assert "|CoA error| <=" in generate_c(coa)["hb.h"]
    height = _block(
        "COG",
        "MAX",
        terms(
            a=m.ShapeMF("triangle", (0.0, 2.0, 5.0), m.Ref("w")),
            b=shape("triangle", 3, 5, 8),
            c=pts((6, 0), (9, 1)),
        ),
    )
    with pytest.raises(CodegenError, match=r"a: a height given by a variable"):
        generate_c(height)
    function_term = _block(
        "WTAVER", "MAX", terms(a=shape("constant", 1), b=m.FunctionMF(m.Name("x")), c=shape("constant", 3))
    )
    assert fuzzyctl.codegen.generate_st(function_term)  # + - * / and IEC functions
    assert generate_c(function_term)  # C expresses them


def test_a_new_plan_switch_is_refused_not_ignored(tmp_path: Path) -> None:
    plan = fuzzyctl.compile(fuzzyctl.load(S.EXAMPLES / "figure7.fcl"), backend="interpreted").plan
    future = dataclasses.make_dataclass(
        "Options", [("clamp_inputs", bool, False)], bases=(Options,), frozen=True
    )
    changed = dataclasses.replace(plan, options=future(clamp_inputs=True))
    with pytest.raises(CodegenError, match=r"engine option of \w+: clamp inputs = True: a setting"):
        build_program(changed, "c")
    build_program(dataclasses.replace(plan, options=future()), "c")  # at its default: fine
