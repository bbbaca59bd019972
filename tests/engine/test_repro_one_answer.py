"""Issue 25's reproducers (``../shared/repro``, extra suite ``repro``: some carry corpus
terms, so they are read there, never copied): one answer on every path, and the independent
oracle - Debian's ``fuzzylite`` 6 binary - where it is installed."""

from __future__ import annotations

import math
import shutil
import subprocess
import tracemalloc
import warnings
from pathlib import Path

import numpy as np
import pytest

from fuzzyctl.api import compile as compile_api
from fuzzyctl.api import load
from fuzzyctl.cli import main
from tests.extras import extra_path

pytestmark = pytest.mark.extra("repro")


def repro(name: str) -> Path:
    return extra_path("repro", "repro", name)


def _ctl(name: str, backend: str, compat: str = "iec") -> object:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return compile_api(load(repro(name)), backend=backend, compat=compat)


def _fuzzylite(name: str, header: str, rows: list[str], tmp: Path) -> list[float] | None:
    """The fuzzylite binary's output for each row (last column), or None without it."""
    exe = shutil.which("fuzzylite")
    if exe is None:
        return None
    fld = tmp / "in.fld"
    fld.write_text(header + "\n" + "\n".join(rows) + "\n")
    out = tmp / "out.fld"
    subprocess.run(
        [exe, "-i", str(repro(name)), "-of", "fld", "-d", str(fld), "-o", str(out), "-decimals", "12"],
        check=True,
        capture_output=True,
        timeout=60,
    )
    return [float(line.split()[-1]) for line in out.read_text().splitlines()[1:] if line.strip()]


def _same(a: float, b: float, tol: float) -> bool:
    return (math.isnan(a) and math.isnan(b)) or abs(a - b) <= tol


@pytest.mark.parametrize(
    "name", ["function.fll", "function_ramp.fll", "function_range.fll", "sigmoid_product.fll"]
)
def test_scalar_batch_and_reference_agree_on_101_inputs(name: str) -> None:
    """function.fll: the scalar path answered 25.49 on a 0..1 range (66 of 101 inputs off);
    sigmoid_product.fll: the interpreter 6.7e-8 off."""
    xs = np.linspace(0.0, 1.0, 101)
    ref = _ctl(name, "interpreted")
    want = [ref.evaluate({"obstacle": float(x)})["steer"] for x in xs]  # type: ignore[attr-defined]
    for backend in ("python", "native"):
        ctl = _ctl(name, backend)
        batch = ctl.evaluate_batch({"obstacle": xs})["steer"]  # type: ignore[attr-defined]
        ctl.reset()  # type: ignore[attr-defined]
        for x, w, b in zip(xs, want, batch, strict=True):
            got = ctl.evaluate({"obstacle": float(x)})["steer"]  # type: ignore[attr-defined]
            assert _same(got, w, 1e-9) and _same(float(b), w, 1e-9), (backend, float(x), got, float(b), w)


def test_function_fll_eval_set_against_fuzzylite(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["eval", str(repro("function.fll")), "--set", "obstacle=0.1", "--json"]) == 0
    got = float(capsys.readouterr().out.split(":")[1].strip(" }\n"))
    ref = _ctl("function.fll", "interpreted").evaluate({"obstacle": 0.1})["steer"]  # type: ignore[attr-defined]
    assert abs(got - ref) <= 1e-9
    fl = _fuzzylite("function.fll", "obstacle", ["0.1"], tmp_path)
    if fl is not None:  # fuzzylite's Centroid samples 100 points: agreement to its resolution
        assert abs(got - fl[0]) < 1e-3, (got, fl)


def test_bell_of_negative_slope_and_huge_centre_as_fuzzylite(tmp_path: Path) -> None:
    """A Bell of negative slope is 0 at its centre (pow(0, -4) = inf), as fuzzylite computes;
    every path says so (bell_negslope: -5.0; slbb_perturbed: one answer, fuzzylite's)."""
    cases = [
        ("bell_negslope.fll", "x", [{"x": 0.0}, {"x": 0.5}]),
        (
            "slbb_perturbed.fll",
            "in1 in2 in3 in4",
            [
                {"in1": 0.0, "in2": 0.0, "in3": 0.2, "in4": 0.0},
                {"in1": -1.5, "in2": 1.5, "in3": 0.2, "in4": 0.4},
                {"in1": 0.3, "in2": -0.2, "in3": 0.1, "in4": 0.1},
            ],
        ),
    ]
    for name, header, rows in cases:
        out = "y" if name.startswith("bell") else "out"
        ref = _ctl(name, "interpreted")
        want = [ref.evaluate(r)[out] for r in rows]  # type: ignore[attr-defined]
        if name.startswith("bell"):
            assert want[0] == -5.0
        for backend in ("python", "native"):
            ctl = _ctl(name, backend)
            batch = ctl.evaluate_batch({k: np.array([r[k] for r in rows]) for k in rows[0]})[out]  # type: ignore[attr-defined]
            for r, w, b in zip(rows, want, batch, strict=True):
                got = ctl.evaluate(r)[out]  # type: ignore[attr-defined]
                assert _same(got, w, 1e-9 * 20) and _same(float(b), w, 1e-9 * 20), (
                    name,
                    backend,
                    r,
                    got,
                    b,
                    w,
                )
        fl = _fuzzylite(name, header, [" ".join(str(r[k]) for k in header.split()) for r in rows], tmp_path)
        if fl is not None:  # fuzzylite's own semantics: its profile (a firing threshold of 1e-6)
            as_fl = _ctl(name, "python", compat="fuzzylite")
            for r, f in zip(rows, fl, strict=True):
                w = as_fl.evaluate(r)[out]  # type: ignore[attr-defined]
                assert abs(w - f) <= 1e-9, (name, r, w, f)


@pytest.mark.parametrize("name", ["function_div0.fll", "function_divzero_mem.fll"])
def test_zero_over_zero_in_a_function_term_bounded_memory(name: str, tmp_path: Path) -> None:
    """200 rows took ~23-37 MB each in the numpy path (MemoryError under 3 GB)."""
    ctl = _ctl(name, "python")
    xs = np.random.default_rng(25).uniform(0.0, 1.0, 200)
    tracemalloc.start()
    try:
        got = ctl.evaluate_batch({"obstacle": xs})["steer"]  # type: ignore[attr-defined]
        _cur, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 100e6, peak
    ref = _ctl(name, "interpreted")
    for x, g in zip(xs[:20], got[:20], strict=True):
        assert _same(ref.evaluate({"obstacle": float(x)})["steer"], float(g), 1e-9)  # type: ignore[attr-defined]
    data = tmp_path / "rows.csv"
    data.write_text("obstacle\n" + "\n".join(str(x) for x in xs) + "\n")
    assert main(["eval", str(repro(name)), "--data", str(data), "-o", str(tmp_path / "out.csv")]) == 0


def test_largest_of_maximum_of_a_function_term_is_proportionate(monkeypatch: pytest.MonkeyPatch) -> None:
    """slow_lom_function.fll: 0.5 s an evaluation (a golden-section search from every node of
    the plateau); now a bounded number of evaluations of the term."""
    from fuzzyctl.engine.reference import interp
    from fuzzyctl.engine.semantics import expr

    calls = 0
    real = expr.eval_expr_np

    def counting(*args: object, **kw: object) -> object:
        nonlocal calls
        calls += 1
        return real(*args, **kw)  # type: ignore[arg-type]

    monkeypatch.setattr(interp, "eval_expr_np", counting)
    for backend in ("python", "interpreted"):
        ctl = _ctl("slow_lom_function.fll", backend)
        for x in (0.1, 0.5, 0.9):
            calls = 0
            ctl.evaluate({"obstacle": x})  # type: ignore[attr-defined]
            assert calls < 600, (backend, x, calls)
