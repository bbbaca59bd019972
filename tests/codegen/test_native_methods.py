"""compile(model, backend="native") runs the whole evaluation in C for every kind of system:
each defuzzification method, Takagi-Sugeno (Tsukamoto terms included), chained blocks,
NC/hold, smooth sets, fuzzylite's rule activation methods and terms given by inputs.

Each system is checked three ways: the native evaluator program holds no kernel the C would
have to call back (HOLD aside, which the renderer prints as two lines of C); evaluating it
calls no Python or numpy kernel (they are replaced by raising stand-ins); and it agrees with
the reference interpreter (engine/reference/interp.py) within 1e-9 of the output range on random
inputs, one row at a time (NC state carried) and as a batch."""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.engine.controller import Controller
from fuzzyctl.engine.native import NativeController
from fuzzyctl.ir.kernels import columns as kernels_np
from fuzzyctl.ir.kernels import scalar as kernels
from fuzzyctl.ir.nodes import For, If, Kernel, Region, Stmt, While
from fuzzyctl.ir.programs.native import build_native
from tests.codegen import systems as S

TOL = 1e-9


private_cache = S.private_cache  # builds go to a fresh cache directory (autouse)


INPUTS = """
VAR_INPUT a : REAL; b : REAL; END_VAR
FUZZIFY a RANGE := (0 .. 10); TERM lo := (0, 1) (10, 0); TERM hi := (0, 0) (10, 1); END_FUZZIFY
FUZZIFY b RANGE := (0 .. 10); TERM lo := (0, 1) (6, 0); TERM hi := (3, 0) (10, 1); END_FUZZIFY
"""

RULES = """
RULEBLOCK r AND : MIN; ACT : {act}; ACCU : {accu};{activation}
RULE 1 : IF a IS lo AND b IS lo THEN y IS s;
RULE 2 : IF a IS hi AND b IS lo THEN y IS m WITH 0.7;
RULE 3 : IF a IS lo OR b IS hi THEN y IS m;
RULE 4 : IF a IS hi AND b IS hi THEN y IS l;
END_RULEBLOCK
"""


def mamdani(method: str, accu: str = "MAX", act: str = "MIN", terms: str | None = None) -> str:
    terms = terms or "TERM s := (0,0) (2,1) (4,0); TERM m := (3,0) (5,1) (7,0); TERM l := (6,0) (8,1) (10,0);"
    return f"""FUNCTION_BLOCK t {INPUTS}
VAR_OUTPUT y : REAL; END_VAR
DEFUZZIFY y RANGE := (0 .. 10); {terms} METHOD : {method}; DEFAULT := NC; END_DEFUZZIFY
{RULES.format(act=act, accu=accu, activation="")}
END_FUNCTION_BLOCK"""


def sugeno(method: str, terms: str, accu: str = "", activation: str = "") -> str:
    acc = f" ACCU : {accu};" if accu else ""
    rules = RULES.format(act="PROD", accu="MAX", activation="").replace(" ACCU : MAX;", acc)
    if activation:  # fuzzylite's rule activation (no FCL spelling: set on the model below)
        rules = f"(* activation: {activation} *)" + rules
    return f"""FUNCTION_BLOCK t {INPUTS}
VAR_OUTPUT y : REAL; END_VAR
DEFUZZIFY y RANGE := (0 .. 10); {terms} METHOD : {method}; DEFAULT := -1; END_DEFUZZIFY
{rules}
END_FUNCTION_BLOCK"""


DRYER = (Path(__file__).resolve().parents[2] / "examples" / "dryer_chained.fcl").read_text()

MEMBER = f"""FUNCTION_BLOCK t
VAR_INPUT a : REAL; b : REAL; c : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY a RANGE := (0 .. 10); TERM lo := (0, 1) (c, 0); TERM hi := (c, 0) (10, 1); END_FUZZIFY
FUZZIFY b RANGE := (0 .. 10); TERM lo := (0, 1) (6, 0); TERM hi := (3, 0) (10, 1); END_FUZZIFY
DEFUZZIFY y RANGE := (0 .. 10); TERM s := (0,0) (2,1) (4,0); TERM m := (3,0) (5,1) (7,0);
  TERM l := (6,0) (8,1) (10,0); METHOD : RM; END_DEFUZZIFY
{RULES.format(act="MIN", accu="MAX", activation="")}
END_FUNCTION_BLOCK"""

SINGLETONS = "TERM s := 1; TERM m := 4.5; TERM l := 9;"
LINEAR = "TERM s := 1; TERM m := LINEAR 0.5 0.25 1; TERM l := LINEAR -0.25 0.5 2; "
TSUKAMOTO = "TERM s := RAMP 2 6; TERM m := SIGMOID 5 1.5; TERM l := (2, 1) (5, 0.6) (9, 0);"
SMOOTH = "TERM s := GAUSSIAN 2 1; TERM m := GAUSSIAN 5 1.2; TERM l := GAUSSIAN 8 0.8;"

SYSTEMS: dict[str, str] = {
    **{f"mamdani-{code}": mamdani(code) for code in ("COG", "COA", "LM", "RM", "MOM")},
    "mamdani-COA-sum-prod": mamdani("COA", accu="SUM", act="PROD"),
    "mamdani-LM-bsum": mamdani("LM", accu="BSUM"),
    "mamdani-MOM-probor": mamdani("MOM", accu="PROBOR"),
    "mamdani-COG-probor": mamdani("COG", accu="PROBOR"),
    "mamdani-COG-three-overlap": mamdani(
        "COG", terms="TERM s := (0,0) (4,1) (8,0); TERM m := (2,0) (5,1) (8,0); TERM l := (3,0) (7,1) (10,0);"
    ),
    "smooth-COG": mamdani("COG", terms=SMOOTH),
    # CoA, LM, RM, MoM of smooth sets (ir/builders/smooth_methods.py): clipped (MIN, plateaus
    # whose edges are located) and unclipped (PROD, smooth peaks)
    **{f"smooth-{code}": mamdani(code, terms=SMOOTH) for code in ("COA", "LM", "RM", "MOM")},
    **{f"smooth-{code}-prod": mamdani(code, act="PROD", terms=SMOOTH) for code in ("COA", "LM", "MOM")},
    "smooth-COA-sum": mamdani("COA", accu="SUM", terms=SMOOTH),
    "singletons-COGS": sugeno("COGS", SINGLETONS),
    "singletons-COGF": sugeno("COGF", SINGLETONS),
    "ts-WTAVER": sugeno("WTAVER", LINEAR),
    "ts-WTSUM": sugeno("WTSUM", LINEAR),
    "tsukamoto-WTAVER": sugeno("WTAVER", TSUKAMOTO),
    "tsukamoto-accumulated": sugeno("WTAVER", TSUKAMOTO, accu="MAX"),
    **{f"chained-{code}": DRYER.replace("METHOD : MoM", f"METHOD : {code}") for code in ("MoM", "LM", "CoA")},
    "member-RM": MEMBER,
    **{
        f"select-{sel.split()[0]}": sugeno("COGS", SINGLETONS, activation=sel)
        for sel in ("First 2", "Last 1 0.2", "Highest 2", "Lowest 1", "Proportional", "Threshold >= 0.3")
    },
}


def _kernels(body: list[Stmt]) -> Iterator[str]:
    for s in body:
        if isinstance(s, Kernel):
            yield s.name
        elif isinstance(s, If):
            for _c, b in s.branches:
                yield from _kernels(b)
            yield from _kernels(s.orelse)
        elif isinstance(s, For | While | Region):
            yield from _kernels(s.body)


def _compile(src: str) -> tuple[Controller, Controller]:
    fb = fuzzyctl.load(src).main
    if "(* activation: " in src:
        start = src.index("(* activation: ") + len("(* activation: ")
        activation = src[start : src.index(" *)", start)]
        blocks = tuple(dataclasses.replace(rb, rule_activation=activation) for rb in fb.rule_blocks)
        fb = dataclasses.replace(fb, rule_blocks=blocks)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # never a fallback, silent or not
        nat = fuzzyctl.compile(fb, backend="native")
    return nat, fuzzyctl.compile(fb, backend="interpreted")


@pytest.mark.parametrize("name", sorted(SYSTEMS))
def test_every_system_runs_wholly_in_c_and_agrees_with_the_interpreter(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    nat, ref = _compile(SYSTEMS[name])
    assert name.startswith("select-") == any(r.selection is not None for r in nat.plan.rules)
    assert isinstance(nat, NativeController)
    assert set(_kernels(build_native(nat.plan).program.body)) <= {"HOLD"}

    def refuse(*_a: object, **_k: object) -> None:
        raise AssertionError("a Python/numpy kernel ran")

    monkeypatch.setattr(kernels_np, "make", refuse)
    monkeypatch.setattr(kernels, "make", refuse, raising=False)
    rng = np.random.default_rng(11)
    n = 400
    cols = {v: rng.uniform(-1.0, 11.0, n) for v in nat.inputs}
    if "c" in cols:
        cols["c"] = rng.uniform(1.0, 9.0, n)
    if "humidity" in cols:  # the dryer: humidity in %, load in kg
        cols["humidity"] = rng.uniform(-5.0, 105.0, n)
    scale = {o.name: max(10.0, (o.high or 0.0) - (o.low or 0.0)) for o in nat.plan.outputs}
    batch = nat.evaluate_batch(cols)
    nat.reset()
    for i in range(n):
        row = {v: float(c[i]) for v, c in cols.items()}
        want = ref.evaluate(row)
        got = nat.evaluate(row)
        for o in want:
            assert _close(got[o], want[o], scale[o]), (name, o, i, got[o], want[o])
            assert _close(batch[o][i], want[o], scale[o]), (name, o, i, batch[o][i], want[o])


def _close(got: float, want: float, scale: float) -> bool:
    """Within 1e-9 of the range, or the same non-finite value."""
    return bool(got == want or abs(got - want) <= TOL * scale or (np.isnan(got) and np.isnan(want)))


def test_every_registered_method_has_a_native_system() -> None:
    """A method added to the registry is added here too (and so checked in C)."""
    from fuzzyctl.kinds import methods as M

    named = {k.split("-")[1] for k in SYSTEMS if k.startswith(("mamdani-", "singletons-", "ts-"))}
    for entry in M.METHODS.values():
        assert entry.code in named or any(s in named for s in entry.spellings.get("fcl", ())), entry.code


def test_the_default_backend_says_once_why_a_system_is_not_native(
    monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """Never a silent fallback: a system the C generator refuses is evaluated by the numpy
    path with one line on stderr naming why, once per process and reason; backend="native"
    warns.  (Every system above is native; the refusal is simulated.)"""
    from fuzzyctl.engine import native
    from fuzzyctl.ir.programs import native as native_program
    from fuzzyctl.ir.state import CodegenError

    def refuse(_plan: object) -> None:
        raise CodegenError("term y.s: something the C cannot express")

    monkeypatch.setattr(native_program, "build_native", refuse)
    monkeypatch.setenv("FUZZYCTL_CACHE_DIR", str(tmp_path))  # no library built before
    monkeypatch.delenv("FUZZYCTL_QUIET", raising=False)
    monkeypatch.delenv("FUZZYCTL_BACKEND", raising=False)
    monkeypatch.setattr(native, "_REASONS_SHOWN", set())
    fb = fuzzyctl.load(SYSTEMS["mamdani-COG"]).main
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a notice, not a warning
        first = fuzzyctl.compile(fb)
        fuzzyctl.compile(fb)
    assert type(first) is Controller
    err = capfd.readouterr().err
    assert err.count("\n") == 1 and "not evaluated natively" in err and "cannot express" in err, err
    with pytest.warns(RuntimeWarning, match="cannot express"):
        fuzzyctl.compile(fb, backend="native")


def test_the_native_coa_takes_libm_sqrt_and_matches_python_bit_for_bit() -> None:
    """The CoA's root (pieces.solve_linear) is libm's sqrt in the native C, correctly rounded
    like the math.sqrt of the same IR printed as Python: the two agree to the bit (the
    Newton helper of the PLC block's C, fz_sqrt, cost 30 ns a row and a last bit here and
    there), and the PLC block's C keeps its helper (no libm beyond exp)."""
    from fuzzyctl.codegen.api import generate_c
    from fuzzyctl.engine.native import sources

    src = SYSTEMS["mamdani-COA"]
    nat, _ref = _compile(src)
    py = fuzzyctl.compile(fuzzyctl.load(src).main, backend="python")
    text = sources(nat.plan)[1]["fz_native.c"]
    assert isinstance(text, str) and " sqrt(" in text and "fz_sqrt" not in text
    assert "fz_sqrt(" in "".join(generate_c(fuzzyctl.load(src).main).values())
    rng = np.random.default_rng(4)
    cols = {v: rng.uniform(0.0, 10.0, 500) for v in nat.inputs}
    batch = nat.evaluate_batch(cols)["y"]
    for i in range(500):  # rows in order, as the batch runs them (NC carried)
        assert py.evaluate({v: float(c[i]) for v, c in cols.items()})["y"] == batch[i], i


FUNCTION_OUTPUT_FLL = """\
Engine: fx
InputVariable: obstacle
  range: 0.000 1.000
  term: left Triangle 0.000 0.300 0.600
  term: right Triangle 0.400 0.700 1.000
OutputVariable: steer
  range: 0.000 1.000
  aggregation: {aggregation}
  defuzzifier: {defuzzifier}
  default: 0.25
  term: left {left}
  term: right {right}
RuleBlock: rb
  conjunction: none
  disjunction: none
  implication: Minimum
  activation: General
  rule: if obstacle is left then steer is right
  rule: if obstacle is right then steer is left
"""
# triangles written as functions of x (below 0 outside: cut at 0 by MAX), and smooth ones
TRI_FX = (
    "Function lt(x, 0.3) * (x - 0.1) / 0.2 + gt(x, 0.3) * (0.5 - x) / 0.2 + eq(x, 0.3)",
    "Function lt(x, 0.7) * (x - 0.5) / 0.2 + gt(x, 0.7) * (0.9 - x) / 0.2 + eq(x, 0.7)",
)
SMOOTH_FX = ("Function exp(-(x - 0.3)^2 / 0.02)", "Function 1 / (1 + ((x - 0.7) / 0.1)^2)")
FUNCTION_OUTPUTS = {
    **{f"tri-{d}": (TRI_FX, "Maximum", d) for d in ("Centroid", "Bisector", "MeanOfMaximum")},
    **{
        f"smooth-{d}": (SMOOTH_FX, "Maximum", d)
        for d in ("Centroid", "Bisector", "SmallestOfMaximum", "LargestOfMaximum", "MeanOfMaximum")
    },
    **{f"smooth-{d}-probor": (SMOOTH_FX, "AlgebraicSum", d) for d in ("Centroid", "Bisector")},
    "smooth-LargestOfMaximum-bsum": (SMOOTH_FX, "BoundedSum", "LargestOfMaximum"),
    # 0/0 where the rule fires: NaN (the reference's answer), the DEFAULT elsewhere
    "nan-Centroid": (("Function gt(x, 0.6) * (1 - x) / (0.6 - 0.6)", SMOOTH_FX[1]), "Maximum", "Centroid"),
    "nan-Bisector": (("Function gt(x, 0.6) * (1 - x) / (0.6 - 0.6)", SMOOTH_FX[1]), "Maximum", "Bisector"),
    "nan-MeanOfMaximum": (
        ("Function gt(x, 0.6) * (1 - x) / (0.6 - 0.6)", SMOOTH_FX[1]),
        "Maximum",
        "MeanOfMaximum",
    ),
}


@pytest.mark.parametrize("name", sorted(FUNCTION_OUTPUTS))
def test_function_of_x_terms_on_a_smooth_output_run_in_c(name: str) -> None:
    """A term whose membership is an expression of x on a smooth output (once a fallback to
    numpy) runs in C, every method, NaN where the reference says NaN, and agrees with the
    reference within 1e-9 of the range, row by row and as a batch."""
    (left, right), aggregation, defuzzifier = FUNCTION_OUTPUTS[name]
    text = FUNCTION_OUTPUT_FLL.format(
        left=left, right=right, aggregation=aggregation, defuzzifier=defuzzifier
    )
    doc = fuzzyctl.load(text, format="fll")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # never a fallback
        nat = fuzzyctl.compile(doc, backend="native")
    ref = fuzzyctl.compile(doc, backend="interpreted")
    assert isinstance(nat, NativeController)
    xs = np.linspace(0.0, 1.0, 101)
    batch = nat.evaluate_batch({"obstacle": xs})["steer"]
    nans = 0
    for i, x in enumerate(xs):
        want = ref.evaluate({"obstacle": float(x)})["steer"]
        got = nat.evaluate({"obstacle": float(x)})["steer"]
        nans += bool(np.isnan(want))
        assert _close(got, want, 1.0), (name, float(x), got, want)
        assert _close(batch[i], want, 1.0), (name, float(x), batch[i], want)
    assert (nans > 0) == name.startswith("nan-"), nans


def test_a_smooth_output_function_term_reading_an_input_still_says_why() -> None:
    """A function term reading an input changes with it: the calibration of the sampling
    cannot see it when the C is generated, so that system is not native, and says so."""
    text = FUNCTION_OUTPUT_FLL.format(
        left="Function exp(-(x - obstacle)^2 / 0.02)",
        right=SMOOTH_FX[1],
        aggregation="Maximum",
        defuzzifier="Centroid",
    )
    with pytest.warns(RuntimeWarning, match="given by variables"):
        ctl = fuzzyctl.compile(fuzzyctl.load(text, format="fll"), backend="native")
    assert type(ctl) is Controller


def _random_fx_term(rng: np.random.Generator) -> str:
    c, w = rng.uniform(0.1, 0.9), rng.uniform(0.05, 0.3)
    if rng.random() < 0.5:
        return f"Function exp(-(x - {c:.4f})^2 / {2 * w * w:.5f})"
    return f"Function 1 / (1 + ((x - {c:.4f}) / {w:.4f})^2)"


@pytest.mark.parametrize("seed", range(5))
def test_random_function_of_x_outputs_agree_with_the_interpreter(seed: int) -> None:
    """Seeded random Gaussian / Cauchy function terms of x, one method per seed (the CoA
    under a probabilistic sum): native, within 1e-9 of the range of the reference."""
    rng = np.random.default_rng(seed)
    method = ("Centroid", "Bisector", "SmallestOfMaximum", "LargestOfMaximum", "MeanOfMaximum")[seed]
    aggregation = "AlgebraicSum" if seed < 2 and seed % 2 else "Maximum"
    text = FUNCTION_OUTPUT_FLL.format(
        left=_random_fx_term(rng), right=_random_fx_term(rng), aggregation=aggregation, defuzzifier=method
    )
    doc = fuzzyctl.load(text, format="fll")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        nat = fuzzyctl.compile(doc, backend="native")
    ref = fuzzyctl.compile(doc, backend="interpreted")
    assert isinstance(nat, NativeController)
    xs = rng.uniform(0.0, 1.0, 41)
    batch = nat.evaluate_batch({"obstacle": xs})["steer"]
    for i, x in enumerate(xs):
        want = ref.evaluate({"obstacle": float(x)})["steer"]
        assert _close(batch[i], want, 1.0), (seed, float(x), batch[i], want)
