"""One answer on every path for output sets (issue 25.1, 25.6, 25.10), small systems written
here, each against a closed form or an independent formulation:

* a Function term that goes below 0 (fuzzylite's function.fll writes triangles that way):
  under MAX the accumulated set starts from the empty set, so what is below 0 is cut at 0 - the
  same set as the triangle written as points, which the exact piecewise-linear path integrates
  in closed form;
* a Gaussian clipped by MIN (kinks inside the quadrature's intervals): CoG by erf;
* CoA with a non-unique bisector: the middle of the zero gap, exactly;
* a 0/0 in a Function term: NaN with bounded memory, "rules fired" (not "no rule fired");
* LargestOfMaximum of a Function term: a bounded number of evaluations of the term."""

from __future__ import annotations

import math
import shutil
import tracemalloc
import warnings

import numpy as np
import pytest

from fuzzyctl.api import compile as compile_api
from fuzzyctl.api import load
from fuzzyctl.cli import main

# fuzzylite's obstacle avoidance with the output triangles written as Function terms that are
# negative outside them (left peaks at 0.3, right at 0.7)
FUNCTION_FLL = """\
Engine: fn
InputVariable: obstacle
  range: 0.000 1.000
  term: left Triangle 0.000 0.300 0.600
  term: right Triangle 0.400 0.700 1.000
OutputVariable: steer
  range: 0.000 1.000
  aggregation: {aggregation}
  defuzzifier: {defuzzifier}
  default: nan
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
F_LEFT = "Function lt(x, 0.3) * (x - 0.1) / 0.2 + gt(x, 0.3) * (0.5 - x) / 0.2 + eq(x, 0.3)"
F_RIGHT = "Function lt(x, 0.7) * (x - 0.5) / 0.2 + gt(x, 0.7) * (0.9 - x) / 0.2 + eq(x, 0.7)"
T_LEFT, T_RIGHT = "Triangle 0.100 0.300 0.500", "Triangle 0.500 0.700 0.900"


def _fll(left: str, right: str, aggregation: str = "Maximum", defuzzifier: str = "Centroid") -> object:
    text = FUNCTION_FLL.format(left=left, right=right, aggregation=aggregation, defuzzifier=defuzzifier)
    return load(text, format="fll")


def _quiet_compile(doc: object, backend: str) -> object:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return compile_api(doc, backend=backend)  # type: ignore[arg-type]


def test_function_term_below_zero_is_cut_at_zero_on_every_path() -> None:
    """Scalar (python), batch (numpy) and the interpreter give the centroid of the same set
    written as triangles (exact closed form), within 1e-9 of the range, at 101 inputs."""
    xs = np.linspace(0.0, 1.0, 101)
    exact = _quiet_compile(_fll(T_LEFT, T_RIGHT), "python")
    want = [exact.evaluate({"obstacle": float(x)})["steer"] for x in xs]  # type: ignore[attr-defined]
    doc = _fll(F_LEFT, F_RIGHT)
    for backend in ("python", "interpreted"):
        ctl = _quiet_compile(doc, backend)
        got = [ctl.evaluate({"obstacle": float(x)})["steer"] for x in xs]  # type: ignore[attr-defined]
        batch = ctl.evaluate_batch({"obstacle": xs})["steer"]  # type: ignore[attr-defined]
        for x, w, g, b in zip(xs, want, got, batch, strict=True):
            if math.isnan(w):
                assert math.isnan(g) and math.isnan(b), (backend, x)
                continue
            assert abs(g - w) <= 1e-9 and abs(b - w) <= 1e-9, (backend, float(x), g, float(b), w)


GAUSS_FCL = """
FUNCTION_BLOCK g
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x
  TERM t := (0, 0) (1, 1);
END_FUZZIFY
DEFUZZIFY y
  TERM g := GAUSS {m} {sd};
  METHOD : COG;
  DEFAULT := 0;
  RANGE := ({lo} .. {hi});
END_DEFUZZIFY
RULEBLOCK rb
  ACT : MIN;
  ACCU : MAX;
  RULE 1 : IF x IS t THEN y IS g;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def _clipped_gauss_cog(m: float, sd: float, a: float, lo: float, hi: float) -> float:
    """CoG of min(a, exp(-(u-m)^2 / 2sd^2)) on [lo, hi], by erf (kinks at m +- d)."""
    d = sd * math.sqrt(-2.0 * math.log(a))
    k = sd * math.sqrt(math.pi / 2.0)

    def g(u: float) -> float:
        return math.exp(-((u - m) ** 2) / (2.0 * sd * sd))

    def tail(u: float, v: float) -> tuple[float, float]:
        area = k * (math.erf((v - m) / (sd * math.sqrt(2.0))) - math.erf((u - m) / (sd * math.sqrt(2.0))))
        return area, m * area + sd * sd * (g(u) - g(v))

    p0, p1 = max(lo, m - d), min(hi, m + d)
    area, moment = a * (p1 - p0), a * 0.5 * (p1 * p1 - p0 * p0)
    for u, v in ((lo, p0), (p1, hi)):
        if v > u:
            ta, tm = tail(u, v)
            area, moment = area + ta, moment + tm
    return moment / area


@pytest.mark.parametrize(("m", "sd", "lo", "hi"), [(3.0, 1.3, 0.0, 10.0), (0.37, 0.05, 0.0, 1.0)])
def test_clipped_smooth_set_matches_its_closed_form_on_every_path(
    m: float, sd: float, lo: float, hi: float
) -> None:
    """The interpreter cuts its quadrature at the clipping kinks (it was 6.7e-8 of the range
    off on such sets): every path within 1e-9 of the range of the erf closed form."""
    doc = load(GAUSS_FCL.format(m=m, sd=sd, lo=lo, hi=hi))
    degrees = [0.013, 0.2, 0.5, 0.77, 0.999]
    want = [_clipped_gauss_cog(m, sd, a, lo, hi) for a in degrees]
    tol = 1e-9 * (hi - lo)
    for backend in ("python", "interpreted", "native"):
        if backend == "native" and not shutil.which("cc"):
            continue
        ctl = _quiet_compile(doc, backend)
        batch = ctl.evaluate_batch({"x": np.array(degrees)})["y"]  # type: ignore[attr-defined]
        for a, w, b in zip(degrees, want, batch, strict=True):
            got = ctl.evaluate({"x": a})["y"]  # type: ignore[attr-defined]
            assert abs(got - w) <= tol and abs(b - w) <= tol, (backend, a, got, float(b), w)


COA_FCL = """
FUNCTION_BLOCK coa
VAR_INPUT a : REAL; b : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY a
  TERM t := (0, 0) (1, 1);
END_FUZZIFY
FUZZIFY b
  TERM t := (0, 0) (1, 1);
END_FUZZIFY
DEFUZZIFY y
  TERM l := {left};
  TERM r := {right};
  METHOD : COA;
  DEFAULT := 0;
  RANGE := (0 .. 10);
END_DEFUZZIFY
RULEBLOCK rb
  ACT : {act};
  ACCU : MAX;
  RULE 1 : IF a IS t THEN y IS l;
  RULE 2 : IF b IS t THEN y IS r;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


@pytest.mark.parametrize(
    ("left", "right", "gap"),
    [
        ("(0, 0) (1, 1) (2, 0)", "(8, 0) (9, 1) (10, 0)", (2.0, 8.0)),
        ("(0, 0) (0.5, 1) (3, 0)", "(6.5, 0) (9, 1) (9.5, 0)", (3.0, 6.5)),  # mirror images
        ("(1, 0) (1, 1) (2, 1) (2, 0)", "(7, 0) (7, 1) (8, 1) (8, 0)", (2.0, 7.0)),  # vertical edges
    ],
)
@pytest.mark.parametrize("act", ["MIN", "PROD"])
def test_coa_of_a_zero_gap_is_its_middle_on_every_path(
    left: str, right: str, gap: tuple[float, float], act: str
) -> None:
    """Two sets of equal area either side of a gap where the set is 0: every point of the
    gap halves the area; CoA answers its middle exactly (docs/engine.md), whatever the degree
    (rounding used to pick an end: 8.00000002 at 0.7, 1.99999999 at 0.3)."""
    doc = load(COA_FCL.format(left=left, right=right, act=act))
    middle = 0.5 * (gap[0] + gap[1])
    degrees = [0.7, 0.3, 0.5, 0.123, 0.999, 1e-9, 0.1 + 0.2]
    backends = ["python", "interpreted"] + (["native"] if shutil.which("cc") else [])
    for backend in backends:
        ctl = _quiet_compile(doc, backend)
        batch = ctl.evaluate_batch({"a": np.array(degrees), "b": np.array(degrees)})["y"]  # type: ignore[attr-defined]
        for d, b in zip(degrees, batch, strict=True):
            assert ctl.evaluate({"a": d, "b": d})["y"] == middle, (backend, d)  # type: ignore[attr-defined]
            assert b == middle, (backend, "batch", d, float(b))


def test_coa_with_a_unique_bisector_is_unchanged() -> None:
    """Unequal degrees: the bisector is inside the larger set, in closed form (left set area
    A1 = 2 a1 - a1^2 of the clipped triangle, the rest solved on the right one)."""
    doc = load(COA_FCL.format(left="(0, 0) (1, 1) (2, 0)", right="(8, 0) (9, 1) (10, 0)", act="PROD"))
    a1, a2 = 0.3, 0.9
    # PROD: areas a1 and a2 (unit triangles); half = (a1 + a2) / 2 lies in the right one at
    # distance s from 8 with a2 s^2 / 2 = half - a1 (s <= 1)
    s = math.sqrt(2.0 * (0.5 * (a1 + a2) - a1) / a2)
    for backend in ("python", "interpreted"):
        ctl = _quiet_compile(doc, backend)
        assert ctl.evaluate({"a": a1, "b": a2})["y"] == pytest.approx(8.0 + s, abs=1e-12)  # type: ignore[attr-defined]


DIV0_FLL = """\
Engine: div0
InputVariable: obstacle
  range: 0.000 1.000
  term: low Triangle 0.000 0.300 0.600
OutputVariable: y
  range: 0.000 1.000
  aggregation: Maximum
  defuzzifier: Centroid
  default: 0.25
  term: bad Function gt(x, 0.6) * (1 - x) / (0.6 - 0.6)
RuleBlock: rb
  conjunction: none
  disjunction: none
  implication: Minimum
  activation: General
  rule: if obstacle is low then y is bad
"""


def test_a_zero_over_zero_set_is_nan_with_bounded_memory() -> None:
    """0/0 in a Function term: the set is NaN where the rule fired; the quadrature stops
    refining such a row at once (it used to refine every row to 40,000 intervals: 23-37 MB a
    row).  The rows where the rule does not fire take the DEFAULT."""
    ctl = _quiet_compile(load(DIV0_FLL, format="fll"), "python")
    xs = np.linspace(0.0, 1.0, 40)
    tracemalloc.start()
    try:
        got = ctl.evaluate_batch({"obstacle": xs})["y"]  # type: ignore[attr-defined]
        _cur, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 40e6, peak
    fires = (xs > 0.0) & (xs < 0.6)
    assert np.isnan(got[fires]).all()
    assert (got[~fires] == 0.25).all()
    ref = _quiet_compile(load(DIV0_FLL, format="fll"), "interpreted")
    for x, g in zip(xs, got, strict=True):
        r = ref.evaluate({"obstacle": float(x)})["y"]  # type: ignore[attr-defined]
        assert (math.isnan(r) and math.isnan(g)) or r == g, (float(x), r, float(g))


def test_explain_and_eval_say_no_rule_fired_only_when_none_fired(
    tmp_path: object, capsys: pytest.CaptureFixture[str]
) -> None:
    ctl = _quiet_compile(load(DIV0_FLL, format="fll"), "python")
    e = ctl.explain({"obstacle": 0.3})  # type: ignore[attr-defined]
    assert e.outputs[0].fired and math.isnan(e.outputs[0].value)
    e = ctl.explain({"obstacle": 0.9})  # type: ignore[attr-defined]
    assert not e.outputs[0].fired and e.outputs[0].value == 0.25
    from pathlib import Path

    path = Path(str(tmp_path)) / "div0.fll"
    path.write_text(DIV0_FLL.replace("default: 0.25", "default: nan"))
    assert main(["eval", str(path), "-s", "obstacle=0.3"]) == 1
    err = capsys.readouterr().err
    assert "rules fired" in err and "no rule fired" not in err
    assert main(["eval", str(path), "-s", "obstacle=0.9"]) == 1
    assert "no rule fired" in capsys.readouterr().err
    assert main(["explain", str(path), "-s", "obstacle=0.3"]) == 0
    out = capsys.readouterr().out
    assert "no rule fired" not in out and "rules fired" in out


def test_largest_of_maximum_of_a_function_term_is_proportionate(monkeypatch: pytest.MonkeyPatch) -> None:
    """LoM of a clipped Function triangle: the right end of the plateau, in closed form, with
    a bounded number of evaluations of the term (a golden-section search from every plateau
    node made it 0.5 s an evaluation)."""
    from fuzzyctl.engine.reference import interp
    from fuzzyctl.engine.semantics import expr

    calls = 0
    real = expr.eval_expr_np

    def counting(*args: object, **kw: object) -> object:
        nonlocal calls
        calls += 1
        return real(*args, **kw)  # type: ignore[arg-type]

    monkeypatch.setattr(interp, "eval_expr_np", counting)
    doc = _fll(F_LEFT, F_RIGHT, defuzzifier="LargestOfMaximum 100")
    for backend in ("python", "interpreted"):
        ctl = _quiet_compile(doc, backend)
        for x in (0.1, 0.2):  # only rule 1 fires: right clipped at a = x / 0.3
            calls = 0
            a = x / 0.3
            got = ctl.evaluate({"obstacle": x})["steer"]  # type: ignore[attr-defined]
            assert got == pytest.approx(0.9 - 0.2 * a, abs=1e-12), (backend, x)
            assert calls < 400, (backend, calls)


PSIG_FLL = """\
Engine: psig
InputVariable: obstacle
  range: 0.000 1.000
  term: left Triangle 0.000 0.300 0.600
  term: right Triangle 0.400 0.700 1.000
OutputVariable: steer
  range: 0.000 1.000
  aggregation: Maximum
  defuzzifier: Centroid
  default: nan
  term: left SigmoidProduct 0.150 25.000 -25.000 0.450
  term: right SigmoidProduct 0.520 40.000 -20.000 0.860
RuleBlock: rb
  conjunction: none
  disjunction: none
  implication: Minimum
  activation: General
  rule: if obstacle is left then steer is right
  rule: if obstacle is right then steer is left
"""


def _psig(u: np.ndarray, c1: float, s1: float, c2: float, s2: float) -> np.ndarray:
    return 1.0 / (1.0 + np.exp(-s1 * (u - c1))) / (1.0 + np.exp(-s2 * (u - c2)))


def _dense_cog(sets: list[tuple[float, tuple[float, float, float, float]]]) -> float:
    """max_k min(a_k, psig_k) on [0, 1]: its kinks located by bisection on a fine grid, each
    smooth piece integrated by 20-point Gauss-Legendre on 2,000 subintervals."""

    def f(u: np.ndarray) -> np.ndarray:
        return np.max([np.minimum(a, _psig(u, *p)) for a, p in sets], axis=0)

    def code(u: np.ndarray) -> np.ndarray:
        c = np.array([np.minimum(a, _psig(u, *p)) for a, p in sets])
        under = np.array([_psig(u, *p) < a for a, p in sets])
        return np.argmax(c, axis=0) * 2 ** len(sets) + (under * (2 ** np.arange(len(sets)))[:, None]).sum(
            axis=0
        )

    grid = np.linspace(0.0, 1.0, 100001)
    cg = code(grid)
    cuts = [0.0, 1.0]
    for i in np.flatnonzero(cg[1:] != cg[:-1]):
        lo, hi = grid[i], grid[i + 1]
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            if code(np.array([mid]))[0] == cg[i]:
                lo = mid
            else:
                hi = mid
        cuts.append(hi)
    nodes, weights = np.polynomial.legendre.leggauss(20)
    area = moment = 0.0
    for p0, p1 in zip(sorted(cuts)[:-1], sorted(cuts)[1:], strict=True):
        e = np.linspace(p0, p1, 2001)
        half, mid = 0.5 * (e[1:] - e[:-1]), 0.5 * (e[1:] + e[:-1])
        u = mid[:, None] + half[:, None] * nodes[None, :]
        y = f(u.ravel()).reshape(u.shape)
        area += float(np.sum((y @ weights) * half))
        moment += float(np.sum(((y * u) @ weights) * half))
    return moment / area


def test_clipped_sigmoid_products_match_a_dense_reference_on_every_path() -> None:
    """Two SigmoidProduct sets clipped by MIN under MAX (sigmoid_product.fll's kind: the
    interpreter was 6.7e-8 of the range off there): every path within 1e-9 of a dense
    reference that locates the kinks itself."""
    doc = load(PSIG_FLL, format="fll")
    ctls = {b: _quiet_compile(doc, b) for b in ("python", "interpreted")}
    # fuzzylite order: left, rising, falling, right -> sig(left, rising) * sig(right, falling)
    left, right = (0.15, 25.0, 0.45, -25.0), (0.52, 40.0, 0.86, -20.0)
    for x in (0.05, 0.23, 0.37, 0.45, 0.55, 0.66, 0.93):
        a_left = max(0.0, min(x / 0.3, (0.6 - x) / 0.3))  # obstacle left -> steer right
        a_right = max(0.0, min((x - 0.4) / 0.3, (1.0 - x) / 0.3))
        sets = [(a, p) for a, p in ((a_left, right), (a_right, left)) if a > 0.0]
        want = _dense_cog(sets)
        for backend, ctl in ctls.items():
            got = ctl.evaluate({"obstacle": x})["steer"]  # type: ignore[attr-defined]
            batch = ctl.evaluate_batch({"obstacle": np.array([x])})["steer"][0]  # type: ignore[attr-defined]
            assert abs(got - want) <= 1e-9 and abs(batch - want) <= 1e-9, (
                backend,
                x,
                got,
                float(batch),
                want,
            )


def test_coa_of_a_zero_gap_between_smooth_sets_is_its_middle() -> None:
    """Cosine sets (compact support [1, 3] and [7, 9]) of equal degree: the quadrature's CoA
    answers the middle of the gap [3, 7] on every path (within 1e-9 of the range: in floating
    point the cosine is exactly 0 from 3 - 3.4e-9 on, so the computed gap starts there)."""
    text = FUNCTION_FLL.format(
        left="Cosine 2.000 2.000", right="Cosine 8.000 2.000", aggregation="Maximum", defuzzifier="Bisector"
    ).replace("range: 0.000 1.000\n  aggregation", "range: 0.000 10.000\n  aggregation")
    text = text.replace(
        "  term: left Triangle 0.000 0.300 0.600\n  term: right Triangle 0.400 0.700 1.000",
        "  term: left Ramp 0.000 1.000\n  term: right Ramp 0.000 1.000",
    )
    doc = load(text, format="fll")
    for backend in ("python", "interpreted"):
        ctl = _quiet_compile(doc, backend)
        for x in (0.3, 0.7, 0.123, 1.0):
            got = ctl.evaluate({"obstacle": x})["steer"]  # type: ignore[attr-defined]
            assert abs(got - 5.0) <= 1e-8, (backend, x, got)
        batch = ctl.evaluate_batch({"obstacle": np.array([0.3, 0.7])})["steer"]  # type: ignore[attr-defined]
        assert (abs(batch - 5.0) <= 1e-8).all(), (backend, batch)


def test_mom_takes_a_rounded_crossing_next_to_a_vertex_for_that_vertex() -> None:
    """Two maxima, at 1 and 2 (a triangle falling from 1 and one rising to 2 at the same
    degree): MoM = 1.5.  A crossing computed 1.3e-15 left of 2 (rounding in the degrees)
    reaches the height too; it is neither a plateau (MoM 2.0) nor a third point (1.67): it
    is the vertex (valeriot90's mamdani.fis: 1.5 on one path, 2.0 on the other)."""
    from fuzzyctl.engine.reference import pwl

    h = 1.1466298317900281e-23
    x_near = 1.9999999999999987
    pieces = [
        (0.0, 1.0, 0.0, h, None),
        (1.0, 1.5, h, 0.5 * h, None),
        (1.5, x_near, 0.5 * h, h * (1 - 1.2e-15), None),
        (x_near, 2.0, h * (1 - 1.2e-15), h, None),
        (2.0, 5.0, 2.7e-77, 0.0, None),
    ]
    points = [(0.0, 0.0), (1.0, h), (2.0, h), (3.0, 0.0), (5.0, 0.0)]
    _sup, lm, rm, mom = pwl.maxima(pieces, points)
    assert (lm, rm) == (1.0, 2.0)
    assert abs(mom - 1.5) <= 1e-9 * 5.0, mom
    assert pwl.distinct_points([1.0, x_near, 2.0], 1e-12 * 5.0) == [1.0, x_near]
