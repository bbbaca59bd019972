"""On Dask: the same result for the same seed whatever the number of workers, an existing
scheduler by address or DASK_SCHEDULER_ADDRESS, and partition-wise scoring of data frames
equal to the single-process path.  One LocalCluster (2 workers, 127.0.0.1) serves the whole
session (conftest.dask_client)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.cli import main
from tests.conftest import EXAMPLES
from tests.tune.conftest import surface


def _same(a: Any, b: Any) -> None:
    assert a.history == b.history
    assert a.document == b.document
    assert a.after == b.after


@pytest.mark.parametrize("optimizer", ["cmaes", "de", "lsq"])
def test_data_tuning_same_result_with_2_workers(dask_client: Any, optimizer: str) -> None:
    cols = surface(150, seed=12)
    learned = fuzzyctl.learn(cols, inputs=["x", "y"], output="z", terms=3, validation=0.0).document
    kw: dict[str, Any] = {"data": cols, "optimizer": optimizer, "budget": 16, "seed": 5}
    local = fuzzyctl.tune(learned, workers=0, **kw)
    remote = fuzzyctl.tune(learned, client=dask_client, **kw)
    assert remote.workers == 2 and local.workers == 0
    _same(local, remote)


def test_plant_tuning_same_result_with_2_workers(dask_client: Any, loop: tuple[Path, Path]) -> None:
    fcl, toml = loop
    local = fuzzyctl.tune(fcl, plant_config=toml, budget=12, seed=2, workers=0)
    remote = fuzzyctl.tune(fcl, plant_config=toml, budget=12, seed=2, client=dask_client)
    _same(local, remote)


def test_existing_scheduler_by_address_and_environment(
    dask_client: Any, monkeypatch: pytest.MonkeyPatch, loop: tuple[Path, Path]
) -> None:
    fcl, toml = loop
    address = dask_client.scheduler.address
    assert address.startswith("tcp://127.0.0.1:")
    by_option = fuzzyctl.tune(fcl, plant_config=toml, budget=6, scheduler=address)
    monkeypatch.setenv("DASK_SCHEDULER_ADDRESS", address)
    by_env = fuzzyctl.tune(fcl, plant_config=toml, budget=6)
    assert by_option.workers == by_env.workers == 2
    _same(by_option, by_env)


def test_evaluate_dataframe_equals_single_process(dask_client: Any) -> None:
    import dask.dataframe as dd
    import pandas as pd

    rng = np.random.default_rng(3)
    frame = pd.DataFrame({"distance": rng.uniform(-6, 22, 1200), "angle": rng.uniform(-18, 18, 1200)})
    frame["id"] = np.arange(len(frame))
    doc = fuzzyctl.load(EXAMPLES / "crane.fcl")
    ddf = dd.from_pandas(frame, npartitions=4)
    scored = fuzzyctl.evaluate_dataframe(ddf, doc)
    assert list(scored.columns) == ["distance", "angle", "id", "power"]
    got = dask_client.compute(scored).result().sort_values("id")
    ref = fuzzyctl.compile(doc).evaluate_batch({"distance": frame["distance"], "angle": frame["angle"]})
    assert np.array_equal(got["power"].to_numpy(), ref["power"])


def test_eval_dask_cli_writes_parquet_partitions(dask_client: Any, tmp_path: Path) -> None:
    import pandas as pd

    rng = np.random.default_rng(4)
    src = tmp_path / "logs"
    src.mkdir()
    frames = []
    for i in range(3):
        f = pd.DataFrame({"distance": rng.uniform(-6, 22, 500), "angle": rng.uniform(-18, 18, 500)})
        f["id"] = np.arange(500) + 500 * i
        f.to_parquet(src / f"day{i}.parquet")
        f.to_csv(src.parent / f"day{i}.csv", index=False)
        frames.append(f)
    whole = pd.concat(frames)
    ref = fuzzyctl.compile(fuzzyctl.load(EXAMPLES / "crane.fcl")).evaluate_batch(
        {"distance": whole["distance"], "angle": whole["angle"]}
    )["power"]
    crane = str(EXAMPLES / "crane.fcl")
    address = dask_client.scheduler.address
    assert main(["eval", crane, "--dask", str(src), "-o", str(tmp_path / "out"), "--scheduler", address]) == 0
    parts = sorted((tmp_path / "out").glob("part-*.parquet"))
    assert len(parts) == 3
    got = pd.concat(pd.read_parquet(p) for p in parts).sort_values("id")
    assert np.array_equal(got["power"].to_numpy(), ref)
    # CSV files by glob, in this process
    assert (
        main(
            [
                "eval",
                crane,
                "--dask",
                str(tmp_path / "day*.csv"),
                "-o",
                str(tmp_path / "o2"),
                "--workers",
                "0",
            ]
        )
        == 0
    )
    got = pd.concat(pd.read_parquet(p) for p in sorted((tmp_path / "o2").glob("*.parquet"))).sort_values("id")
    assert np.array_equal(got["power"].to_numpy(), ref)


def test_eval_dask_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import pandas as pd

    pd.DataFrame({"distance": [1.0], "speed": [2.0]}).to_parquet(tmp_path / "x.parquet")
    crane = str(EXAMPLES / "crane.fcl")
    out = str(tmp_path / "o")
    assert main(["eval", crane, "--dask", str(tmp_path / "*.parquet"), "-o", out, "--workers", "0"]) == 1
    assert "no column for input 'angle'" in capsys.readouterr().err
    assert main(["eval", crane, "--dask", str(tmp_path / "none*.csv"), "-o", out, "--workers", "0"]) == 1
    assert "no Parquet or CSV file" in capsys.readouterr().err
    assert main(["eval", crane, "--dask", str(tmp_path), "--workers", "0"]) == 2
    assert main(["eval", crane, "-s", "distance=1", "-s", "angle=0", "--workers", "2"]) == 2
