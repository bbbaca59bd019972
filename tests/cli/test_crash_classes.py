"""The crash classes of issue 25 point 6 through the CLI: each input is a diagnostic with its
place (file:line:column), never exit 3 (an internal error) - for the whole class, not the
one reproducer: every accumulation on every writer, every shape with a divisor parameter on
check/eval/codegen, numbers too large in every numeric field of both JSON readers, nesting in
both JSON readers."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

import fuzzyctl
from fuzzyctl import formats
from fuzzyctl import model as m
from fuzzyctl.cli import main
from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.limits import MAX_JSON_DEPTH

EXIT_INTERNAL = 3


def _fcl(accu: str = "MAX", output_term: str = "TRIAN 0 5 10", extra: str = "", method: str = "COG") -> str:
    return f"""\
FUNCTION_BLOCK f
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x
  TERM lo := (0, 1) (10, 0);
  TERM hi := (0, 0) (10, 1);
END_FUZZIFY
DEFUZZIFY y
  TERM a := {output_term};
  TERM b := (5, 0) (10, 1) (15, 0);{extra}
  METHOD : {method};
  DEFAULT := 0;
END_DEFUZZIFY
RULEBLOCK r
  AND : MIN;
  ACT : MIN;
  ACCU : {accu};
  RULE 1 : IF x IS lo THEN y IS a;
  RULE 2 : IF x IS hi THEN y IS b;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def _located(err: str, path: Path) -> re.Match[str] | None:
    return re.search(rf"{re.escape(path.name)}:(\d+):(\d+): error", err)


@pytest.mark.parametrize("accu", sorted(m.ACCU_METHODS))
@pytest.mark.parametrize("target", ["fll", "fis", "fpl", "xfuz", "json"])
def test_convert_lossy_writes_every_accumulation_or_says_why(
    tmp_path: Path, accu: str, target: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """``convert --lossy`` of NSUM to FLL was KeyError 'NSUM' (the studio's export: 500)."""
    source = tmp_path / "f.fcl"
    source.write_text(_fcl(accu))
    out = tmp_path / f"out.{target}"
    code = main(["convert", "--lossy", str(source), str(out)])
    assert code == 0, capsys.readouterr().err
    formats.read_path(out)  # what was written reads back


def test_nsum_to_fll_gives_the_same_centroid(tmp_path: Path) -> None:
    """NSUM scales the accumulated set by a constant: UnboundedSum has the same centroid."""
    source = tmp_path / "f.fcl"
    source.write_text(_fcl("NSUM"))
    out = tmp_path / "out.fll"
    assert main(["convert", "--lossy", str(source), str(out)]) == 0
    for x in (1.0, 3.0, 5.0, 8.0):
        want = fuzzyctl.compile(fuzzyctl.load(source), backend="interpreted").evaluate({"x": x})["y"]
        got = fuzzyctl.compile(fuzzyctl.load(out), backend="interpreted").evaluate({"x": x})["y"]
        assert got == pytest.approx(want, abs=1e-9 * 15)


@pytest.mark.parametrize(
    "term",
    [
        "TRIAN 2 2.2250738585072014e-308 4",  # the reproducer: an unused, malformed triangle
        "(0, 0) (2.2250738585072014e-308, 2.2250738585072014e-308) (1, 1) (2, 0)",
        "TRIAN 0 1e300 1e300",
        "TRAPE 0 1e-300 2e-300 3",
    ],
)
def test_closed_forms_that_overflow_are_integrated_not_a_crash(
    tmp_path: Path, term: str, capsys: pytest.CaptureFixture[str]
) -> None:
    source = tmp_path / "f.fcl"
    source.write_text(_fcl(output_term=term))
    code = main(["eval", str(source), "-s", "x=5", "--json"])
    captured = capsys.readouterr()
    assert code != EXIT_INTERNAL, captured.err
    if code == 0:  # every backend gives the reference's number
        reference = fuzzyctl.compile(fuzzyctl.load(source), backend="interpreted").evaluate({"x": 5.0})["y"]
        assert json.loads(captured.out)["y"] == pytest.approx(reference, abs=1e-9 * 15)


# shapes whose formula divides by a parameter, each with that parameter 0 (jFuzzyLogic syntax)
DIVISORS = [
    "GBELL 1 0 5",  # slope 0: the reproducer
    "GBELL 0 2 5",  # width 0
    "GBELL 0 0 5",
    "GAUSS 5 0",
    "GAUSS2 5 0 6 0",
    "SIGM 0 5",
    "DSIGM 0 2 0 8",
    "COSINE 0 5",
]


COMMANDS = [["check"], ["eval", "-s", "x=5"], ["codegen"], ["codegen", "--lang", "c"]]


@pytest.mark.parametrize("shape", DIVISORS)
@pytest.mark.parametrize("where", ["input", "output"])
@pytest.mark.parametrize("command", COMMANDS)
def test_a_divisor_parameter_of_0_is_never_an_internal_error(
    tmp_path: Path, shape: str, where: str, command: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    """GBELL of slope 0 was ZeroDivisionError on check, eval and codegen (studio: 500)."""
    text = _fcl(output_term=shape, method="COG") if where == "output" else _fcl()
    if where == "input":
        text = text.replace("TERM hi := (0, 0) (10, 1);", f"TERM hi := {shape};")
    source = tmp_path / "f.fcl"
    source.write_text(text)
    args = [command[0], str(source), *command[1:]]
    if command[0] == "codegen" and "c" in command:
        args += ["-o", str(tmp_path)]
    code = main(args)
    err = capsys.readouterr().err
    assert code != EXIT_INTERNAL, err
    if code == 1:  # a refusal names the file, the line and the column
        assert _located(err, source), err


def test_gbell_slope_0_without_range_says_to_give_a_range_at_the_term(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    source = tmp_path / "f.fcl"
    source.write_text(_fcl(output_term="GBELL 1 0 5").replace("  DEFAULT := 0;\n", ""))
    assert main(["check", str(source)]) == 1
    err = capsys.readouterr().err
    found = _located(err, source)
    assert found and found.group(1) == "9" and "RANGE" in err  # TERM a is on line 9


# --------------------------------------------------------------------------- JSON readers


def _model_json() -> dict[str, object]:
    source = _fcl()
    text, _losses = formats.convert(formats.read_text(source, "fcl").document, "json")
    data = json.loads(text)
    assert isinstance(data, dict)
    return data


NUMBERS = ["9" * 401, "-" + "1" + "0" * 400, "9" * 350, "1e400", "-1e400", "9" * 5001]


@pytest.mark.parametrize("number", NUMBERS, ids=lambda n: n[:8] + f"..({len(n)})")
@pytest.mark.parametrize(
    "field",
    [
        ("blocks", 0, "fuzzify", 0, "terms", 0, "mf", "points", 0, "x"),
        ("blocks", 0, "fuzzify", 0, "terms", 0, "mf", "points", 0, "y"),
        ("blocks", 0, "defuzzify", 0, "default", "value"),
        ("blocks", 0, "defuzzify", 0, "span", "line"),  # an integer field
    ],
    ids=lambda f: ".".join(map(str, f[-3:])),
)
def test_a_number_too_large_in_a_model_json_is_refused_at_its_place(
    tmp_path: Path, number: str, field: tuple[object, ...], capsys: pytest.CaptureFixture[str]
) -> None:
    """bigint.json: a 401-digit integer was OverflowError on eval."""
    data = _model_json()
    node: object = data
    for key in field[:-1]:
        node = node[key]  # type: ignore[index]
    node[field[-1]] = "@NUMBER@"  # type: ignore[index]
    source = tmp_path / "m.json"
    source.write_text(json.dumps(data, indent=1).replace('"@NUMBER@"', number))
    code = main(["eval", str(source), "-s", "x=1"])
    err = capsys.readouterr().err
    assert code == 1, err
    found = _located(err, source)
    assert found, err
    line = int(found.group(1))
    assert number[:20] in source.read_text().splitlines()[line - 1]


def _xfuz_json() -> dict[str, object]:
    text = (Path(__file__).resolve().parents[2] / "examples" / "xfuz_3_3.xfuz").read_text()
    data = json.loads(text)
    assert isinstance(data, dict)
    return data


@pytest.mark.parametrize("number", NUMBERS, ids=lambda n: n[:8] + f"..({len(n)})")
@pytest.mark.parametrize("where", ["FA", "ESV", "constants"])
def test_a_number_too_large_in_xfuz_tables_is_refused_at_its_place(
    tmp_path: Path, number: str, where: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """bigint.xfuz: 5001 digits was ValueError (Python's 4300-digit limit) on convert."""
    data = _xfuz_json()
    if where == "constants":
        data["constants"]["T_OFB$"] = "@NUMBER@"  # type: ignore[index]
    else:
        data[where][3] = "@NUMBER@"  # type: ignore[index]
    source = tmp_path / "t.xfuz"
    source.write_text(json.dumps(data, indent=1).replace('"@NUMBER@"', number))
    code = main(["convert", str(source), str(tmp_path / "out.fcl")])
    err = capsys.readouterr().err
    assert code == 1, err
    assert _located(err, source), err


@pytest.mark.parametrize("fmt", ["json", "xfuz"])
@pytest.mark.parametrize("depth", [MAX_JSON_DEPTH + 1, 100_000])
def test_json_nested_too_deep_is_refused_by_both_json_readers_at_its_place(
    tmp_path: Path, fmt: str, depth: int, capsys: pytest.CaptureFixture[str]
) -> None:
    """XFUZ tables nested 100,000 deep were a RecursionError (the model reader stopped at 240)."""
    nested = "[" * depth + "]" * depth
    text = (
        f'{{"format": "xfuz-tables", "version": 1, "ESV": {nested}}}'
        if fmt == "xfuz"
        else f'{{"format": "fuzzyctl-model", "version": 1, "blocks": {nested}}}'
    )
    source = tmp_path / f"deep.{fmt}"
    source.write_text(text)
    code = main(["convert", str(source), str(tmp_path / "out.fcl")])
    err = capsys.readouterr().err
    assert code == 1, err
    found = _located(err, source)
    assert found and "levels deep" in err, err


def test_xfuz_csv_indices_and_values_of_any_length_are_diagnostics(tmp_path: Path) -> None:
    source = tmp_path / "t.csv"
    source.write_text(f"table,index,value\nESV,{'9' * 5000},1\nESV,1,{'9' * 5000}\nESV,\u00b2,3\n")
    with pytest.raises(FuzzyctlError) as caught:
        formats.read_path(source, "xfuz")
    rendered = str(caught.value.render() if hasattr(caught.value, "render") else caught.value)
    assert "t.csv:2:1" in rendered and "t.csv:3:1" in rendered and "t.csv:4:1" in rendered
    assert len(rendered) < 3000  # the 5000-digit literals are not echoed
