"""The conformance statement (IEC 61131-7 6.1 c/d, 6.2): docs/conformance.md is what
fuzzyctl.statement generates from the code (measured numbers aside), every Table 9 element
is realised, the probes and `fuzzyctl check` agree, and the CLI prints it."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest

from fuzzyctl import statement
from fuzzyctl.fcl.conformance import Level
from tests.conftest import EXAMPLES, ROOT

DOC = ROOT / "docs" / "conformance.md"


@pytest.fixture(scope="module")
def generated() -> tuple[list[statement.ProbeResult], list[statement.LimitRow]]:
    return statement.element_rows(), statement.limit_rows()


def test_docs_conformance_md_is_the_generated_statement(generated: Any) -> None:
    elements, limits = generated
    on_disk = DOC.read_text(encoding="utf-8")
    bare, measured = statement.split_measured(on_disk)
    assert "| crane.fcl |" in measured and "µs" in measured  # the examples were measured
    regenerated = statement.render(elements, limits, measured_text=measured)
    assert statement.split_measured(regenerated)[0] == bare, (
        "docs/conformance.md is out of date: run `python benchmarks/conformance.py --write`"
    )


def test_every_table_8_and_9_element_is_realised(generated: Any) -> None:
    elements, _ = generated
    by_table = {t: [r for r in elements if r.probe.table == t] for t in ("Table 8", "Table 9", "Table 10")}
    assert len(by_table["Table 8"]) >= 12 and all(r.supported and r.codegen for r in by_table["Table 8"])
    # Table 9 as the standard lists it: VAR, 4 variable points, AND PROD/BDIF, OR ASUM/BSUM, NOT,
    # ( ), ACT MIN/PROD, ACCU BSUM/NSUM, RANGE, CoG/CoA/LM/RM, n rule blocks, n input variables,
    # n subconclusions / output variables, WITH constant and variable
    details = {r.probe.detail for r in by_table["Table 9"]}
    for needed in (
        "AND: PROD",
        "AND: BDIF",
        "OR: ASUM",
        "OR: BSUM",
        "ACT: PROD",
        "ACCU: NSUM",
        "METHOD: RM",
        "WITH a variable declared in VAR_INPUT",
        "VAR: local variables",
        "RULEBLOCK: n rule blocks",
    ):
        assert needed in details
    assert all(r.supported for r in by_table["Table 9"])
    # Table 10's own examples: free shapes, more than four points, degrees in (0, 1), variable values
    open_details = " ".join(r.probe.detail for r in by_table["Table 10"])
    for needed in ("GAUSS", "more than four points", "degrees between 0 and 1", "variable membership values"):
        assert needed in open_details
    # every parametric shape of the model is listed, for inputs
    assert {
        r.probe.feature[1]
        for r in by_table["Table 10"]
        if r.probe.feature and "input shape" in r.probe.feature[1]
    } >= {f"input shape {k}" for k in statement.SHAPE_PARAMS}


def test_a_probe_the_checker_classifies_otherwise_stops_the_generation() -> None:
    probe = next(p for p in statement.probes() if p.detail == "AND: PROD")
    with pytest.raises(RuntimeError, match="expects"):
        statement.run_probe(replace(probe, feature=("conditional aggregation", "AND: BDIF")))
    with pytest.raises(RuntimeError, match="Basic probe"):
        statement.run_probe(replace(probe, table="Table 8", feature=None))
    assert probe.level is Level.EXTENSION


def test_table_11_limits(generated: Any) -> None:
    _, limits = generated
    rows = {r.item: r for r in limits}
    inputs = rows["max. number of input variables for fuzzification"]
    assert (
        inputs.fuzzyctl.startswith("no fixed limit (tested: 32 inputs")
        and inputs.siemens == "8"
        and inputs.xfuz == "8"
    )
    terms = rows["max. total number of membership function terms for all input variables"]
    assert terms.siemens == "56" and terms.xfuz == "64"  # 8 x 7 (Siemens 1.3); 64 FA records
    assert rows["nesting depth of ( )"].fuzzyctl == "no fixed limit (tested: depth 32)"
    assert rows["max. number of rules per block"].siemens == "200"
    assert rows["max. number of subconclusions per rule"].xfuz == "2"
    assert "REAL" in rows["data types of function block inputs and outputs"].fuzzyctl
    assert rows["length of identifiers"].fuzzyctl == "no fixed limit (tested: 255 characters)"


def test_check_conformance_prints_the_statement_and_measures_a_file(
    generated: Any, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from fuzzyctl.cli.app import main

    elements, limits = generated
    monkeypatch.setattr(statement, "element_rows", lambda progress=None: elements)  # probed above
    monkeypatch.setattr(statement, "limit_rows", lambda: limits)
    assert main(["check", "--conformance", str(EXAMPLES / "siemens_fpltest.fcl")]) == 0
    out = capsys.readouterr().out
    assert out.startswith("# IEC 61131-7 conformance statement of fuzzyctl")
    assert (
        "## Extension level (in the form of Table 9)" in out and "| siemens_fpltest.fcl | 2 | 1 | 4 |" in out
    )
    assert main(["check", "--conformance"]) == 0
    assert "Not measured here" in capsys.readouterr().out
    assert main(["check"]) == 2
    assert main(["check", "--conformance", str(Path("no-such-file.fcl"))]) == 2
