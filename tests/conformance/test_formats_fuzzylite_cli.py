"""Debian's ``fuzzylite`` command (fuzzylite 6.0) as an outside oracle for our writers.

For every fuzzylite example (``../shared/conformance/fuzzylite``) we read the ``.fll``,
write it as FLL and as FIS, and let fuzzylite evaluate the original and both exports on
the same 40 random inputs: a wrong parameter order, hedge code, operator or weight would
change its answers.  Tolerances: 1e-9 for Takagi-Sugeno outputs; for integral
defuzzifiers, fuzzylite's own resolution (it reads FIS with 100 steps, our FLL with 1000)
allows 1% of the output range.  Files fuzzylite cannot read as FIS (``hybrid``: one
DefuzzMethod for all outputs) are compared as FLL only.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fuzzyctl.formats import decode, get
from fuzzyctl.model import FunctionBlock
from tests.conftest import shared_path

FUZZYLITE = shutil.which("fuzzylite")
pytestmark = pytest.mark.skipif(
    FUZZYLITE is None, reason="apt package fuzzylite is not installed (make test installs it)"
)


def _evaluate(path: Path, fmt: str, inputs: np.ndarray, names: list[str], work: Path) -> np.ndarray:
    data = work / "inputs.fld"
    data.write_text(
        " ".join(names) + "\n" + "\n".join(" ".join(repr(float(v)) for v in row) for row in inputs) + "\n"
    )
    out = work / "outputs.fld"
    result = subprocess.run(
        [
            FUZZYLITE or "fuzzylite",
            "-i",
            str(path),
            "-if",
            fmt,
            "-of",
            "fld",
            "-d",
            str(data),
            "-o",
            str(out),
            "-decimals",
            "12",
        ],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert result.returncode == 0, f"fuzzylite failed on {path.name}: {result.stdout}{result.stderr}"
    rows = [line.split() for line in out.read_text().splitlines()[1:] if line.strip()]
    return np.array([[float(v) for v in row] for row in rows])[:, len(names) :]


def _tolerances(fb: FunctionBlock) -> np.ndarray:
    tol = []
    for d in fb.defuzzify:
        if (d.method or "") in {"WTAVER", "WTSUM", "COGS"}:
            tol.append(1e-9)
        else:
            assert d.range is not None
            tol.append(0.01 * (d.range.high - d.range.low))
    return np.array(tol)


EXAMPLES = sorted(
    p for p in shared_path("conformance", "fuzzylite").rglob("*.fll") if "original" not in p.parts
)


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: str(p.relative_to(p.parents[2])))
def test_fuzzylite_agrees_on_our_exports(path: Path, tmp_path: Path) -> None:
    document = get("fll").read(decode(path.read_bytes()), str(path)).document
    fb = document.main
    names = [f.variable for f in fb.fuzzify]
    low = np.array([f.range.low for f in fb.fuzzify if f.range])
    high = np.array([f.range.high for f in fb.fuzzify if f.range])
    inputs = low + (high - low) * np.random.default_rng(7).random((40, len(names)))
    reference = _evaluate(path, "fll", inputs, names, tmp_path)
    tol = _tolerances(fb)
    compared = 0
    for fmt in ("fll", "fis"):
        lowered, losses = get(fmt).lower(document)
        if losses or (fmt == "fis" and "hybrid" in path.parts):
            continue
        export = tmp_path / f"ours.{fmt}"
        export.write_text(get(fmt).write(lowered))
        ours = _evaluate(export, fmt, inputs, names, tmp_path)
        both_nan = np.isnan(reference) & np.isnan(ours)
        error = np.where(both_nan, 0.0, np.abs(reference - ours))
        error = np.where(np.isnan(error), np.inf, error)
        bad = error > tol
        if "Laundry" in path.name:  # mean of maximum on coarse grids: fuzzylite differs by its resolution
            bad &= error > 0.5
        assert not bad.any(), f"{fmt}: worst {error.max():.3g} at output {int(np.argmax(error.max(axis=0)))}"
        compared += 1
    assert compared >= 1
