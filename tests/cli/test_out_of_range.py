"""Inputs outside their range (issue 27, point 6): a warning by default and the numbers the
engine computed before; clamp, raise and ignore on request; a count per column for data
files; the same in explain, in the quick path and in the API."""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.cli import main
from fuzzyctl.diagnostics import InputError
from fuzzyctl.engine.ranges import InputRangeWarning, outside_lines
from tests.conftest import EXAMPLES

CRANE = EXAMPLES / "crane.fcl"  # no RANGE: distance's terms span -4..20, angle's -15..15
TIPPER = EXAMPLES / "tipper.fis"  # RANGE 0..10 for both inputs, Gaussian service terms


def test_eval_warns_and_keeps_the_number(capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["eval", str(CRANE), "-s", "distance=300", "-s", "angle=0", "--json"]
    assert main(argv) == 0
    captured = capsys.readouterr()
    assert "'distance' = 300 is outside its range -4..20" in captured.err
    # the number is the engine's as it was: far's shoulder holds beyond 20, so 300 reads as 20
    at_edge = fuzzyctl.compile(CRANE).evaluate(distance=20, angle=0)["power"]
    assert json.loads(captured.out)["power"] == at_edge
    assert main([*argv, "--out-of-range", "ignore"]) == 0
    quiet = capsys.readouterr()
    assert quiet.err == "" and quiet.out == captured.out
    assert main(["eval", str(CRANE), "-s", "distance=19", "-s", "angle=0"]) == 0
    assert "outside" not in capsys.readouterr().err


def test_clamp_raise_and_explain(capsys: pytest.CaptureFixture[str]) -> None:
    # a Gaussian keeps changing beyond the RANGE: clamping gives the value at the bound
    edge = fuzzyctl.compile(TIPPER).evaluate(service=10, food=5)["tip"]
    beyond = fuzzyctl.compile(TIPPER).evaluate(service=14, food=5, out_of_range="ignore")["tip"]
    assert abs(edge - beyond) > 1e-6
    argv = ["eval", str(TIPPER), "-s", "service=14", "-s", "food=5", "--json"]
    assert main([*argv, "--out-of-range", "clamp"]) == 0
    assert json.loads(capsys.readouterr().out)["tip"] == pytest.approx(edge, abs=1e-12)
    assert main([*argv, "--out-of-range", "raise"]) == 1
    assert "'service' = 14 is outside its range 0..10" in capsys.readouterr().err
    assert main(["explain", str(TIPPER), "-s", "service=14", "-s", "food=5", "--json"]) == 0
    captured = capsys.readouterr()
    assert "'service' = 14 is outside its range 0..10" in captured.err
    assert json.loads(captured.out)["outputs"][0]["value"] == pytest.approx(beyond, abs=1e-12)


def test_data_files_count_per_column(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rng = np.random.default_rng(5)
    distance, angle = rng.uniform(-10, 30, 200), rng.uniform(-20, 20, 200)
    src = tmp_path / "d.csv"
    rows = zip(distance.tolist(), angle.tolist(), strict=True)
    src.write_text("distance,angle\n" + "".join(f"{d!r},{a!r}\n" for d, a in rows))
    out = tmp_path / "o.csv"
    assert main(["eval", str(CRANE), "--data", str(src), "-o", str(out)]) == 0
    err = " ".join(capsys.readouterr().err.split())
    n_d = int(np.count_nonzero((distance < -4) | (distance > 20)))
    n_a = int(np.count_nonzero((angle < -15) | (angle > 15)))
    assert f"column 'distance': {n_d} of 200 values outside the input's range -4..20" in err
    assert f"column 'angle': {n_a} of 200 values outside the input's range -15..15" in err
    # the rows are the engine's numbers, unchanged
    got = np.loadtxt(out, delimiter=",", skiprows=1)[:, 2]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", InputRangeWarning)
        want = fuzzyctl.compile(CRANE).evaluate_batch({"distance": distance, "angle": angle})["power"]
    assert np.array_equal(got, want)
    assert main(["eval", str(CRANE), "--data", str(src), "-o", str(out), "--out-of-range", "raise"]) == 1
    first = int(np.flatnonzero((distance < -4) | (distance > 20) | (angle < -15) | (angle > 15))[0])
    assert f"d.csv:{first + 2}" in capsys.readouterr().err  # header is line 1


def test_api_warning_class_and_modes() -> None:
    ctl = fuzzyctl.compile(TIPPER)
    with pytest.warns(InputRangeWarning, match="'food' outside its range 0..10") as record:
        value = ctl.evaluate(service=3, food=11)["tip"]
    assert record[0].message.counts == {"food": 1}  # type: ignore[union-attr]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert ctl.evaluate(service=3, food=11, out_of_range="ignore")["tip"] == value
        clamped = fuzzyctl.compile(TIPPER, out_of_range="clamp").evaluate(service=3, food=11)["tip"]
        assert clamped == ctl.evaluate(service=3, food=10)["tip"]
    with pytest.raises(InputError, match="'food' = 11"):
        fuzzyctl.compile(TIPPER, out_of_range="raise").evaluate(service=3, food=11)
    with pytest.raises(InputError, match="out_of_range must be one of"):
        fuzzyctl.compile(TIPPER, out_of_range="wrap")
    food = np.array([-1.0, 0.0, 5.0, 10.0, 10.5, 12.0, math.nan])
    service = np.full(len(food), 4.0)
    with pytest.warns(InputRangeWarning) as record:
        batch = ctl.evaluate_batch({"service": service, "food": food}, on_invalid="nan")
    assert record[0].message.counts == {"food": 3} and record[0].message.total == 7  # type: ignore[union-attr]
    for i in range(len(food) - 1):  # each row as a single evaluation (the warned numbers)
        single = ctl.evaluate(service=4.0, food=food[i], out_of_range="ignore")["tip"]
        assert batch["tip"][i] == pytest.approx(single, abs=1e-9)
    clamped_batch = ctl.evaluate_batch({"service": service[:6], "food": food[:6]}, out_of_range="clamp")
    want = [ctl.evaluate(service=4.0, food=min(max(f, 0.0), 10.0))["tip"] for f in food[:6]]
    assert clamped_batch["tip"] == pytest.approx(want, abs=1e-9)


def test_the_quick_path_prints_the_same_warning() -> None:
    from fuzzyctl.cli.quick_record import outside_lines as quick_lines

    rng = np.random.default_rng(1)
    ranges = {"a": (-4.0, 20.0), "b": (0.0, 1e-3)}
    for _ in range(200):
        values = {"a": float(rng.uniform(-30, 40)), "b": float(rng.uniform(-1e-3, 2e-3)), "c": 1.0}
        assert quick_lines(ranges, values) == outside_lines(ranges, values)


def test_the_quick_start_warns_as_the_full_command_line(tmp_path: Path) -> None:
    """The console script answers simple evals from a cached record without the engine: the
    first start (full path, records) and the second (from the record) print the warning the
    full command line prints."""
    from tests.cli.test_quick import _console, _full, _quick_env

    env = _quick_env(tmp_path)
    argv = ["eval", str(CRANE), "--set", "distance=300", "--set", "angle=-40", "--json"]
    full = _full(argv, env)
    assert full.returncode == 0 and "'angle' = -40 is outside its range -15..15" in full.stderr
    first, second = _console(argv, env), _console(argv, env)
    assert list((tmp_path / "cache" / "quick").glob("*.json")), "no record was written"
    for run in (first, second):
        assert (run.returncode, run.stdout, run.stderr) == (0, full.stdout, full.stderr)
