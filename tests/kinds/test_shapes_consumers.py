"""Each shape of the registry walked through every consumer: the FCL, FIS, FLL and JSON
writers and readers (a round trip where the format can say the shape, a clear refusal where
its entry says it cannot), the engine on every backend against the reference interpreter, the
Structured Text / C / PLCopen generators, the studio's catalogue (the default placement gives
a shape the engine reads) and the tuner's space.

The systems are built from the entry itself (its probe parameters), so a new entry is
walked with no change here."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

import fuzzyctl
from fuzzyctl import formats
from fuzzyctl.codegen import CodegenError, generate_c, generate_plcopen, generate_st
from fuzzyctl.engine.semantics.shapes import membership
from fuzzyctl.fcl.writer import mf_text
from fuzzyctl.kinds.shapes import ENTRIES, NA, Shape, Written
from fuzzyctl.model import Document, FunctionBlock, ShapeMF
from fuzzyctl.studio import create_app
from fuzzyctl.tune.space import build_space
from tests.conftest import EXAMPLES

XS = np.linspace(0.0, 10.0, 41)
Y_RANGE = 40.0  # the output's RANGE -20..20


def _text(kind: str, params: tuple[float, ...]) -> str:
    return mf_text(ShapeMF(kind, tuple(float(p) for p in params)))


def system(shape: Shape) -> str:
    """A two-rule block with the shape on the input x (an output for Takagi-Sugeno kinds) and,
    for fuzzy sets, on the output too; a second input hw (jFuzzyLogic's variable-width COSINE
    reads its half width there; the probes' linear output has two coefficients and a
    constant)."""
    out_terms, method = "", "METHOD : COG;"
    if isinstance(shape.probe, NA):  # a parameter given by a variable (cosine_half)
        x_term = f"{shape.spellings.fcl[0].name} hw 5"  # type: ignore[index]
        out_terms = "TERM s := (-10, 0) (0, 1) (10, 0);"
    elif shape.takagi_sugeno:
        x_term = "(0, 1) (10, 0)"
        out_terms = f"TERM s := {_text(shape.kind, shape.probe)};"
        method = "METHOD : WTAVER;"
    else:
        x_term = _text(shape.kind, shape.probe)
        out = shape.output_probe()
        assert isinstance(out, tuple)
        out_terms = f"TERM s := {_text(shape.kind, out)};"
    t_out = _text("constant", (10.0,)) if shape.takagi_sugeno else "(12, 0) (16, 1) (20, 0)"
    return f"""FUNCTION_BLOCK walk
VAR_INPUT
    x : REAL;
    hw : REAL;
END_VAR
VAR_OUTPUT
    y : REAL;
END_VAR
FUZZIFY x
    RANGE := (0 .. 10);
    TERM s := {x_term};
    TERM t := (0, 0) (10, 1);
END_FUZZIFY
FUZZIFY hw
    TERM t := (0, 0) (10, 1);
END_FUZZIFY
DEFUZZIFY y
    RANGE := (-20 .. 20);
    {out_terms}
    TERM t := {t_out};
    {method}
    DEFAULT := 0;
END_DEFUZZIFY
RULEBLOCK r
    AND : MIN;
    ACT : MIN;
    ACCU : MAX;
    RULE 1 : IF x IS s THEN y IS s;
    RULE 2 : IF x IS t OR hw IS t THEN y IS t;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def _doc(shape: Shape) -> Document:
    return fuzzyctl.load(system(shape))


def _rows(fb: FunctionBlock) -> list[dict[str, float]]:
    names = [v.name for v in fb.inputs]
    return [{n: (float(x) if n == "x" else 3.0) for n in names} for x in XS]


def _shape_terms(fb: FunctionBlock) -> list[ShapeMF]:
    out = []
    for blk in [*fb.fuzzify, *fb.defuzzify]:
        out += [t.mf for t in blk.terms if isinstance(t.mf, ShapeMF)]
    return out


IDS = [s.kind for s in ENTRIES]


def _term(fb: FunctionBlock, var: str) -> Any:
    blk = fb.fuzzify_block(var) or fb.defuzzify_block(var)
    assert blk is not None
    return next(t.mf for t in blk.terms if t.name == "s")


def _outputs(doc: Document) -> np.ndarray:
    ctl = fuzzyctl.compile(doc, backend="interpreted")
    return np.array([ctl.evaluate_reference(r)["y"] for r in _rows(doc.main)])


@pytest.mark.parametrize("shape", ENTRIES, ids=IDS)
def test_shape_walks_through_the_formats(shape: Shape) -> None:
    doc = _doc(shape)
    fb = doc.main
    assert shape.kind in {mf.kind for mf in _shape_terms(fb)}, "the FCL reader gives the entry's kind"
    want = _outputs(doc)
    for fmt in ("fcl", "json", "fis", "fll"):
        spelled = fmt in ("fcl", "json") or isinstance(getattr(shape.spellings, fmt), Written)
        try:
            text, _losses = formats.convert(doc, fmt)
        except formats.LossError as exc:
            # a refusal names the term and is what the entry says (no spelling, or a
            # parameter given by a variable the format cannot hold)
            assert not spelled or isinstance(shape.probe, NA), (fmt, str(exc))
            assert "s" in str(exc), str(exc)
            continue
        back = formats.read_text(text, fmt).document
        # the same system: every parameter in its place
        np.testing.assert_allclose(_outputs(back), want, atol=1e-9 * Y_RANGE, rtol=0, err_msg=fmt)
        for var in ("x", "y"):
            before, after = _term(fb, var), _term(back.main, var)
            if not (isinstance(before, ShapeMF) and before.kind == shape.kind):
                continue
            if isinstance(after, ShapeMF):
                assert after.kind == shape.kind, (fmt, after)
                assert len(after.params) == len(before.params)
                for p, q in zip(after.params, before.params, strict=True):
                    assert p == q or p == pytest.approx(q), (fmt, after, before)
            else:  # written in the format's own form: IEC points of a piecewise-linear shape
                assert shape.piecewise_linear or not spelled, (fmt, after)


def _backends() -> list[str]:
    from fuzzyctl.engine import native

    # without a C compiler the native backend is not there to test
    return ["interpreted", "python"] + (["native"] if native.compiler() else [])


@pytest.mark.parametrize("shape", ENTRIES, ids=IDS)
def test_shape_on_every_backend_agrees_with_the_reference(shape: Shape) -> None:
    doc = _doc(shape)
    rows = _rows(doc.main)
    ref = fuzzyctl.compile(doc, backend="interpreted")
    want = np.array([ref.evaluate_reference(r)["y"] for r in rows])
    assert np.isfinite(want).all()
    for backend in _backends():
        ctl = fuzzyctl.compile(doc, backend=backend)
        single = np.array([ctl.evaluate(r)["y"] for r in rows])
        np.testing.assert_allclose(single, want, atol=1e-9 * Y_RANGE, rtol=0, err_msg=backend)
        batch = ctl.evaluate_batch({k: np.array([r[k] for r in rows]) for k in rows[0]})["y"]
        np.testing.assert_allclose(batch, want, atol=1e-9 * Y_RANGE, rtol=0, err_msg=f"{backend} batch")


@pytest.mark.parametrize("shape", ENTRIES, ids=IDS)
def test_shape_generates_st_c_and_plcopen_or_says_why(shape: Shape) -> None:
    doc = _doc(shape)
    for generate in (generate_st, generate_c, generate_plcopen):
        try:
            out: Any = generate(doc)
        except CodegenError as exc:
            assert "walk" in str(exc) or "term" in str(exc) or "y" in str(exc), str(exc)
            continue
        text = "\n".join(out.values()) if isinstance(out, dict) else out
        assert "walk" in text.lower()


@pytest.fixture(scope="module")
def catalogue() -> dict[str, Any]:
    client = TestClient(create_app(EXAMPLES, token=None), base_url="http://127.0.0.1:8770")
    data: dict[str, Any] = client.get("/api/shapes").json()
    return data


def _evaluate(tree: Any, env: dict[str, float]) -> float:
    """The placement trees as the studio's terms.js evaluates them."""
    if isinstance(tree, int | float):
        return float(tree)
    if isinstance(tree, str):
        return env[tree]
    op, left, *right = tree
    if op == "neg":
        return -_evaluate(left, env)
    a, b = _evaluate(left, env), _evaluate(right[0], env)
    return {"+": a + b, "-": a - b, "*": a * b, "/": a / b}[op]


@pytest.mark.parametrize("shape", ENTRIES, ids=IDS)
def test_studio_places_a_shape_the_engine_reads(shape: Shape, catalogue: dict[str, Any]) -> None:
    view = catalogue[shape.kind]
    assert view["params"] == list(shape.params) and view["roles"] == list(shape.roles)
    a, b, c = 2.0, 8.0, 5.0
    env = {"a": a, "b": b, "c": c, "w": b - a}
    params = [0.0, 0.0] if shape.variadic else [_evaluate(t, env) for t in view["placement"]]
    for h in view["handles"]:
        assert 0 <= h["at"] < len(shape.params)
    mf = ShapeMF(shape.kind, tuple(params))
    fb = _doc(shape).main
    blk = fb.defuzzify[0] if shape.takagi_sugeno else fb.fuzzify[0]
    term = next(t for t in blk.terms if t.name == "s")
    placed_blk = dataclasses.replace(
        blk, terms=tuple(dataclasses.replace(t, mf=mf) if t is term else t for t in blk.terms)
    )
    placed = dataclasses.replace(
        fb,
        fuzzify=tuple(placed_blk if x is blk else x for x in fb.fuzzify),
        defuzzify=tuple(placed_blk if x is blk else x for x in fb.defuzzify),
    )
    fuzzyctl.compile(placed, backend="interpreted")  # no diagnostic: a valid shape
    if not shape.takagi_sugeno:
        # placed on the support [a, b]: it reaches half its height there
        mu = [membership(shape.kind, params, 1.0, x) for x in np.linspace(a, b, 241)]
        assert max(mu) >= 0.5, (params, max(mu))


@pytest.mark.parametrize("shape", ENTRIES, ids=IDS)
def test_tune_finds_parameters_in_every_shape(shape: Shape) -> None:
    """`tune --free VARIABLE.TERM` on a term of each shape frees its parameters (the five
    shapes once missing from the tuner - concave, binary, arc, semiellipse, cosine_half -
    included; cosine_half's centre is written as a number, its half width a variable)."""
    doc = _doc(shape)
    fb = doc.main
    var = "y" if shape.takagi_sugeno else "x"
    space = build_space(fb, f"{var}.s")
    assert space.size > 0, space.notes
    assert not any("nothing to tune" in n for n in space.notes), space.notes
    # the decoded system at the start is the written one and compiles
    decoded = space.decode(space.initial())
    fuzzyctl.compile(decoded, backend="interpreted")
    if not isinstance(shape.probe, NA):
        freed = {k[3] for k in space.free_keys if k[0] == "term" and k[1] == var}
        tunable = {i for i, r in enumerate(shape.tuning) if r != "abscissa"} | {
            i
            for i, r in enumerate(shape.tuning)
            if r == "abscissa" and 0.0 < float(shape.probe[i] if var == "x" else 0.5) < 10.0
        }
        assert freed, shape.kind
        assert freed <= set(range(max(len(shape.probe), 1))) and freed & tunable, (freed, tunable)


def test_every_format_reader_is_walked() -> None:
    """The round trip covers every format that reads and writes shapes by name."""
    names = {f.name for f in formats.available()}
    assert {"fcl", "fis", "fll", "json"} <= names
    assert math.isfinite(Y_RANGE)
