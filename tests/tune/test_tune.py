"""Tuning against data and against the closed loop, in this process (the Dask runs are in
test_dask.py): recovery of a known optimum, every optimiser, Ctrl-C, reports, errors."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.cli import main
from fuzzyctl.diagnostics import InputError
from fuzzyctl.tune.space import build_space
from tests.conftest import EXAMPLES


@pytest.fixture(scope="module")
def crane_data() -> dict[str, object]:
    """Samples of the crane controller as written, and a copy of it with moved terms: the
    written one is a known optimum (loss 0)."""
    fb = fuzzyctl.load(EXAMPLES / "crane.fcl").main
    rng = np.random.default_rng(0)
    d, a = rng.uniform(-6, 22, 400), rng.uniform(-18, 18, 400)
    power = fuzzyctl.compile(fb).evaluate_batch({"distance": d, "angle": a})["power"]
    space = build_space(fb, "all")
    moved = space.decode(np.clip(space.initial() + rng.normal(0, 0.04, space.size), 0, 1), digits=6)
    return {"original": fb, "moved": moved, "cols": {"distance": d, "angle": a, "power": power}}


def test_least_squares_recovers_the_known_optimum(crane_data: dict[str, object]) -> None:
    r = fuzzyctl.tune(crane_data["moved"], data=crane_data["cols"], workers=0, budget=40)
    assert r.optimizer == "lsq" and "gradient: closed form" in r.notes
    assert r.before > 1.0 and r.after < 1e-6
    # the parameters went back to the values the data came from
    original = crane_data["original"]
    assert r.block.fuzzify == original.fuzzify  # type: ignore[attr-defined]
    assert r.block.defuzzify[0].terms == original.defuzzify[0].terms  # type: ignore[attr-defined]
    assert r.evaluations < 40
    names = [row[0] for row in r.table]
    assert "training RMSE power" in names and "validation RMSE power" in names


@pytest.mark.parametrize(
    ("optimizer", "loss"), [("cmaes", "rmse"), ("de", "mae"), ("lbfgsb", "max"), ("lbfgsb", "mae")]
)
def test_every_optimizer_improves(crane_data: dict[str, object], optimizer: str, loss: str) -> None:
    r = fuzzyctl.tune(
        crane_data["moved"],
        data=crane_data["cols"],
        free="power",
        optimizer=optimizer,
        loss=loss,
        budget=40,
        workers=0,
        seed=1,
    )
    assert r.after < r.before
    assert r.evaluations <= 40
    assert [h[0] for h in r.history] == list(range(1, r.evaluations + 1))
    assert all(b2 <= b1 for (_, _, b1), (_, _, b2) in zip(r.history, r.history[1:], strict=False))


def test_finite_differences_where_the_closed_form_does_not_hold(crane_data: dict[str, object]) -> None:
    from fuzzyctl.fcl import load_text, write

    text = write(crane_data["moved"]).replace(  # type: ignore[arg-type]
        "RULE 18 : IF distance IS zero AND angle IS zero", "RULE 18 : IF distance IS zero OR angle IS zero"
    )
    r = fuzzyctl.tune(
        load_text(text).raise_for_errors(), data=crane_data["cols"], free="power", budget=25, workers=0
    )
    assert any("finite differences" in n and "OR" in n for n in r.notes)
    assert r.after < r.before


def test_ctrl_c_keeps_the_best_so_far(crane_data: dict[str, object], tmp_path: Path) -> None:
    def interrupt(done: int, total: int, best: float) -> None:
        if done == 12:
            raise KeyboardInterrupt

    r = fuzzyctl.tune(
        crane_data["moved"],
        data=crane_data["cols"],
        optimizer="cmaes",
        budget=100,
        workers=0,
        progress=interrupt,
    )
    assert r.interrupted and r.evaluations == 12
    best = min(h[1] for h in r.history)
    assert r.after == pytest.approx(min(best, r.before), rel=1e-4)  # the best, as written
    back = fuzzyctl.load(r.write_fcl(tmp_path / "best.fcl"))
    assert back.main == r.block
    if r.changes:
        assert "interrupted" in " ".join(back.main.comments)


def test_plant_tuning_and_report(loop: tuple[Path, Path], tmp_path: Path) -> None:
    fcl, toml = loop
    r = fuzzyctl.tune(fcl, plant_config=toml, budget=12, workers=0, seed=0)
    assert r.kind == "plant" and r.optimizer == "cmaes"
    assert r.after < r.before
    rows = dict((k, (b, a)) for k, b, a in r.table)
    assert set(rows) >= {"step to 1: cost", "step to 1: iae", "step to 1: max:u", "step to 0.5: cost"}
    # the total is the sum of the scenario costs (weights 1)
    assert r.after == pytest.approx(rows["step to 1: cost"][1] + rows["step to 0.5: cost"][1])
    files = r.write_report(tmp_path / "rep")
    assert {"md", "json", "cost.png", "responses.png", "html"} <= set(files)
    md = files["md"].read_text()
    assert "Changed parameters" in md and "| step to 1: iae |" in md
    assert json.loads(files["json"].read_text())["cost"]["after"] == pytest.approx(r.after)
    html = files["html"].read_text()
    assert html.count("<script") >= 1 and "plotly" in html


def test_cost_and_scenario_errors(loop: tuple[Path, Path]) -> None:
    fcl, toml = loop
    with pytest.raises(InputError, match="unknown cost term 'overshot'"):
        fuzzyctl.tune(fcl, plant_config=toml, cost="overshot=1", workers=0, budget=1)
    bad = toml.with_name("bad.toml")
    bad.write_text(toml.read_text().replace('name = "step to 1"', 'name = "step to 1"\nsetpoint = 3'))
    with pytest.raises(InputError, match=r"#1: unknown key\(s\) 'setpoint'"):
        fuzzyctl.tune(fcl, plant_config=bad, workers=0, budget=1)
    with pytest.raises(InputError, match="needs data"):
        fuzzyctl.tune(fcl, plant_config=toml, optimizer="lsq", workers=0, budget=1)
    with pytest.raises(InputError, match="either data"):
        fuzzyctl.tune(fcl, workers=0)


def test_cli_tune_data_and_errors(
    crane_data: dict[str, object], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from fuzzyctl.fcl import write

    moved = tmp_path / "moved.fcl"
    moved.write_text(write(crane_data["moved"]))  # type: ignore[arg-type]
    cols = crane_data["cols"]
    data = tmp_path / "d.csv"
    rows = np.column_stack([cols["distance"], cols["angle"], cols["power"]])  # type: ignore[index]
    data.write_text("distance,angle,power\n" + "\n".join(",".join(repr(float(v)) for v in r) for r in rows))
    out = tmp_path / "tuned.fcl"
    args = ["tune", str(moved), "--data", str(data), "-o", str(out), "--workers", "0", "--budget", "30"]
    assert main([*args, "--json", "--report", str(tmp_path / "rep")]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["cost"]["after"] < 1e-6 and (tmp_path / "rep" / "fit.png").exists()
    assert "Tuned by fuzzyctl tune (lsq" in out.read_text()
    assert main([*args, "--free", "speed"]) == 1
    assert "--free 'speed'" in capsys.readouterr().err
    assert main([*args, "--target", "force"]) == 1
    assert "not an output" in capsys.readouterr().err
    assert main(["tune", str(moved), "-o", str(out)]) == 2
    assert main([*args, "--optimizer", "pso"]) == 1
    assert "--optimizer must be one of" in capsys.readouterr().err
