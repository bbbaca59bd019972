"""The library as a Python user meets it: keyword inputs and numpy scalars, inspection of the
variables and terms, plots as matplotlib Figures, and a typed package."""

from __future__ import annotations

import importlib.resources
import math
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.diagnostics import InputError
from tests.conftest import EXAMPLES

FIG7 = EXAMPLES / "figure7.fcl"
FIG7_10_60 = (100 * 17 / 24 - 100 / 8) / (17 / 24 + 7 / 24 + 1 / 8)  # by hand: tests/cli/test_run.py


@pytest.fixture
def ctl() -> fuzzyctl.engine.controller.Controller:
    return fuzzyctl.compile(fuzzyctl.load(FIG7))


def test_keyword_inputs_and_numpy_scalars(ctl: fuzzyctl.engine.controller.Controller) -> None:
    assert ctl.evaluate(temp=10, pressure=60)["valve"] == pytest.approx(FIG7_10_60, abs=1e-12)
    assert ctl.evaluate({"temp": 10}, pressure=60)["valve"] == pytest.approx(FIG7_10_60, abs=1e-12)
    for value in (np.float64(10), np.float32(10), np.int64(10), np.array(10.0), np.array(10)):
        assert ctl.evaluate(temp=value, pressure=np.array(60.0))["valve"] == pytest.approx(
            FIG7_10_60, abs=1e-12
        )
    assert ctl.explain(temp=10, pressure=60).values["valve"] == pytest.approx(FIG7_10_60, abs=1e-12)
    with pytest.raises(InputError, match="given twice"):
        ctl.evaluate({"temp": 10}, temp=11, pressure=60)
    with pytest.raises(InputError, match="must be a number"):
        ctl.evaluate(temp=np.array([10.0, 11.0]), pressure=60)


def test_misspelt_names_come_before_missing_ones(ctl: fuzzyctl.engine.controller.Controller) -> None:
    with pytest.raises(InputError, match=r"unknown input 'presure' \(did you mean 'pressure'\?\)"):
        ctl.evaluate(temp=10, presure=60)
    with pytest.raises(InputError, match=r"unknown input 'tmep' \(did you mean 'temp'\?\)"):
        ctl.evaluate_batch({"tmep": [1.0], "pressure": [2.0]})
    with pytest.raises(InputError, match=r"unknown input 'x' \(inputs: temp, pressure\)"):
        ctl.evaluate(x=1, temp=10, pressure=60)


def test_inputs_and_outputs_expose_ranges_and_terms() -> None:
    ctl = fuzzyctl.compile(fuzzyctl.load(EXAMPLES / "tipper.fis"))
    assert list(ctl.inputs) == ["service", "food"] and "food" in ctl.inputs and len(ctl.inputs) == 2
    service = ctl.inputs["service"]
    assert service.range == (0.0, 10.0) and service.role == "input"
    assert [(t.name, t.kind, t.params) for t in service.terms] == [
        ("poor", "gaussian", (0.0, 1.5)),
        ("good", "gaussian", (5.0, 1.5)),
        ("excellent", "gaussian", (10.0, 1.5)),
    ]
    # the term evaluates as the closed form of MATLAB's gaussmf
    x = np.array([0.0, 2.5, 7.0])
    assert service.term("good").membership(x) == pytest.approx(np.exp(-((x - 5.0) ** 2) / (2 * 1.5**2)))
    food = ctl.inputs["food"]
    assert food.term("rancid").points == ((-2.0, 0.0), (0.0, 1.0), (1.0, 1.0), (3.0, 0.0))
    tip = ctl.outputs["tip"]
    assert tip.range == (0.0, 30.0) and tip.method == "COG"
    assert tip.term("average").points == ((10.0, 0.0), (15.0, 1.0), (20.0, 0.0))
    with pytest.raises(KeyError, match="no term 'great'"):
        tip.term("great")
    with pytest.raises(KeyError, match="no variable 'speed'"):
        ctl.inputs["speed"]


def test_plot_terms_draws_every_term_labelled(tmp_path: Path) -> None:
    ctl = fuzzyctl.compile(fuzzyctl.load(EXAMPLES / "tipper.fis"))
    fig = fuzzyctl.plot_terms(ctl.inputs["service"])
    ax = fig.axes[0]
    assert ax.get_xlabel() == "service" and "degree" in ax.get_ylabel()
    lines = {line.get_label(): line for line in ax.get_lines()}
    assert set(lines) == {"poor", "good", "excellent"}
    xs, ys = lines["poor"].get_data()
    assert np.asarray(ys) == pytest.approx(np.exp(-(np.asarray(xs) ** 2) / (2 * 1.5**2)))
    assert {t.get_text() for t in ax.texts} == {"poor", "good", "excellent"}
    fig.savefig(tmp_path / "service.png")
    assert (tmp_path / "service.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    singletons = fuzzyctl.plot_terms(fuzzyctl.compile(fuzzyctl.load(FIG7)).outputs["valve"]).axes[0]
    segments = [c.get_segments()[0] for c in singletons.collections]
    assert sorted(float(s[0][0]) for s in segments) == [-100.0, 0.0, 100.0]


def test_explanation_plot_is_a_figure_of_the_accumulated_set(
    ctl: fuzzyctl.engine.controller.Controller, tmp_path: Path
) -> None:
    e = ctl.explain(temp=6, pressure=85)
    fig = e.plot()
    ax = fig.axes[0]
    value = e.output("valve").value
    marker = [line for line in ax.get_lines() if "valve =" in str(line.get_label())]
    assert marker and float(marker[0].get_xdata()[0]) == pytest.approx(value)
    fig.savefig(tmp_path / "e.png")
    assert (tmp_path / "e.png").stat().st_size > 1000
    assert not math.isnan(value)


def test_the_package_is_typed() -> None:
    assert importlib.resources.files("fuzzyctl").joinpath("py.typed").is_file()
