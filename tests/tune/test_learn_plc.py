"""``learn --type mamdani`` for PLC use (issue 27, point 16): the Siemens FUZZY block computes
what the file says (no profile warning, the block's cycles equal the engine's rows), and the
ranges are numbers a person would write, rounded outward around the data."""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.cli import main
from fuzzyctl.tune.learning import readable_range
from tests.tune.conftest import surface


def _csv(path: Path, cols: dict[str, np.ndarray]) -> Path:
    names = list(cols)
    rows = zip(*cols.values(), strict=True)
    lines = [",".join(names)] + [",".join(repr(float(v)) for v in r) for r in rows]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("terms", ["3", "5"])
def test_the_siemens_block_computes_what_the_learned_file_says(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], terms: str
) -> None:
    cols = surface(300, seed=21)
    cols["x"] = cols["x"] * 1.7 + 0.00438  # a span whose ends are not round
    train = _csv(tmp_path / "t.csv", cols)
    out = tmp_path / "m.fcl"
    args = ["learn", str(train), "--inputs", "x,y", "--target", "z", "--type", "mamdani", "--and", "min"]
    assert main([*args, "--terms", terms, "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["blocks", "check", str(out)]) == 0
    assert "warning" not in capsys.readouterr().err  # blocks check warned about ACCU MAX before
    rng = np.random.default_rng(2)
    probe = {"x": rng.uniform(-5, 5, 60), "y": rng.uniform(-3, 3, 60)}
    samples = _csv(tmp_path / "s.csv", probe)
    assert main(["blocks", "siemens", str(out), str(samples)]) == 0
    block = [float(r["z"]) for r in csv.DictReader(io.StringIO(capsys.readouterr().out))]
    engine = fuzzyctl.compile(out, out_of_range="ignore").evaluate_batch(probe)["z"]
    span = float(np.ptp(cols["z"]))
    # the block computes in single precision (REAL): agreement to its rounding, not to MAX's error
    assert np.max(np.abs(np.array(block) - engine)) < 1e-5 * span


def test_prod_says_what_the_block_takes(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    train = _csv(tmp_path / "t.csv", surface(100, seed=23))
    args = ["learn", str(train), "--inputs", "x,y", "--target", "z", "--type", "mamdani"]
    assert main([*args, "-o", str(tmp_path / "p.fcl")]) == 0
    assert "--and min" in capsys.readouterr().out
    assert main(["blocks", "check", str(tmp_path / "p.fcl")]) == 1
    assert "AND : PROD; the block uses MIN" in capsys.readouterr().err


def test_learned_ranges_are_readable_and_hold_the_data(tmp_path: Path) -> None:
    cols = surface(300, seed=22)
    cols["x"] = cols["x"] * 1.66 + 5.0  # about 0.0044 .. 9.99
    result = fuzzyctl.learn(cols, inputs=["x", "y"], output="z", kind="mamdani", validation=0.0)
    fb = result.block
    for block in (*fb.fuzzify, *fb.defuzzify):
        rng = block.range
        assert rng is not None
        for v in (rng.low, rng.high):
            assert len(f"{v:g}".lstrip("-").replace(".", "").strip("0")) <= 2, (block.variable, v)
    x = fb.fuzzify_block("x").range
    assert x is not None and x.low <= cols["x"].min() and x.high >= cols["x"].max()


@pytest.mark.parametrize(
    ("lo", "hi", "want"),
    [
        (0.00438, 9.99467, (0.0, 10.0)),
        (-2.96505, 2.99416, (-3.0, 3.0)),
        (0.0502513, 10.0, (0.0, 10.0)),
        (0.7, 0.9, (0.7, 0.9)),  # already round: kept (0.7 / 0.01 is not exactly 70)
        (-1591.25, 1576.37, (-1600.0, 1600.0)),
        (1e-7, 3.3e-6, (1e-7, 3.3e-6)),  # two digits of the span: 0.1e-6 steps
    ],
)
def test_readable_range_rounds_outward(lo: float, hi: float, want: tuple[float, float]) -> None:
    got = readable_range(lo, hi)
    assert got[0] <= lo and got[1] >= hi
    assert got == pytest.approx(want, rel=1e-12, abs=1e-15)
    assert all(math.isfinite(v) for v in got)
