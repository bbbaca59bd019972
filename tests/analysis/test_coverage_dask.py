"""Coverage from data on Dask: the same numbers as the serial path (itself checked against
explain() row by row in test_coverage.py), on a multi-file log, threaded and distributed."""

from __future__ import annotations

import importlib.util
import math
import random
from collections.abc import Callable
from fractions import Fraction
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import fuzzyctl
from fuzzyctl.analysis import coverage, usage
from tests.analysis.systems import random_system
from tests.analysis.test_coverage import HEATER, brute, check, points, write_csv

pytest.importorskip("dask.dataframe")
HAS_DISTRIBUTED = importlib.util.find_spec("distributed") is not None


def same(a: usage.Coverage, b: usage.Coverage) -> None:
    """Every count, and the degree sums bit for bit."""
    assert a.to_json() == b.to_json()
    assert [r.exact_total for r in a.rules] == [r.exact_total for r in b.rules]


def parquet_log(tmp_path: Path, rows: list[dict[str, float]], files: int) -> Path:
    d = tmp_path / "logs"
    d.mkdir()
    for i in range(files):
        part = rows[i::files]
        table = pa.table({"t": list(range(len(part)))} | {f"plc.{k}": [r[k] for r in part] for k in part[0]})
        pq.write_table(table, d / f"day{i:02d}.parquet", row_group_size=37)
    return d


def _recorder(seen: list[tuple[int, int]]) -> Callable[[int, int], None]:
    return lambda done, total: seen.append((done, total))


def test_exact_sums_are_correctly_rounded() -> None:
    """Against math.fsum (correctly rounded) and Fraction, tiny and subnormal values included."""
    rng = np.random.default_rng(3)
    vals = np.concatenate([rng.random(5000), rng.random(50) * 1e-300, [5e-324, 1.0, 0.0, 2.0**-1000]])
    rows = np.stack([vals, vals[::-1] ** 3])
    sums = usage.exact_sums(rows)
    for s, row in zip(sums, rows, strict=True):
        assert Fraction(s, 1 << usage.SUM_SHIFT) == sum(Fraction(float(v)) for v in row)
        assert float(Fraction(s, 1 << usage.SUM_SHIFT)) == math.fsum(row.tolist())
    # split anywhere: the parts add up to the whole
    assert [
        a + b for a, b in zip(usage.exact_sums(rows[:, :777]), usage.exact_sums(rows[:, 777:]), strict=True)
    ] == sums


@pytest.mark.parametrize("seed", range(3))
def test_threaded_equals_serial_on_a_multi_file_parquet_log(seed: int, tmp_path: Path) -> None:
    doc = fuzzyctl.load(random_system(seed))
    rows = points(doc, 400, seed)
    rows[5] = dict.fromkeys(rows[5], float("nan"))  # skipped and counted on both paths
    log = parquet_log(tmp_path, rows, 4)
    for eps in (0.0, 0.3):
        serial = coverage(doc, log, epsilon=eps)
        seen: list[tuple[int, int]] = []
        par = coverage(
            doc, str(log / "*.parquet"), epsilon=eps, dask=True, scheduler="threads", progress=_recorder(seen)
        )
        same(par, serial)
        assert par.invalid_rows == 1 and par.rows == len(rows) - 1
        assert seen and seen[-1][0] == seen[-1][1] >= 4  # at least one partition per file
        good = [r for r in rows if not math.isnan(next(iter(r.values())))]
        check(par, brute(doc, good, eps), len(good))


def test_csv_directory_with_gap_rows_and_out_of_range(tmp_path: Path) -> None:
    """The heater: temp = 30 is its gap, 60 is outside its RANGE; three CSV files."""
    doc = fuzzyctl.load(HEATER)
    rng = random.Random(1)
    rows = [
        {"temp": rng.choice([30.0, 60.0, rng.uniform(0, 50)]), "flow": rng.uniform(0, 5)} for _ in range(90)
    ]
    d = tmp_path / "csv"
    d.mkdir()
    for i in range(3):
        write_csv(d / f"part{i}.csv", rows[i * 30 : (i + 1) * 30])
    serial = coverage(doc, d)
    par = coverage(doc, d, dask=True, scheduler="sync")
    same(par, serial)
    assert par.gap_rows["valve"] == sum(r["temp"] == 30.0 for r in rows) > 0
    assert par.out_of_range["temp"] == sum(r["temp"] > 50.0 for r in rows) > 0
    assert len(par.sources) == 3


@pytest.mark.skipif(not HAS_DISTRIBUTED, reason="dask.distributed not installed")
def test_distributed_client_equals_serial(tmp_path: Path) -> None:
    from distributed import Client, LocalCluster

    doc = fuzzyctl.load(random_system(4))
    rows = points(doc, 300, 4)
    log = parquet_log(tmp_path, rows, 3)
    serial = coverage(doc, log)
    with (
        LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address="127.0.0.1:0",
        ) as cluster,
        Client(cluster) as client,
    ):
        par = coverage(doc, log, dask=True, scheduler=client)
    same(par, serial)


def test_cli_dask_json_equals_serial(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import json

    from fuzzyctl.cli.app import main

    doc = fuzzyctl.load(HEATER)
    rows = points(doc, 120, 7)
    log = parquet_log(tmp_path, rows, 3)
    assert main(["analyze", str(HEATER), "--data", str(log), "--json"]) == 0
    serial = json.loads(capsys.readouterr().out)
    assert (
        main(["analyze", str(HEATER), "--data", str(log / "*.parquet"), "--dask", "--workers", "0", "--json"])
        == 0
    )
    par = json.loads(capsys.readouterr().out)
    serial["coverage"]["sources"] = par["coverage"]["sources"]
    assert par == serial
    assert main(["analyze", str(HEATER), "--dask"]) != 0
    assert "--data" in capsys.readouterr().err


def test_missing_dask_gives_the_install_hint(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    from fuzzyctl.diagnostics import FuzzyctlError

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda n, *a: None if n == "dask" else real(n, *a))
    log = write_csv(tmp_path / "a.csv", [{"temp": 1.0, "flow": 1.0}])
    with pytest.raises(FuzzyctlError, match=r"tune extra \(dask missing\): pip install"):
        coverage(fuzzyctl.load(HEATER), log, dask=True)
