"""Rules without an IF part (Siemens S7 manual 1.5: "a truth degree of 1 always acts on the
THEN part") carried end to end: model, FPL, JSON, FIS, FLL, XFUZ, FCL (as ``IF ALWAYS THEN``
with an unconnected input := 1.0, docs/fcl.md), the engine and both PLC blocks; never
dropped."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl import formats
from fuzzyctl.blocks.schneider import XfuzFB
from fuzzyctl.blocks.siemens import FuzzyFB
from fuzzyctl.fcl import conformance, load_text
from fuzzyctl.fcl.parser import parse_source
from fuzzyctl.fcl.source import Source
from fuzzyctl.formats.fpl.reader import read_fpl
from fuzzyctl.formats.xfuz.writer import adapt_xfuz, constants_from_model
from fuzzyctl.model import Degree, Document
from tests.conftest import EXAMPLES

BIAS = "RULE bias THEN Valve = closed END\nRULE Rule_04"


def biased() -> Document:
    """FPLTEST (manual 1.3) with a rule "THEN Valve = closed" and no IF part."""
    return read_fpl((EXAMPLES / "fpltest.fpl").read_text().replace("RULE Rule_04", BIAS))


def test_siemens_1_5_bias_rule_by_hand_in_the_block_and_the_engine() -> None:
    # Temp 9, Pressure 65: inlet .75, closed .25 + .25 + 1 (the bias rule), drainage .25
    # -> (75 - 25) / 2.5 = 20 (1.4, the rules of one term added).  Temp 30, Pressure 100:
    # drainage 1, closed 1 -> -50.  Temp 15, Pressure 75: every rule .5, closed 1 + 1 -> 0.
    doc = biased()
    (bias,) = [r for _rb, r in doc.main.rules() if r.label == "bias"]
    assert bias.condition is None
    fb = FuzzyFB(doc)
    controller = fuzzyctl.compile(doc)
    for temp, pressure, want in ((9.0, 65.0, 20.0), (30.0, 100.0, -50.0), (15.0, 75.0, 0.0)):
        fb.set_inputs([temp, pressure])
        fb.execute()
        assert fb.outputs[0] == want
        assert controller.evaluate({"Temp": temp, "Pressure": pressure})["Valve"] == pytest.approx(want)


@pytest.mark.parametrize("fmt", ["fcl", "json", "fpl", "fis", "fll"])
def test_every_format_keeps_the_rule_without_if_part(fmt: str) -> None:
    doc = biased()
    text, losses = formats.convert(doc, fmt, lossy=True)
    assert not [loss for loss in losses if "bias" in str(loss) or "condition" in loss.reason]
    back = formats.read_text(text, fmt).document
    (rule,) = [r for _rb, r in back.main.rules() if r.condition is None]
    assert [c.term for c in rule.conclusions] == ["closed"]
    assert [v.name for v in back.main.inputs] == ["Temp", "Pressure"]  # no extra input
    grid = {"Temp": np.linspace(0, 30, 13), "Pressure": np.linspace(50, 100, 11)[:, None]}
    grid = {k: np.broadcast_to(v, (11, 13)).ravel() for k, v in grid.items()}
    want = fuzzyctl.compile(doc).evaluate_batch(grid)["Valve"]
    got = fuzzyctl.compile(back).evaluate_batch(grid)[back.main.outputs[0].name]
    assert np.allclose(got, want, rtol=0, atol=1e-9)


def test_fcl_form_is_a_degree_input_left_unconnected_and_computes_the_same_as_written() -> None:
    doc = biased()
    text = formats.convert(doc, "fcl")[0]
    assert "ALWAYS : REAL := 1;" in text and "RULE bias : IF ALWAYS THEN Valve IS closed;" in text
    assert "leave unconnected" in text
    (note,) = formats.get("fcl").notes(doc)
    assert "ALWAYS" in note.reason and "unconnected" in note.reason
    # As another IEC tool reads it: ALWAYS is an input; unconnected it keeps 1.0.
    as_written = parse_source(Source(text, None)).document
    assert as_written is not None and "ALWAYS" in [v.name for v in as_written.main.inputs]
    (rule,) = [r for _rb, r in as_written.main.rules() if r.label == "bias"]
    assert rule.condition == Degree("ALWAYS")
    iec = fuzzyctl.compile(as_written)
    ours = fuzzyctl.compile(doc)
    for temp, pressure in ((9.0, 65.0), (20.0, 60.0), (3.0, 99.0), (28.0, 51.0)):
        point = {"Temp": temp, "Pressure": pressure}
        assert iec.evaluate(point)["Valve"] == pytest.approx(ours.evaluate(point)["Valve"], abs=1e-12)
    # Read by fuzzyctl, the form is the rule without IF part again, with a note.
    result = load_text(text)
    assert result.document == doc and [d.code for d in result.diagnostics if d.code == "no-if-part"]
    assert formats.convert(result.document, "fcl")[0] == text  # stable
    feats = conformance.features(result.document)
    (feat,) = [f for f in feats if "rule without IF part" in f.detail]
    assert feat.level is conformance.Level.EXTENSION and feat.table == "Table 9"


def test_always_is_only_read_back_when_it_is_the_writer_s_form() -> None:
    text = formats.convert(biased(), "fcl")[0]
    ordinary = [
        text.replace("ALWAYS : REAL := 1;", "ALWAYS : REAL := 0.5;"),  # another initial value
        text.replace("IF ALWAYS THEN", "IF ALWAYS AND Temp IS cold THEN"),  # part of a condition
        text.replace("ALWAYS : REAL := 1;", "ALWAYS : REAL;"),  # no initial value
        text.replace("ALWAYS", "BIAS_IN"),  # another name
    ]
    for variant in ordinary:
        doc = load_text(variant).raise_for_errors()
        assert all(r.condition is not None for _rb, r in doc.main.rules())
        assert len(doc.main.inputs) == 3
    # A name taken by the program: the writer picks ALWAYS_2 and reads it back.
    taken = formats.convert(
        read_fpl(
            (EXAMPLES / "fpltest.fpl").read_text().replace("Temp", "ALWAYS").replace("RULE Rule_04", BIAS)
        ),
        "fcl",
    )[0]
    assert "ALWAYS_2 : REAL := 1;" in taken
    back = load_text(taken).raise_for_errors()
    assert [v.name for v in back.main.inputs] == ["ALWAYS", "Pressure"]
    assert sum(r.condition is None for _rb, r in back.main.rules()) == 1


def test_generated_c_computes_the_rule_without_if_part(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from fuzzyctl.codegen import generate_st

    monkeypatch.setenv("FUZZYCTL_CACHE_DIR", str(tmp_path))
    doc = biased()
    assert "RULE bias" in generate_st(doc)
    native = fuzzyctl.compile(doc, backend="native")  # the generated C, compiled
    assert type(native).__name__ == "NativeController"
    assert native.evaluate({"Temp": 9.0, "Pressure": 65.0})["Valve"] == pytest.approx(20.0)  # (75 - 25) / 2.5


def test_xfuz_tables_hold_it_as_an_always_true_predicate() -> None:
    doc = biased()
    adapted, _losses = adapt_xfuz(doc)
    constants, diags = constants_from_model(adapted)
    assert not [d for d in diags if d.is_error]
    (note,) = formats.get("xfuz").notes(doc)
    assert "INPi IS ALWAYS" in note.reason
    block = XfuzFB(constants)
    block.MAN_AUTO, block.START = 1, 1
    names = [r.label for r in adapted.main.rule_blocks[0].rules]
    k = names.index("bias")
    for temp in (0, 9, 30, -32768, 32767):  # 1 for every input word
        block["INP1"], block["INP2"] = temp, 65
        block.START = 0
        block.execute()
        block.START = 1
        block.execute()
        assert block.DEGRE[k] == 255
    back = formats.read_text(formats.convert(doc, "xfuz", lossy=True)[0], "xfuz").document
    assert [r.condition is None for _rb, r in back.main.rules()] == [False, False, False, True, False]
    assert all(t.name != "ALWAYS" for f in back.main.fuzzify for t in f.terms)


def test_convert_warns_about_the_fcl_form(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from fuzzyctl.cli.app import main

    source = tmp_path / "bias.fpl"
    source.write_text((EXAMPLES / "fpltest.fpl").read_text().replace("RULE Rule_04", BIAS))
    code = main(["convert", str(source), str(tmp_path / "bias.fcl")])
    err = capsys.readouterr().err
    assert code == 0 and "warning: rule(s) 'bias': no IF part" in err and "dropped" not in err
    assert "IF ALWAYS THEN" in (tmp_path / "bias.fcl").read_text()
