"""``fuzzyctl eval --data``: CSV and Parquet in and out, streamed, every column kept.

Expected outputs come from the hand calculation of figure 7 (tests/cli/test_run.py) or from
the scalar path evaluated row by row (the data path runs the numpy batch path), never from
a run of the command itself."""

from __future__ import annotations

import csv
import io
import json
import math
import os
import stat
import sys
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import fuzzyctl
from fuzzyctl.cli import main
from fuzzyctl.engine.controller import InvalidRowsWarning
from tests.conftest import EXAMPLES

FIG7 = str(EXAMPLES / "figure7.fcl")
FIG7_10_60 = (100 * 17 / 24 - 100 / 8) / (17 / 24 + 7 / 24 + 1 / 8)


def _rows(text: str, delimiter: str = ",") -> list[list[str]]:
    return list(csv.reader(io.StringIO(text), delimiter=delimiter))


def _scalar(temp: float, pressure: float) -> float:
    return fuzzyctl.compile(fuzzyctl.load(FIG7)).evaluate(temp=temp, pressure=pressure)["valve"]


def test_columns_that_are_not_inputs_pass_through_unchanged(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src = tmp_path / "log.csv"
    src.write_text(
        "time,temp,note,pressure\n2024-01-01T00:00:00.000Z,10,ok,60\n2024-01-01T00:00:01.5Z,15.50,,50\n"
    )
    assert main(["eval", FIG7, "--data", str(src)]) == 0
    rows = _rows(capsys.readouterr().out)
    assert rows[0] == ["time", "temp", "note", "pressure", "valve"]
    assert rows[1][:4] == ["2024-01-01T00:00:00.000Z", "10", "ok", "60"]
    assert rows[2][:4] == ["2024-01-01T00:00:01.5Z", "15.50", "", "50"]  # text kept as written
    assert float(rows[1][4]) == pytest.approx(FIG7_10_60, abs=1e-12)
    assert float(rows[2][4]) == _scalar(15.5, 50.0)


def test_semicolon_is_detected_and_kept_and_decimal_comma(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src = tmp_path / "eu.csv"
    src.write_text("temp;pressure\n10;60\n12,5;55,25\n")
    assert main(["eval", FIG7, "--data", str(src), "--decimal", ","]) == 0
    rows = _rows(capsys.readouterr().out, ";")
    assert rows[0] == ["temp", "pressure", "valve"]
    assert rows[2][:2] == ["12,5", "55,25"]
    assert float(rows[1][2]) == pytest.approx(FIG7_10_60, abs=1e-12)
    assert float(rows[2][2]) == _scalar(12.5, 55.25)


def test_explicit_delimiter_tab(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = tmp_path / "t.tsv"
    src.write_text("temp\tpressure\n10\t60\n")
    assert main(["eval", FIG7, "--data", str(src), "--delimiter", "tab"]) == 0
    assert float(_rows(capsys.readouterr().out, "\t")[1][2]) == pytest.approx(FIG7_10_60, abs=1e-12)
    assert main(["eval", FIG7, "--data", str(src), "--delimiter", ";;"]) == 1
    assert "one character" in capsys.readouterr().err


def test_stdin_and_stdout(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(b"temp,pressure\n10,60\n")))
    assert main(["eval", FIG7, "--data", "-", "-o", "-"]) == 0
    assert float(_rows(capsys.readouterr().out)[1][2]) == pytest.approx(FIG7_10_60, abs=1e-12)


def test_json_with_data_writes_json_lines(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = tmp_path / "in.csv"
    src.write_text("id,temp,pressure\na,10,60\nb,,60\n")
    assert main(["eval", FIG7, "--data", str(src), "--json"]) == 0
    out = capsys.readouterr()
    lines = [json.loads(line) for line in out.out.splitlines()]
    assert lines[0]["id"] == "a" and lines[0]["valve"] == pytest.approx(FIG7_10_60, abs=1e-12)
    assert lines[1]["valve"] is None  # JSON has no NaN; the warning says why
    assert "1 of 2 rows" in out.err
    target = tmp_path / "out.jsonl"
    assert main(["eval", FIG7, "--data", str(src), "-o", str(target)]) == 0
    assert json.loads(target.read_text().splitlines()[0])["id"] == "a"


def test_nan_and_empty_cells_give_nan_rows_with_a_count_or_stop(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src = tmp_path / "gaps.csv"
    src.write_text("temp,pressure\n10,60\n,60\n20,nan\n10,inf\n10,60\n")
    assert main(["eval", FIG7, "--data", str(src)]) == 0
    out = capsys.readouterr()
    values = [r[2] for r in _rows(out.out)[1:]]
    assert values[1:4] == ["nan", "nan", "nan"]
    assert float(values[0]) == float(values[4]) == pytest.approx(FIG7_10_60, abs=1e-12)
    assert "3 of 5 rows have an empty, NaN or infinite input" in out.err
    assert main(["eval", FIG7, "--data", str(src), "--on-error", "fail", "-o", str(tmp_path / "o.csv")]) == 1
    err = capsys.readouterr().err
    assert "gaps.csv:3: column 1 ('temp'): empty" in err
    assert not (tmp_path / "o.csv").exists()


def test_text_that_is_not_a_number_always_stops_with_its_place(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src = tmp_path / "bad.csv"
    src.write_text("time,temp,pressure\nt0,10,60\nt1,12,high\n")
    assert main(["eval", FIG7, "--data", str(src)]) == 1
    assert "bad.csv:3: column 3 ('pressure'): 'high' is not a number" in capsys.readouterr().err
    src.write_text("temp,pressure\n10,60\n11\n")
    assert main(["eval", FIG7, "--data", str(src)]) == 1
    assert "bad.csv:3: 1 cells, expected 2" in capsys.readouterr().err


def test_a_missing_input_column_points_at_a_near_miss(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src = tmp_path / "typo.csv"
    src.write_text("temp,presure\n10,60\n")
    assert main(["eval", FIG7, "--data", str(src)]) == 1
    assert "no column for input 'pressure' (is column 'presure' it?)" in capsys.readouterr().err


def test_unknown_set_name_is_reported_before_a_missing_one(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["eval", FIG7, "--set", "temp=10", "--set", "presure=60"]) == 1
    assert "unknown input 'presure' (did you mean 'pressure'?)" in capsys.readouterr().err


def test_parquet_in_and_out(tmp_path: Path) -> None:
    src = tmp_path / "in.parquet"
    pq.write_table(
        pa.table(
            {"t": pa.array([1, 2, 3], pa.int64()), "temp": [10.0, 12.5, None], "pressure": [60, 55, 60]}
        ),
        src,
    )
    out = tmp_path / "out.parquet"
    assert main(["eval", FIG7, "--data", str(src), "-o", str(out)]) == 0
    table = pq.read_table(out)
    assert table.column_names == ["t", "temp", "pressure", "valve"]
    assert table.column("t").to_pylist() == [1, 2, 3]  # types kept too
    valve = table.column("valve").to_pylist()
    assert valve[0] == pytest.approx(FIG7_10_60, abs=1e-12)
    assert valve[1] == _scalar(12.5, 55.0)
    assert math.isnan(valve[2])


def test_a_column_named_like_an_output_is_kept(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = tmp_path / "logged.csv"
    src.write_text("temp,pressure,valve\n10,60,49.5\n")
    assert main(["eval", FIG7, "--data", str(src)]) == 0
    rows = _rows(capsys.readouterr().out)
    assert rows[0] == ["temp", "pressure", "valve", "valve_computed"]
    assert rows[1][2] == "49.5" and float(rows[1][3]) == pytest.approx(FIG7_10_60, abs=1e-12)


def test_cells_with_the_delimiter_are_quoted(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = tmp_path / "q.csv"
    src.write_text('note,temp,pressure\n"a, b",10,60\n"say ""hi""",10,60\n')
    assert main(["eval", FIG7, "--data", str(src)]) == 0
    rows = _rows(capsys.readouterr().out)
    assert [r[0] for r in rows[1:]] == ["a, b", 'say "hi"']


def test_many_rows_in_several_batches_keep_order_and_state(tmp_path: Path) -> None:
    """More rows than one read block: order, row numbers in messages and the NC state that
    carries from row to row all survive the batching."""
    from fuzzyctl.tables import BLOCK_BYTES

    rng = np.random.default_rng(3)
    n = BLOCK_BYTES // 20 * 3
    temp, pressure = rng.uniform(0, 30, n).round(3), rng.uniform(0, 100, n).round(3)
    src = tmp_path / "big.csv"
    src.write_text("temp,pressure\n" + "".join(f"{a},{b}\n" for a, b in zip(temp, pressure, strict=True)))
    out = tmp_path / "out.csv"
    assert main(["eval", FIG7, "--data", str(src), "-o", str(out)]) == 0
    got = np.loadtxt(out, delimiter=",", skiprows=1)
    want = fuzzyctl.compile(fuzzyctl.load(FIG7), backend="interpreted")
    for i in rng.choice(n, 200, replace=False):
        assert got[i, 2] == pytest.approx(
            want.evaluate(temp=temp[i], pressure=pressure[i])["valve"], abs=1e-9
        )
    assert len(got) == n


def test_output_file_keeps_its_mode_or_gets_the_umask_default(tmp_path: Path) -> None:
    src = tmp_path / "in.csv"
    src.write_text("temp,pressure\n10,60\n")
    out = tmp_path / "out.csv"
    old = os.umask(0o022)
    try:
        assert main(["eval", FIG7, "--data", str(src), "-o", str(out)]) == 0
        assert stat.S_IMODE(out.stat().st_mode) == 0o644
        out.chmod(0o664)
        assert main(["eval", FIG7, "--data", str(src), "-o", str(out)]) == 0
        assert stat.S_IMODE(out.stat().st_mode) == 0o664
    finally:
        os.umask(old)


NC_SYSTEM = """
FUNCTION_BLOCK nc
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x TERM low := (0, 1) (5, 0); TERM high := (5, 0) (6, 1) (7, 0); END_FUZZIFY
DEFUZZIFY y TERM a := 10; TERM b := 20; METHOD : COGS; DEFAULT := NC; END_DEFUZZIFY
RULEBLOCK r AND : MIN; RULE 1 : IF x IS low THEN y IS a; RULE 2 : IF x IS high THEN y IS b; END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def test_evaluate_batch_can_give_nan_rows_and_keeps_the_state_over_them() -> None:
    """DEFAULT := NC: a skipped (invalid) row neither fires nor moves the kept value."""
    ctl = fuzzyctl.compile(fuzzyctl.load(NC_SYSTEM))
    x = np.array([1.0, 6.0, np.nan, 9.0, np.inf, 1.0, 9.0])
    with pytest.warns(InvalidRowsWarning, match="2 of 7 rows"):
        got = ctl.evaluate_batch({"x": x}, on_invalid="nan")["y"]
    # 1: a fires -> 10; 6: b -> 20; NaN: skipped; 9: nothing fires -> kept 20; inf: skipped;
    # 1: 10; 9: kept 10
    assert got[[0, 1, 3, 5, 6]].tolist() == [10.0, 20.0, 20.0, 10.0, 10.0]
    assert math.isnan(got[2]) and math.isnan(got[4])
    with pytest.raises(fuzzyctl.diagnostics.InputError, match="row 2"):
        ctl.evaluate_batch({"x": x})
