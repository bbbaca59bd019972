"""One validation for every reader (issue 25, point 4): the rules of IEC 61131-7 5.2.2 and
5.2.4 that FCL enforces hold for models from JSON, FIS, FLL, FPL and XFUZ the same way, each
refusal at the reader's own place (file:line:column, or a JSON path), and ``convert`` never
writes a file that ``check`` refuses."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import fuzzyctl
from fuzzyctl import formats
from fuzzyctl import model as m
from fuzzyctl.cli import main
from fuzzyctl.diagnostics import Diagnostic, DiagnosticError
from fuzzyctl.engine.support import unsupported
from fuzzyctl.fcl import load_text
from fuzzyctl.formats import LossError
from fuzzyctl.validation import validate

READERS = ("fcl", "json", "fis", "fll", "fpl")


def _points(*xy: tuple[float, float]) -> m.PointsMF:
    return m.PointsMF(tuple(m.Point(float(x), float(y)) for x, y in xy))


def _model(
    odd: m.PointsMF | None = None, weight: float | None = None, input_range: m.Range | None = None
) -> m.Document:
    """Two inputs terms (``odd`` is no standard shape, so every writer writes it as points),
    two output terms, ACT PROD (a WITH weight is then also a FIS/FLL rule weight, losslessly)."""
    odd = odd or _points((0, 0), (3.25, 0.375), (6, 1), (10, 0))
    fz = m.FuzzifyBlock(
        "x",
        (m.Term("lo", _points((0, 1), (10, 0))), m.Term("odd", odd)),
        range=input_range or m.Range(0.0, 10.0),
    )
    dz = m.DefuzzifyBlock(
        "y",
        (m.Term("a", _points((0, 0), (5, 1), (10, 0))), m.Term("b", _points((5, 0), (10, 1), (15, 0)))),
        range=m.Range(0.0, 15.0),
        method="COG",
        default=m.Default(0.0),
    )
    rules = (
        m.Rule("1", m.Is("x", "lo"), (m.Conclusion("y", "a"),)),
        m.Rule("2", m.Is("x", "odd"), (m.Conclusion("y", "b", weight),)),
    )
    rb = m.RuleBlock("r", rules, and_op="MIN", act="PROD", accu="MAX")
    variables = (m.Variable("x", m.VarKind.INPUT), m.Variable("y", m.VarKind.OUTPUT))
    return m.Document((m.FunctionBlock("f", variables, (fz,), (dz,), (rb,)),))


def _text(fmt: str, document: m.Document) -> str:
    text, losses = formats.convert(document, fmt, lossy=fmt == "fpl")  # FPL: MAX and DEFAULT
    assert fmt == "fpl" or not losses
    return text


def _replace_once(text: str, old: str, new: str) -> tuple[str, int]:
    """``text`` with the one literal ``old`` made ``new``, and the line it is on."""
    assert text.count(old) == 1, (old, text)
    at = text.index(old)
    return text.replace(old, new), text.count("\n", 0, at) + 1


def _first_error(exc: DiagnosticError) -> Diagnostic:
    return next(d for d in exc.diagnostics if d.is_error)


# --------------------------------------------------------------------------- each rule, each reader


@pytest.mark.parametrize("fmt", READERS)
@pytest.mark.parametrize(
    ("old", "new", "code", "json_path"),
    [
        ("0.375", "1.375", "degree-out-of-range", "$.blocks[0].fuzzify[0].terms[1].mf.points[1].y"),
        ("3.25", "7.25", "points-not-ascending", "$.blocks[0].fuzzify[0].terms[1].mf.points[2].x"),
    ],
    ids=["degree", "ascending"],
)
def test_every_reader_refuses_a_term_that_breaks_5_2_2_at_its_place(
    fmt: str, old: str, new: str, code: str, json_path: str
) -> None:
    text, line = _replace_once(_text(fmt, _model()), old, new)
    with pytest.raises(DiagnosticError) as caught:
        formats.read_text(text, fmt, path=f"model.{fmt}")
    first = _first_error(caught.value)
    if fmt == "json":  # the spans a JSON model holds are not positions in the JSON
        assert first.code == code and first.message.startswith(json_path + ": "), first.render()
        return
    if fmt != "fpl":  # the FPL parser refuses both itself, with its own words
        assert first.code == code, first.render()
    assert first.span is not None and first.span.line == line, first.render()
    assert first.render().startswith(f"model.{fmt}:{line}:")


def test_a_term_of_one_point_is_refused_in_fcl_and_json_singletons_still_load() -> None:
    one = _model(_points((5, 1)))
    assert [f.code for f in validate(one)] == ["too-few-points"]
    fcl = "TERM odd := (5, 1);"
    text, line = _replace_once(
        _text("fcl", _model()), "TERM odd := (0, 0) (3.25, 0.375) (6, 1) (10, 0);", fcl
    )
    with pytest.raises(DiagnosticError) as caught:
        formats.read_text(text, "fcl")
    first = _first_error(caught.value)
    assert first.code == "too-few-points" and first.span is not None and first.span.line == line
    with pytest.raises(DiagnosticError) as caught:
        formats.read_text(_text("json", one), "json")
    assert _first_error(caught.value).message.startswith("$.blocks[0].fuzzify[0].terms[1].mf.points[0]: ")
    # a singleton (5.2.3) is one value, not a list of one point: every form of it loads
    singletons = (
        _text("fcl", _model())
        .replace("TERM a := (0, 0) (5, 1) (10, 0);", "TERM a := 5;")
        .replace("TERM b := (5, 0) (10, 1) (15, 0);", "TERM b := SINGLETONS (10, 1);")
        .replace("COG;", "COGS;")
    )
    document = formats.read_text(singletons, "fcl").document
    assert not [f for f in validate(document) if f.severity.name == "ERROR"]
    assert fuzzyctl.compile(document).evaluate({"x": 0.0})["y"] == pytest.approx(5.0)


def test_the_jfuzzylogic_profile_reads_a_term_of_one_point_with_a_warning() -> None:
    """jFuzzyLogic runs a one-point list (a constant degree): under its profile the term is a
    warning, elsewhere the error of 5.2.2; the CLI's --compat reads the file the same way."""
    text, _line = _replace_once(
        _text("fcl", _model()), "TERM odd := (0, 0) (3.25, 0.375) (6, 1) (10, 0);", "TERM odd := (5, 1);"
    )
    with pytest.raises(DiagnosticError):
        fuzzyctl.load(text)
    document = fuzzyctl.load(text, compat="jfuzzylogic")
    found = validate(document, compat="jfuzzylogic")
    assert [(f.code, f.severity.name) for f in found] == [("too-few-points", "WARNING")]
    assert [f.severity.name for f in validate(document)] == ["ERROR"]


@pytest.mark.parametrize("fmt", ["fis", "fll"])
def test_a_discrete_term_of_one_pair_is_the_constant_fuzzylite_reads(fmt: str) -> None:
    """fuzzylite's Discrete (and MATLAB's discretemf) of one pair is that degree everywhere:
    read as two equal points, it converts to an FCL that ``check`` accepts."""
    text = _text(fmt, _model())
    text = text.replace("0 0 3.25 0.375 6 1 10 0", "5 0.5")
    document = formats.read_text(text, fmt).document
    odd = document.main.fuzzify_block("x").term("odd")  # type: ignore[union-attr]
    assert odd is not None and odd.mf == _points((5, 0.5), (5, 0.5))
    fcl, _losses = formats.convert(document, "fcl")
    assert load_text(fcl).ok


@pytest.mark.parametrize("fmt", ["fcl", "json", "fis", "fll"])
def test_a_weight_above_1_is_a_warning_and_an_error_under_strict_in_every_format(fmt: str) -> None:
    text, line = _replace_once(_text(fmt, _model(weight=0.75)), "0.75", "1.75")
    loaded = formats.read_text(text, fmt, path=f"model.{fmt}")
    assert [d.code for d in loaded.diagnostics if d.code == "weight-out-of-range"] == ["weight-out-of-range"]
    with pytest.raises(DiagnosticError) as caught:
        fuzzyctl.compile(loaded.document, strict=True)
    first = _first_error(caught.value)
    assert first.code == "weight-out-of-range" and "1.75" in first.message
    if fmt == "json":
        assert first.message.startswith("$.blocks[0].rule_blocks[0].rules[1].")
    else:
        assert first.span is not None and first.span.line == line, first.render()


def test_fcl_check_strict_refuses_with_1_5() -> None:
    text = _text("fcl", _model(weight=0.75)).replace("WITH 0.75", "WITH 1.5")
    assert load_text(text).ok
    strict = load_text(text, strict=True)
    assert not strict.ok
    assert [d.code for d in strict.diagnostics if d.is_error] == ["weight-out-of-range"]


@pytest.mark.parametrize("fmt", ["json", "fll"])
def test_a_range_upside_down_is_refused_by_every_reader(fmt: str) -> None:
    text = _text(fmt, _model())
    if fmt == "json":
        data = json.loads(text)
        data["blocks"][0]["fuzzify"][0]["range"] = {"low": 10.0, "high": 0.0}
        text = json.dumps(data)
    else:
        text, _line = _replace_once(text, "range: 0 10\n", "range: 10 0\n")
    with pytest.raises(DiagnosticError) as caught:
        formats.read_text(text, fmt)
    first = _first_error(caught.value)  # FLL's reader says it first, in its own words
    assert (
        first.code in {"bad-range", "fll-value"} and "minimum" in first.message and "above" in first.message
    )


# --------------------------------------------------------------------------- random models

coordinates = st.floats(0.0, 10.0, allow_nan=False).map(lambda v: round(v, 3))
degrees = st.floats(0.0, 1.0, allow_nan=False).map(lambda v: round(v, 3))


@st.composite
def valid_terms(draw: st.DrawFn) -> m.PointsMF:
    xs = sorted(draw(st.lists(coordinates, min_size=2, max_size=5)))
    ys = draw(st.lists(degrees, min_size=len(xs), max_size=len(xs)))
    return _points(*zip(xs, ys, strict=True))


@st.composite
def valid_models(draw: st.DrawFn) -> m.Document:
    return _model(draw(valid_terms()), draw(st.none() | degrees))


def _fcl_check_errors(text: str) -> list[Diagnostic]:
    """What ``fuzzyctl check`` reports as errors (the language checks, then the engine's)."""
    result = load_text(text)
    found = [d for d in result.diagnostics if d.is_error]
    if result.ok and result.document is not None:
        found += [d for fb in result.document.blocks for d in unsupported(fb) if d.is_error]
    return found


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(valid_models())
def test_a_valid_model_written_in_every_format_reads_back_and_converts_to_an_fcl_check_accepts(
    document: m.Document,
) -> None:
    assert not [f for f in validate(document) if f.severity.name == "ERROR"]
    for fmt in ("fcl", "json", "fis", "fll", "fpl", "xfuz"):
        text, _losses = formats.convert(document, fmt, lossy=True)
        again = formats.read_text(text, fmt).document  # no error
        fcl, _losses = formats.convert(again, "fcl", lossy=True)
        assert not _fcl_check_errors(fcl), (fmt, fcl)


@st.composite
def invalid_models(draw: st.DrawFn) -> tuple[m.Document, str]:
    term = draw(valid_terms())
    points = list(term.points)
    kind = draw(st.sampled_from(["degree", "ascending"]))
    i = draw(st.integers(0, len(points) - 1))
    if kind == "degree":
        bad = draw(st.floats(1.001, 5.0) | st.floats(-5.0, -0.001)).__round__(3)
        points[i] = m.Point(points[i].x, bad)
        code = "degree-out-of-range"
    else:
        xs = sorted({float(p.x) for p in points})  # type: ignore[arg-type]
        if len(xs) < 2:
            points = [m.Point(1.0, 0.0), m.Point(2.0, 1.0)]
        j = max(1, i)
        points[j - 1], points[j] = points[j], points[j - 1]
        if not float(points[j].x) < float(points[j - 1].x):  # type: ignore[arg-type]
            points[j - 1], points[j] = m.Point(9.0, 0.0), m.Point(1.0, 1.0)
        code = "points-not-ascending"
    return _model(m.PointsMF(tuple(points))), code


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(invalid_models())
def test_an_invalid_model_is_refused_the_same_way_by_every_reader(case: tuple[m.Document, str]) -> None:
    document, code = case
    assert code in {f.code for f in validate(document)}
    refused = []
    for fmt in ("fcl", "json", "fis", "fll"):
        try:
            text, _losses = formats.convert(document, fmt)
        except LossError:
            continue  # the writer does not write it (FIS: discretemf descending): never refused later
        with pytest.raises(DiagnosticError) as caught:
            formats.read_text(text, fmt)
        assert _first_error(caught.value).code == code, (fmt, text)
        refused.append(fmt)
    assert {"fcl", "json"} <= set(refused)


@pytest.mark.parametrize("fmt", ["fcl", "json", "fll", "fis"])
@pytest.mark.parametrize(
    "command", [["check"], ["eval", "-s", "x=5"], ["codegen"], ["codegen", "--lang", "c"]], ids=str
)
def test_the_cli_strict_refuses_a_weight_above_1_in_every_format(
    tmp_path: Path, fmt: str, command: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    """``--strict`` accepted WITH 1.5 (issue 25); now every command refuses it whatever the
    format, and without ``--strict`` the same file runs (with a warning)."""
    if command == ["check"] and fmt != "fcl":
        return  # check reads FCL only
    text, _line = _replace_once(_text(fmt, _model(weight=0.75)), "0.75", "1.75")
    source = tmp_path / f"model.{fmt}"
    source.write_text(text)
    args = [command[0], str(source), *command[1:]]
    if "c" in command:
        args += ["-o", str(tmp_path)]
    assert main(args) == 0, capsys.readouterr().err
    capsys.readouterr()
    assert main([*args, "--strict"]) == 1
    err = capsys.readouterr().err
    assert "weight 1.75 is above 1" in err and "internal error" not in err
