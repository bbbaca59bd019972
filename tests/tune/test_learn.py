"""Learning an initial system from data (grid partition / clustering, least-squares
consequents): the acceptance figure on a smooth two-input function, exactness on a linear
function, least-squares optimality, and the written file working everywhere a file does."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.cli import main
from fuzzyctl.diagnostics import InputError
from fuzzyctl.fcl import load_text, write
from fuzzyctl.model import SingletonMF
from tests.tune.conftest import surface


def _csv(path: Path, cols: dict[str, np.ndarray]) -> Path:
    names = list(cols)
    rows = np.column_stack([cols[n] for n in names])
    path.write_text(",".join(names) + "\n" + "\n".join(",".join(repr(float(v)) for v in r) for r in rows))
    return path


def _rmse(doc: fuzzyctl.model.Document, cols: dict[str, np.ndarray], out: str = "z") -> float:
    ctl = fuzzyctl.compile(doc)
    pred = ctl.evaluate_batch({k: v for k, v in cols.items() if k != out})[out]
    return float(np.sqrt(np.mean((pred - cols[out]) ** 2)))


def test_acceptance_smooth_two_input_function_with_default_options(tmp_path: Path) -> None:
    """The issue's acceptance figure: checking RMSE well under 5 % of the target's range."""
    train = _csv(tmp_path / "train.csv", surface(400, seed=1))
    out = tmp_path / "learned.fcl"
    assert main(["learn", str(train), "--inputs", "x,y", "--target", "z", "-o", str(out), "--json"]) == 0
    checking = surface(2000, seed=2)  # fresh points, never seen by learn
    doc = fuzzyctl.load(out)
    span = float(np.ptp(checking["z"]))
    rmse = _rmse(doc, checking)
    assert rmse < 0.01 * span, f"checking RMSE {rmse:.4g} is {100 * rmse / span:.2f} % of the range"


def test_linear_function_is_reproduced_exactly() -> None:
    rng = np.random.default_rng(0)
    x, y = rng.uniform(-3, 3, 300), rng.uniform(0, 10, 300)
    z = 2.0 * x - 0.5 * y + 1.0
    result = fuzzyctl.learn({"x": x, "y": y, "z": z}, inputs=["x", "y"], output="z", validation=0.0)
    # a first-order Takagi-Sugeno system holds any linear function: the fit must be exact
    assert result.scores["training RMSE"] < 1e-6 * float(np.ptp(z))


@pytest.mark.parametrize("kind", ["tsk", "mamdani"])
def test_consequents_are_the_least_squares_optimum(kind: str) -> None:
    cols = surface(300, seed=4)
    result = fuzzyctl.learn(cols, inputs=["x", "y"], output="z", kind=kind, terms=4, validation=0.0)
    fb = result.block

    def sse(block: fuzzyctl.model.FunctionBlock) -> float:
        return _rmse(fuzzyctl.model.Document((block,)), cols) ** 2

    base = sse(fb)
    out = fb.defuzzify[0]
    import dataclasses

    rng = np.random.default_rng(5)
    for _ in range(6):
        k = int(rng.integers(len(out.terms)))
        t = out.terms[k]
        step = 1e-3
        if isinstance(t.mf, SingletonMF):
            lo, hi = out.range.low, out.range.high  # type: ignore[union-attr]
            v = float(t.mf.value)  # type: ignore[arg-type]
            if not lo + step < v < hi - step:
                continue  # a position on the bound of the bounded fit
            mf = dataclasses.replace(t.mf, value=v + step * rng.choice([-1, 1]))
        else:
            p = list(t.mf.params)  # type: ignore[union-attr]
            j = int(rng.integers(len(p)))
            p[j] = float(p[j]) + step * rng.choice([-1, 1])  # type: ignore[arg-type]
            mf = dataclasses.replace(t.mf, params=tuple(p))  # type: ignore[type-var]
        terms = list(out.terms)
        terms[k] = dataclasses.replace(t, mf=mf)
        moved = dataclasses.replace(fb, defuzzify=(dataclasses.replace(out, terms=tuple(terms)),))
        assert sse(moved) >= base * (1 - 1e-9)


def test_mamdani_has_ordered_linguistic_singletons() -> None:
    cols = surface(400, seed=6)
    result = fuzzyctl.learn(cols, inputs=["x", "y"], output="z", kind="mamdani")
    terms = result.block.defuzzify[0].terms
    assert [t.name for t in terms] == ["nb", "nm", "ns", "ze", "ps", "pm", "pb"]
    values = [float(t.mf.value) for t in terms]  # type: ignore[union-attr, arg-type]
    assert values == sorted(values)
    assert result.scores["validation RMSE"] < 0.05 * float(np.ptp(cols["z"]))
    assert result.block.defuzzify[0].method == "COGS"


def test_clustering_is_seeded_and_fits() -> None:
    cols = surface(400, seed=7)
    a = fuzzyctl.learn(cols, inputs=["x", "y"], output="z", method="cluster", seed=3)
    b = fuzzyctl.learn(cols, inputs=["x", "y"], output="z", method="cluster", seed=3)
    assert a.document == b.document
    assert a.rules == 10
    assert a.scores["validation RMSE"] < 0.1 * float(np.ptp(cols["z"]))
    assert all(t.mf.kind == "gaussian" for t in a.block.fuzzify[0].terms)  # type: ignore[union-attr]


def test_learned_file_works_with_codegen_and_plc_blocks(tmp_path: Path) -> None:
    train = _csv(tmp_path / "t.csv", surface(200, seed=8))
    out = tmp_path / "m.fcl"
    args = ["learn", str(train), "--inputs", "x,y", "--target", "z", "--type", "mamdani", "--and", "min"]
    assert main([*args, "--terms", "3", "--out-terms", "5", "-o", str(out), "--json"]) == 0
    doc = fuzzyctl.load(out)
    assert load_text(write(doc)).raise_for_errors() == doc
    assert main(["codegen", str(out), "--lang", "st", "-o", str(tmp_path / "m.st")]) == 0
    from fuzzyctl.blocks.siemens import FuzzyFB  # the PLC block takes it as any other file

    fb = FuzzyFB(doc)
    assert fb is not None


def test_cli_errors_name_the_problem(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    cols = surface(50, seed=9)
    cols["k"] = np.ones(50)
    train = _csv(tmp_path / "t.csv", cols)
    out = str(tmp_path / "o.fcl")
    assert main(["learn", str(train), "--inputs", "x,w", "--target", "z", "-o", out]) == 1
    assert "no column 'w'" in capsys.readouterr().err
    assert main(["learn", str(train), "--inputs", "x,k", "--target", "z", "-o", out]) == 1
    assert "'k' is constant" in capsys.readouterr().err
    assert main(["learn", str(tmp_path / "none.csv"), "--inputs", "x", "--target", "z", "-o", out]) == 1
    assert "no such file" in capsys.readouterr().err
    with pytest.raises(InputError, match="--method"):
        fuzzyctl.learn(cols, inputs=["x"], output="z", method="bogus")


def test_cli_json_reports_both_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    train = _csv(tmp_path / "t.csv", surface(100, seed=10))
    check = _csv(tmp_path / "c.csv", surface(100, seed=11))
    out = tmp_path / "o.fcl"
    args = ["learn", str(train), "--inputs", "x,y", "--target", "z", "-o", str(out), "--json"]
    assert main([*args, "--validation-data", str(check)]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["training rows"] == 100 and info["validation rows"] == 100
    assert info["validation RMSE"] == pytest.approx(
        _rmse(fuzzyctl.load(out), surface(100, seed=11)), rel=1e-9
    )
