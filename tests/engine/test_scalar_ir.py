"""Single evaluation (``Controller.evaluate``, backend "python") runs the native evaluator's
IR printed as Python (ir/programs/scalar.py): the defuzzification is the IR's, not a
hand-written kernel's.  Checked against the reference interpreter (engine/reference/interp.py)
within 1e-9 of the output range: every system of the native suite (each method, Takagi-Sugeno
and Tsukamoto, chained blocks, NC, rule activation, terms given by inputs) one row at a time
with the state carried, with the Python kernels replaced by raising stand-ins; random systems
for every method; and what stays a kernel or falls back (smooth sets under a maximum method,
Python's domain errors)."""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import fuzzyctl
from fuzzyctl import model as m
from fuzzyctl.engine.controller import Controller
from fuzzyctl.ir.kernels import scalar as kernels
from fuzzyctl.ir.nodes import For, If, Kernel, Region, Stmt, While
from fuzzyctl.ir.programs import scalar
from fuzzyctl.ir.programs.evaluator import FastBuilder
from tests.codegen.test_native_methods import SMOOTH, SYSTEMS, mamdani, sugeno
from tests.engine.randsys import HI, LO, describe, input_values, system

TOL = 1e-9


def _kernel_nodes(body: list[Stmt]) -> list[Kernel]:
    out: list[Kernel] = []
    for s in body:
        if isinstance(s, Kernel):
            out.append(s)
        elif isinstance(s, If):
            for _c, b in s.branches:
                out += _kernel_nodes(b)
            out += _kernel_nodes(s.orelse)
        elif isinstance(s, For | While | Region):
            out += _kernel_nodes(s.body)
    return out


def _kernels(body: list[Stmt]) -> set[str]:
    return {k.name for k in _kernel_nodes(body)}


def _block(src: str) -> m.FunctionBlock:
    fb = fuzzyctl.load(src).main
    if "(* activation: " in src:  # fuzzylite's rule activation (as the native suite sets it)
        start = src.index("(* activation: ") + len("(* activation: ")
        activation = src[start : src.index(" *)", start)]
        blocks = tuple(dataclasses.replace(rb, rule_activation=activation) for rb in fb.rule_blocks)
        fb = dataclasses.replace(fb, rule_blocks=blocks)
    return fb


def _close(got: float, want: float, scale: float) -> bool:
    return bool(got == want or abs(got - want) <= TOL * scale or (math.isnan(got) and math.isnan(want)))


def _agree(fb: m.FunctionBlock, rows: list[dict[str, float]]) -> Controller:
    """The python backend's single evaluations against the interpreter's, row after row (the
    NC state carried by both)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # inputs outside their range are part of the test
        ctl = fuzzyctl.compile(fb, backend="python")
        ref = fuzzyctl.compile(fb, backend="interpreted")
        scale = {o.name: max(10.0, (o.high or 0.0) - (o.low or 0.0)) for o in ctl.plan.outputs}
        for i, row in enumerate(rows):
            want = ref.evaluate(row)
            got = ctl.evaluate(row)
            for o in want:
                assert _close(got[o], want[o], scale[o]), (o, i, row, got[o], want[o])
    return ctl


def _rows(ctl_inputs: list[str], n: int, seed: int) -> list[dict[str, float]]:
    rng = np.random.default_rng(seed)
    rows = []
    for _ in range(n):
        row = {v: float(rng.uniform(-1.0, 11.0)) for v in ctl_inputs}
        if "c" in row:
            row["c"] = float(rng.uniform(1.0, 9.0))
        if "humidity" in row:  # the dryer: humidity in %, load in kg
            row["humidity"] = float(rng.uniform(-5.0, 105.0))
        rows.append(row)
    return rows


def _allowed(ctl: Controller) -> set[str]:
    """The Python kernels the scalar program may keep for ``ctl``'s plan (ir/programs/scalar.py
    says which were measured faster than their IR): AM_LINES for three or more MIN-activated
    sets on one interval under MAX, the interpreter's MAMDANI where the IR was slower."""
    allowed = {"HOLD", "AM_LINES"}
    for op in ctl.plan.outputs:
        if op.kind == "mamdani" and not (scalar.ir_exact(op) if op.exact else scalar.ir_smooth(op)):
            allowed.add("MAMDANI")
    return allowed


@pytest.mark.parametrize("name", sorted(SYSTEMS))
def test_every_system_is_the_ir_in_python_and_agrees_with_the_interpreter(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    fb = _block(SYSTEMS[name])
    ctl = fuzzyctl.compile(fb, backend="python")
    allowed = _allowed(ctl)
    nodes = _kernel_nodes(scalar.build_scalar(ctl.plan).program.body)
    assert {k.name for k in nodes} <= allowed
    for k in nodes:
        if k.name == "AM_LINES":  # kept only for three or more MIN-activated sets under MAX
            _x0, _x1, accu, geom = k.data
            assert len(geom) >= 3 and accu == "MAX" and all(mn for _l, _r, mn in geom), k.data
    exact = name.startswith(("mamdani-COA", "mamdani-LM", "mamdani-RM", "mamdani-MOM"))
    if exact and not name.endswith(("probor", "bsum")):
        assert "MAMDANI" not in allowed, "an exact method under MAX or SUM of PROD is IR"
    make = kernels.make

    def only_allowed(kname: str, data: object, plan: object) -> object:
        assert kname in allowed, f"the hand-written Python kernel {kname} ran"
        return make(kname, data, plan)  # type: ignore[arg-type]

    monkeypatch.setattr(kernels, "make", only_allowed)
    fresh = Controller(ctl.plan)  # rendered on first use, under the stand-in
    _agree_controller(fresh, fb, _rows(list(ctl.inputs), 300, 7))


def _agree_controller(ctl: Controller, fb: m.FunctionBlock, rows: list[dict[str, float]]) -> None:
    ref = fuzzyctl.compile(fb, backend="interpreted")
    scale = {o.name: max(10.0, (o.high or 0.0) - (o.low or 0.0)) for o in ctl.plan.outputs}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for i, row in enumerate(rows):
            want = ref.evaluate(row)
            got = ctl.evaluate(row)
            for o in want:
                assert _close(got[o], want[o], scale[o]), (o, i, row, got[o], want[o])


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_random_piecewise_linear_systems_every_method(data: st.DataObject) -> None:
    fb = data.draw(system())
    rows = input_values(data.draw, fb, 6)
    try:
        _agree(fb, rows)
    except AssertionError as exc:
        raise AssertionError(f"{exc}\n{describe(fb)}") from None


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_random_smooth_outputs_by_centroid(data: st.DataObject) -> None:
    """Gaussian output terms: the IR's quadrature (ir/builders/quadrature.py) in Python."""
    fb = data.draw(system(methods=("COG",), smooth_output=True))
    ctl = fuzzyctl.compile(fb, backend="python")
    assert "MAMDANI" not in _kernels(scalar.build_scalar(ctl.plan).program.body)
    rows = input_values(data.draw, fb, 4)
    try:
        _agree(fb, rows)
    except AssertionError as exc:
        raise AssertionError(f"{exc}\n{describe(fb)}") from None


@pytest.mark.parametrize("method", ["LM", "RM", "MOM", "COA"])
def test_a_smooth_set_under_another_method_stays_the_interpreters(method: str) -> None:
    """The IR integrates only the centroid of smooth sets: such an output is the MAMDANI
    kernel (the interpreter's code), the rest of the program IR."""
    fb = _block(mamdani(method, terms=SMOOTH))
    ctl = _agree(fb, _rows(["a", "b"], 40, 3))
    assert _kernels(scalar.build_scalar(ctl.plan).program.body) == {"HOLD", "MAMDANI"}


def test_a_plan_the_ir_refuses_falls_back_to_the_kernels(monkeypatch: pytest.MonkeyPatch) -> None:
    """A plan the scalar builder refuses is the evaluator with the Python kernels, not the
    interpreter alone."""
    from fuzzyctl.ir.state import CodegenError

    def refuse(self: object) -> None:
        raise CodegenError("refused for the test")

    monkeypatch.setattr(scalar.ScalarBuilder, "build", refuse)
    fb = _block(mamdani("RM"))
    ctl = _agree(fb, _rows(["a", "b"], 30, 5))
    assert "MAMDANI" in _kernels(scalar.build_scalar(ctl.plan).program.body)
    assert _kernels(FastBuilder(ctl.plan, "py").build().program.body) == {"HOLD", "MAMDANI"}


def test_a_python_domain_error_takes_the_interpreters_ieee_value() -> None:
    """A Tsukamoto sigmoid at its full degree is ``log(0)``: -inf in C (the sigmoid's inverse
    at the end of the universe), a ValueError in Python; the call is then the interpreter's."""
    sigmoids = "TERM s := SIGMOID 5 1.5; TERM m := SIGMOID 5 1.5; TERM l := SIGMOID 5 1.5;"
    fb = _block(sugeno("WTAVER", sigmoids))
    rows = [{"a": 0.0, "b": 0.0}, {"a": 10.0, "b": 10.0}, {"a": 4.0, "b": 2.0}]
    _agree(fb, rows)


def test_the_scalar_program_is_what_the_controller_runs() -> None:
    """The rendered source holds the IR's defuzzification (no call of a Python kernel for
    an exact CoA output) and the controller's result is the program's."""
    fb = _block(mamdani("COA"))
    ctl = fuzzyctl.compile(fb, backend="python")
    fast = ctl._fast
    assert fast is not None and "_k" not in fast.__source__  # type: ignore[attr-defined]
    state: list[float | None] = [None]
    assert fast([2.0, 7.0], state)[0] == ctl.evaluate({"a": 2.0, "b": 7.0})["y"]
    assert LO <= state[0] <= HI  # type: ignore[operator]
