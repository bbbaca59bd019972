"""``--samples N`` of ``eval``, ``explain`` and ``codegen``: the output sample count of an
interval type-2 system, refused below 2 and for a type-1 system (docs/type2.md)."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

import fuzzyctl
from fuzzyctl.cli import main
from fuzzyctl.engine.type2 import Type2Controller
from tests.conftest import EXAMPLES

TYPE2 = str(EXAMPLES / "tipper_type2.fis")
TYPE1 = str(EXAMPLES / "figure7.fcl")
ROWS = [{"service": 3.0, "food": 7.0}, {"service": 8.5, "food": 2.0}, {"service": 0.5, "food": 9.5}]


def reference(samples: int | None, row: dict[str, float]) -> float:
    """The readable type-2 engine (not the compiled program the CLI runs with --samples)."""
    fb = fuzzyctl.load(TYPE2).main
    return Type2Controller(fb, samples=samples).evaluate(row)["tip"]


@pytest.mark.parametrize("n", [5, 11, 101])
def test_eval_set_uses_n_samples(n: int, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["eval", TYPE2, "-s", "service=3", "-s", "food=7", "--samples", str(n), "--json"]) == 0
    got = json.loads(capsys.readouterr().out)["tip"]
    assert got == pytest.approx(reference(n, ROWS[0]), abs=1e-9)
    # the option reaches the engine: another count, and the exact centroid, give other values
    assert abs(got - reference(n + 1, ROWS[0])) > 1e-6
    assert abs(got - reference(None, ROWS[0])) > 1e-6


def test_eval_data_uses_n_samples(tmp_path: Path) -> None:
    src, out = tmp_path / "in.csv", tmp_path / "out.csv"
    src.write_text("service,food\n" + "".join(f"{r['service']},{r['food']}\n" for r in ROWS))
    assert main(["eval", TYPE2, "--data", str(src), "-o", str(out), "--samples", "7"]) == 0
    with out.open(newline="") as f:
        got = [float(r["tip"]) for r in csv.DictReader(f)]
    assert got == pytest.approx([reference(7, r) for r in ROWS], abs=1e-9)


def test_explain_says_sampled_with_n_samples(capsys: pytest.CaptureFixture[str]) -> None:
    args = ["explain", TYPE2, "-s", "service=3", "-s", "food=7", "--json"]
    assert main([*args, "--samples", "11"]) == 0
    (tip,) = json.loads(capsys.readouterr().out)["outputs"]
    assert tip["exact"] is False
    assert tip["value"] == pytest.approx(reference(11, ROWS[0]), abs=1e-9)
    assert main(args) == 0  # without it: the exact centroid of these piecewise-linear sets
    assert json.loads(capsys.readouterr().out)["outputs"][0]["exact"] is True


@pytest.mark.parametrize("lang", ["st", "c", "plcopen"])
def test_codegen_states_n_samples(lang: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    assert main(["codegen", TYPE2, "--lang", lang, "-o", str(out), "--samples", "37"]) == 0
    text = "".join(p.read_text() for p in sorted(out.iterdir())) if out.is_dir() else out.read_text()
    assert "sampled at 37 points" in text
    assert "sampled at 101 points" not in text


def test_codegen_to_a_file_defaults_to_101_samples(tmp_path: Path) -> None:
    """(Writing a type-2 block to a file once ended in an internal error after writing it.)"""
    out = tmp_path / "tipper.st"
    assert main(["codegen", TYPE2, "-o", str(out)]) == 0
    assert "sampled at 101 points" in out.read_text()


@pytest.mark.parametrize(
    "command",
    [
        ["eval", TYPE2, "-s", "service=3", "-s", "food=7"],
        ["explain", TYPE2, "-s", "service=3", "-s", "food=7"],
        ["codegen", TYPE2],
    ],
)
@pytest.mark.parametrize("n", ["1", "0", "-3"])
def test_fewer_than_two_samples_is_a_usage_error(
    command: list[str], n: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main([*command, "--samples", n]) == 2
    err = capsys.readouterr().err
    assert "--samples" in err and "at least 2" in err and "Traceback" not in err


@pytest.mark.parametrize(
    "command",
    [
        ["eval", TYPE1, "-s", "temp=10", "-s", "pressure=60"],
        ["explain", TYPE1, "-s", "temp=10", "-s", "pressure=60"],
        ["codegen", TYPE1],
        ["codegen", TYPE1, "--lang", "c"],
    ],
)
def test_samples_on_a_type1_system_is_refused(command: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    assert main([*command, "--samples", "51"]) == 2
    err = capsys.readouterr().err
    assert "--samples" in err and "type-1" in err and "Traceback" not in err


def test_samples_with_dask_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["eval", TYPE2, "--dask", str(tmp_path), "-o", str(tmp_path / "o"), "--samples", "9"]) == 2
    assert "--samples" in capsys.readouterr().err
