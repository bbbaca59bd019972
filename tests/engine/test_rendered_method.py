"""A defuzzification method with no hand-written numpy kernel runs on the numpy batch path by
its IR rendered (fuzzyctl/ir/kernels/rendered.py) and gives the reference's numbers.

The methods are registered at test time: a copy of LM whose entry names no numpy kernel (its
IR is grid_pieces' LM, its reference pwl.leftmost), and a method of a new kind defined here
by its reference and its IR only - the mean of the left-most and right-most maxima
(fuzzylite 4's MeanOfMaximum).  Both are checked row by row against the reference
interpreter (``Controller(plan, specialise=False)``) and, for the first, against LM's
hand-written kernel; the second against an independent brute force of its definition on a
fine grid.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator, Sequence

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.engine.controller import Controller
from fuzzyctl.engine.plan import GridPlan, Plan
from fuzzyctl.engine.reference import pwl
from fuzzyctl.ir.builders import grid_pieces as GP
from fuzzyctl.ir.kernels.rendered import output_kernel
from fuzzyctl.ir.nodes import Ex, Var
from fuzzyctl.ir.state import Gen
from fuzzyctl.kinds import methods as M

FCL = """
FUNCTION_BLOCK t
VAR_INPUT a : REAL; b : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY a RANGE := (0 .. 10); TERM lo := (0, 1) (10, 0); TERM hi := (0, 0) (10, 1); END_FUZZIFY
FUZZIFY b RANGE := (0 .. 10); TERM lo := (0, 1) (6, 0); TERM hi := (4, 0) (10, 1); END_FUZZIFY
DEFUZZIFY y RANGE := (0 .. 10);
  TERM s := (0, 0) (2, 1) (3, 1) (5, 0); TERM m := (2, 0) (5, 1) (8, 0); TERM l := (5, 0) (8, 1) (10, 1);
  METHOD : LM; DEFAULT := -1;
END_DEFUZZIFY
RULEBLOCK r AND : MIN; ACT : {act}; ACCU : {accu};
RULE 1 : IF a IS lo AND b IS lo THEN y IS s;
RULE 2 : IF a IS hi AND b IS lo THEN y IS m WITH 0.7;
RULE 3 : IF a IS lo AND b IS hi THEN y IS m;
RULE 4 : IF a IS hi AND b IS hi THEN y IS l;
RULE 5 : IF a IS hi OR b IS hi THEN y IS s WITH 0.4;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""

HERE = __name__


def mid_reference(pieces: Sequence[pwl.Piece], points: pwl.Points, area: float, moment: float) -> float:
    """The mean of the left-most and right-most maxima (pwl.maxima)."""
    _sup, lm, rm, _mom = pwl.maxima(pieces, points)
    return 0.5 * (lm + rm)


def mid_ir(g: Gen, p: GP.Pieces, grid: GridPlan, areas: list[Var], total: Var) -> Ex:
    """Its IR: grid_pieces' LM and RM."""
    return 0.5 * (GP.leftmost(g, p, grid, areas, total) + GP.rightmost(g, p, grid, areas, total))


def _entry(code: str, **kw: object) -> M.Method:
    spellings = {f: () for f in M.FORMATS}
    return M.Method(code, "test-only", {**spellings, "fcl": (code,), "json": (code,)}, **kw)  # type: ignore[arg-type]


ENTRIES = {
    "TLMNOKERNEL": _entry(
        "TLMNOKERNEL",
        maximum="left",
        reference="fuzzyctl.engine.reference.pwl:leftmost",
        ir="fuzzyctl.ir.builders.grid_pieces:leftmost",
    ),
    "TMIDMAX": _entry("TMIDMAX", reference=f"{HERE}:mid_reference", ir=f"{HERE}:mid_ir"),
}


@pytest.fixture
def registered(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    for code, entry in ENTRIES.items():
        monkeypatch.setitem(M.METHODS, code, entry)
    yield


def _plan(method: str, act: str, accu: str) -> Plan:
    plan = fuzzyctl.compile(fuzzyctl.load(FCL.format(act=act, accu=accu)), backend="python").plan
    outputs = tuple(dataclasses.replace(o, method=method) for o in plan.outputs)
    return dataclasses.replace(plan, outputs=outputs)


def _columns(n: int = 400) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(11)
    a, b = rng.uniform(0, 10, n), rng.uniform(0, 10, n)
    a[:20] = np.round(a[:20])  # vertices and plateau ends: ties between maxima
    b[:20] = np.round(b[:20])
    return {"a": a, "b": b}


CASES = [
    ("MIN", "MAX"),
    ("PROD", "MAX"),
    ("MIN", "SUM"),
    ("PROD", "SUM"),
    ("MIN", "BSUM"),
    ("PROD", "PROBOR"),
]


@pytest.mark.parametrize("method", sorted(ENTRIES))
@pytest.mark.parametrize(("act", "accu"), CASES)
def test_numpy_batch_equals_the_reference_without_a_kernel(
    registered: None, method: str, act: str, accu: str
) -> None:
    plan = _plan(method, act, accu)
    assert not M.METHODS[plan.outputs[0].method].numpy
    cols = _columns()
    batch = Controller(plan).evaluate_batch(cols)["y"]
    ref = Controller(plan, specialise=False).evaluate_batch(cols)["y"]
    assert Controller(plan)._batch is not None, "the numpy program, not the interpreter row by row"
    np.testing.assert_allclose(batch, ref, rtol=0, atol=1e-9 * 10)
    if method == "TLMNOKERNEL":  # LM's hand-written kernel: the same numbers
        lm = Controller(_plan("LM", act, accu)).evaluate_batch(cols)["y"]
        np.testing.assert_allclose(batch, lm, rtol=0, atol=1e-9 * 10)


@pytest.mark.parametrize(("act", "accu"), CASES[:4])
def test_linear_accumulations_are_if_converted(registered: None, act: str, accu: str) -> None:
    """Under MAX and SUM the IR is printed as numpy (every row at once; the LM copy's IR under
    MAX integrates three sets on one interval with arrays indexed by a per-row count: printed
    with gathers), never run row by row."""
    for method in ENTRIES:
        plan = _plan(method, act, accu)
        op = plan.outputs[0]
        layout = [(c.term or 0, c.act) for c in op.contributions]
        assert output_kernel(plan, op, layout).how == "numpy"  # type: ignore[attr-defined]


def test_the_new_kind_is_its_definition(registered: None) -> None:
    """TMIDMAX against a brute force of its definition: the set sampled on a fine grid (the
    set's own formula, not the engine's pieces), its height, the first and last sample
    within 1e-9 of it."""
    plan = _plan("TMIDMAX", "MIN", "MAX")
    cols = _columns(60)
    got = Controller(plan).evaluate_batch(cols)["y"]
    xs = np.linspace(0, 10, 200_001)
    terms = {
        "s": [(0, 0), (2, 1), (3, 1), (5, 0)],
        "m": [(2, 0), (5, 1), (8, 0)],
        "l": [(5, 0), (8, 1), (10, 1)],
    }
    mu = {k: np.interp(xs, [p[0] for p in v], [p[1] for p in v]) for k, v in terms.items()}
    for i in range(60):
        a, b = cols["a"][i], cols["b"][i]
        alo, ahi = 1 - a / 10, a / 10
        blo, bhi = float(np.interp(b, [0, 6], [1, 0])), float(np.interp(b, [4, 10], [0, 1]))
        fired = [
            ("s", min(alo, blo), 1.0),
            ("m", min(ahi, blo), 0.7),
            ("m", min(alo, bhi), 1.0),
            ("l", min(ahi, bhi), 1.0),
            ("s", max(ahi, bhi), 0.4),
        ]
        y = np.zeros_like(xs)
        for t, d, w in fired:
            y = np.maximum(y, w * np.minimum(d, mu[t]))
        top = y.max()
        at = xs[y >= top - 1e-9]
        assert got[i] == pytest.approx(0.5 * (at[0] + at[-1]), abs=1e-3), i


def _example_files() -> list[str]:
    from tests.codegen import systems as S

    return [p.name for p in S.example_files()]


@pytest.mark.parametrize("name", _example_files())
def test_the_ir_printed_with_gathers_is_the_reference_on_every_example(name: str) -> None:
    """npsrc's ``gather`` (a per-row index read as a gather, written as masked stores; a loop
    over each row's own bounds) on the whole native program of every example, against the
    reference interpreter: 1e-9 of each output's range."""
    from fuzzyctl.ir.programs.native import NativeBuilder
    from fuzzyctl.ir.render.npsrc import vectorise
    from fuzzyctl.ir.state import CodegenError
    from tests.codegen import systems as S

    plan = S.plan_of(S.EXAMPLES / name)
    if plan.options.emulate is not None or not plan.inputs:
        pytest.skip("evaluated by its own evaluator, or no input column")
    try:
        fn = vectorise(NativeBuilder(plan, "np").build(), gather=True)
    except CodegenError as e:
        pytest.skip(f"the native builder does not express it: {e}")
    data = S.random_inputs(plan, 300, seed=2)
    got = fn([data[:, i] for i in range(len(plan.inputs))], [None] * len(plan.outputs), len(data))
    ref = Controller(plan, specialise=False).evaluate_batch(
        {inp.name: data[:, i] for i, inp in enumerate(plan.inputs)}
    )
    for oi, op in enumerate(plan.outputs):
        if op.name in ref:
            scale = S.output_scale(plan, oi, ref[op.name])
            np.testing.assert_allclose(got[oi], ref[op.name], rtol=0, atol=1e-9 * scale, err_msg=op.name)
