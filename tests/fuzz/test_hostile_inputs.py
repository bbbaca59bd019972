"""The crashes the outside fuzzer found (issue 14, points 5 and 6), one test each: every one
is now a diagnostic with its place (file:line:column, or the parameter), and on extreme but
finite inputs every backend gives the same IEEE value instead of raising."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.cli.app import main
from fuzzyctl.diagnostics import DiagnosticError, FuzzyctlError
from fuzzyctl.limits import MAX_NESTING

FCL = """FUNCTION_BLOCK f
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x
  RANGE := ({low} .. 10);
  TERM lo := (0, 1) (10, 0);
  TERM hi := (0, 0) (10, 1);
END_FUZZIFY
DEFUZZIFY y
  TERM a := (0, 0) (2, 1) (4, 0);
  TERM b := (6, 0) (8, 1) (10, 0);
  METHOD : COG;
  DEFAULT := {default};
END_DEFUZZIFY
RULEBLOCK r
  AND : MIN;
  RULE 1 : IF {cond} THEN y IS a;
  RULE 2 : IF x IS hi THEN y IS b;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""

FIS = """[System]
Name='f'
Type='mamdani'
NumInputs=1
NumOutputs=1
NumRules={nrules}
AndMethod='min'
OrMethod='max'
ImpMethod='min'
AggMethod='max'
DefuzzMethod='centroid'

[Input1]
Name='x'
Range=[0 10]
NumMFs=2
MF1='lo':'{kind}',{params}
MF2='hi':'trimf',[0 10 10]

[Output1]
Name='y'
Range=[0 10]
NumMFs=2
MF1='a':'trimf',[0 2 4]
MF2='b':'trimf',[6 8 10]

[Rules]
{rule}
2, 2 (1) : 1
"""


def fcl(cond: str = "x IS lo", low: str = "0", default: str = "0") -> str:
    return FCL.format(cond=cond, low=low, default=default)


def fis(nrules: str = "2", kind: str = "trimf", params: str = "[0 0 10]", rule: str = "1, 1 (1) : 1") -> str:
    return FIS.format(nrules=nrules, kind=kind, params=params, rule=rule)


# (name, text, format, expected line, words the message must hold)
REFUSED = [
    ("NOT x 491", fcl("NOT " * 491 + "x IS lo"), "fcl", 17, ["nests", str(MAX_NESTING)]),
    ("2000 nested OR/AND", fcl("(x IS lo OR " * 2000 + "x IS lo" + ")" * 2000), "fcl", 17, ["nests"]),
    ("5001-digit number in FCL", fcl(low="9" * 5001), "fcl", 5, ["too large", "5001 characters"]),
    ("RANGE := (nan .. 10)", fcl(low="nan"), "fcl", 5, ["RANGE", "not a number"]),
    ("1000-deep parentheses in FIS parameters", fis(params="[" + "(" * 1000 + "0" + ")" * 1000 + " 0 10]"),
     "fis", 17, ["nests"]),
    ("NumRules=Infinity", fis(nrules="Infinity"), "fis", 6, ["NumRules", "whole number"]),
    ("inf in a FIS rule", fis(rule="inf, 1 (1) : 1"), "fis", 28, ["not a term number"]),
    ("nan in a FIS rule", fis(rule="nan, 1 (1) : 1"), "fis", 28, ["not a term number"]),
    ("5001-digit number in FIS", fis(params="[0 " + "9" * 5001 + " 10]"), "fis", 17, ["too large"]),
    ("100,000-deep JSON", "[" * 100_000 + "]" * 100_000, "json", 1, ["nests"]),
    ("5001-digit JSON integer", '{"a": ' + "9" * 5001 + "}", "json", 1, ["too large", "5001 characters"]),
]  # fmt: skip


@pytest.mark.parametrize(
    ("text", "fmt", "line", "words"), [r[1:] for r in REFUSED], ids=[r[0] for r in REFUSED]
)
def test_each_found_crash_is_now_a_diagnostic_with_its_place(
    text: str, fmt: str, line: int | None, words: list[str]
) -> None:
    with pytest.raises(DiagnosticError) as info:
        fuzzyctl.load(text, format=fmt)
    d = info.value.diagnostics[0]
    for word in words:
        assert word in d.message, d.message
    assert len(d.message) < 300  # the offending text is shortened, never echoed whole
    if line is not None:
        assert d.span is not None and d.span.line == line


def test_the_cli_names_file_line_and_column(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "deep.fcl"
    path.write_text(fcl("NOT " * 491 + "x IS lo"))
    assert main(["check", str(path)]) == 1
    assert f"{path}:17:" in capsys.readouterr().err


def test_a_long_flat_chain_of_ands_loads_and_runs() -> None:
    """10,000 ANDs in a row are one flat condition, not 10,000 levels: nothing to refuse."""
    doc = fuzzyctl.load(fcl(" AND ".join(["x IS lo"] * 10_000)), format="fcl")
    ctl = fuzzyctl.compile(doc, backend="python")
    assert ctl.evaluate({"x": 0.0})["y"] == pytest.approx(2.0)


def test_csv_tables_with_cr_line_ends_and_huge_fields() -> None:
    root = Path(__file__).resolve().parents[2]
    text = (root / "examples" / "xfuz_3_3.csv.xfuz").read_text()
    # CR alone ends rows as LF does: the same system
    same = fuzzyctl.load(text.replace("\n", "\r"), format="xfuz")
    assert same == fuzzyctl.load(text, format="xfuz")
    lines = text.split("\n")
    lines[5] = "CONST,OP_ET," + "7" * 200_000 + ","  # over the csv module's 131,072 characters
    with pytest.raises(DiagnosticError) as info:
        fuzzyctl.load("\n".join(lines), format="xfuz")
    d = info.value.diagnostics[0]
    assert d.span is not None and d.span.line == 6 and len(d.message) < 300


# --------------------------------------------------------------------------- extreme inputs

BACKENDS = ["python", "interpreted"] + (["native"] if shutil.which("cc") or shutil.which("gcc") else [])


def _both(ctl: fuzzyctl.Controller, x: dict[str, float]) -> tuple[float, float]:
    one = ctl.evaluate(x)["y"]
    many = ctl.evaluate_batch({k: np.array([v]) for k, v in x.items()})["y"][0]
    return float(one), float(many)


def _same(a: float, b: float) -> bool:
    return (math.isnan(a) and math.isnan(b)) or a == pytest.approx(b, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize(
    ("kind", "params"),
    [
        ("gbellmf", "[2 200 5]"),  # |(x - c)/a| ** 400 overflows at 1e20
        ("gaussmf", "[1e-100 5]"),  # (x - c)^2 / 2 sd^2 overflows to inf: exp(-inf) = 0
        ("gaussmf", "[1e100 5]"),  # x^2 overflows at 1e300
        ("sigmf", "[1e3 5]"),  # exp(-a (x - c)) overflows at -1e20
    ],
)
def test_large_finite_inputs_give_one_value_on_every_backend(backend: str, kind: str, params: str) -> None:
    doc = fuzzyctl.load(fis(kind=kind, params=params), format="fis")
    ctl = fuzzyctl.compile(doc, backend=backend)
    ref = fuzzyctl.compile(doc, backend="interpreted")
    for x in (1e20, -1e20, 1e300, 4.0, 5.0):
        one, many = _both(ctl, {"x": x})
        assert _same(one, many), (x, one, many)
        assert _same(one, _both(ref, {"x": x})[0]), x
    # the degree itself, where the arithmetic is exact: 1 / (1 + 0) at the centre
    if kind == "gbellmf":
        assert ctl.explain({"x": 5.0}).terms[0].degree == 1.0


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("sd", ["1e-200", "-1e-320", "1e200"])
def test_a_gaussian_width_whose_square_is_not_a_number_is_refused(backend: str, sd: str) -> None:
    """2 sd^2 of 0 or inf makes the centre 0/0: refused with the term's place, on every backend
    (the generated Python raised ZeroDivisionError where numpy gave NaN)."""
    doc = fuzzyctl.load(fis(kind="gaussmf", params=f"[{sd} 5]"), format="fis")
    with pytest.raises(DiagnosticError) as info:
        fuzzyctl.compile(doc, backend=backend)
    d = info.value.diagnostics[0]
    assert "standard deviation between 1e-150 and 1e+150" in d.message and d.span is not None


SUGENO = """[System]
Name='s'
Type='sugeno'
NumInputs=2
NumOutputs=1
NumRules=2
AndMethod='prod'
OrMethod='max'
ImpMethod='prod'
AggMethod='sum'
DefuzzMethod='wtaver'

[Input1]
Name='a'
Range=[0 10]
NumMFs=1
MF1='any':'trapmf',[-Inf 0 10 Inf]

[Input2]
Name='b'
Range=[0 10]
NumMFs=1
MF1='any':'trapmf',[-Inf 0 10 Inf]

[Output1]
Name='y'
Range=[0 10]
NumMFs=2
MF1='p':'linear',[1 1 0]
MF2='q':'linear',[-1 -1 0]

[Rules]
1 1, 1 (1) : 1
1 1, 2 (1) : 1
"""


@pytest.mark.parametrize("backend", BACKENDS)
def test_explain_and_every_backend_survive_sums_that_overflow(backend: str) -> None:
    """``a + b`` overflows to inf and ``-a - b`` to -inf: their weighted average is NaN (the
    IEEE value; math.fsum raised "-inf + inf in fsum" in explain and the interpreted path)."""
    ctl = fuzzyctl.compile(fuzzyctl.load(SUGENO, format="fis"), backend=backend)
    x = {"a": 1e308, "b": 1e308}
    one, many = _both(ctl, x)
    assert math.isnan(one) and math.isnan(many)
    assert math.isnan(ctl.explain(x).outputs[0].value)
    assert ctl.evaluate({"a": 1.0, "b": 2.0})["y"] == 0.0  # (3 - 3) / 2


# --------------------------------------------------------------------------- the CLI (14.6)


def test_eval_never_prints_an_overflow_as_a_result(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "s.fis"
    path.write_text(SUGENO.replace("[-1 -1 0]", "[1 1 0]"))
    assert main(["eval", str(path), "-s", "a=1e308", "-s", "b=1e308", "--json"]) == 1
    out, err = capsys.readouterr()
    assert out.strip() == '{"y": null}'
    assert "output 'y' has no value (inf)" in err
    assert main(["eval", str(path), "-s", "a=1", "-s", "b=2"]) == 0


def test_eval_says_when_no_rule_fired_and_the_default_is_nan(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "f.fcl"
    path.write_text(
        fcl(cond="x IS hi", default="nan").replace("RULE 2 : IF x IS hi", "RULE 2 : IF x IS lo AND x IS hi")
    )
    assert main(["eval", str(path), "-s", "x=0"]) == 1
    assert "output 'y' has no value (nan): no rule fired and its DEFAULT is NaN" in capsys.readouterr().err
    assert main(["eval", str(path), "-s", "x=10"]) == 0


def test_api_errors_are_project_errors() -> None:
    """What the API raises for a bad file is a FuzzyctlError (the CLI's exit 1), never a
    RecursionError, OverflowError, ValueError or csv.Error."""
    for _name, text, fmt, _line, _words in REFUSED:
        try:
            fuzzyctl.load(text, format=fmt)
        except FuzzyctlError:
            continue
        pytest.fail(f"{_name} loaded")


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_subnormal_vertex_is_zero_not_a_nan_centroid(backend: str) -> None:
    """Found by the fuzzer: ``Triangle 1e-320 15 20`` next to a term ending at 0 made a piece
    1e-320 wide whose slope overflowed - NaN in batches, a compile error in the generated
    code.  A subnormal parameter is 0: the same centroid as with 0, on every path."""
    root = Path(__file__).resolve().parents[2]
    text = (root / "tests/data/fuzzylite/original/mamdani/matlab/tipper1.fll").read_text()
    assert "term: average Triangle 10.000 15.000 20.000" in text
    tiny = fuzzyctl.compile(
        fuzzyctl.load(text.replace("Triangle 10.000 15.000", "Triangle 1e-320 15.000"), format="fll"),
        backend=backend,
    )
    zero = fuzzyctl.compile(
        fuzzyctl.load(text.replace("Triangle 10.000 15.000", "Triangle 0 15.000"), format="fll"),
        backend="interpreted",
    )
    for service in (0.0, 3.0, 10.0):
        one = tiny.evaluate({"service": service})["tip"]
        many = float(tiny.evaluate_batch({"service": np.array([service])})["tip"][0])
        assert one == pytest.approx(zero.evaluate({"service": service})["tip"], rel=1e-12)
        assert many == pytest.approx(one, rel=1e-12)
