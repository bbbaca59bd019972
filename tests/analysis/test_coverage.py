"""Coverage from data against a brute-force count from the engine's explain() per row."""

from __future__ import annotations

import random
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import fuzzyctl
from fuzzyctl.analysis import coverage, usage
from tests.analysis.systems import random_system
from tests.conftest import ROOT

HEATER = ROOT / "examples" / "analyze" / "heater_defects.fcl"


def brute(model: object, rows: list[dict[str, float]], epsilon: float = 0.0) -> dict[str, object]:
    """Per-rule fired/dominated/mean/max and gap rows, from explain() row by row."""
    ctl = fuzzyctl.compile(model, backend="python")
    fired: dict[str, int] = {}
    dom: dict[str, int] = {}
    total: dict[str, float] = {}
    top: dict[str, float] = {}
    gaps: dict[str, int] = {}
    for point in rows:
        ex = ctl.explain(point)
        ctl.reset()
        labels = [r.label for r in ex.rules]
        per_out: dict[str, float] = {}
        for r in ex.rules:
            for c in r.conclusions:
                per_out[c.variable] = max(per_out.get(c.variable, 0.0), r.degree)
        best_out: dict[str, float] = {}
        for r in ex.rules:
            for c in r.conclusions:
                best_out[c.variable] = max(best_out.get(c.variable, 0.0), c.degree * c.weight)
        for r, label in zip(ex.rules, labels, strict=True):
            f = r.degree >= epsilon if epsilon > 0 else r.degree > 0
            fired[label] = fired.get(label, 0) + f
            total[label] = total.get(label, 0.0) + r.degree
            top[label] = max(top.get(label, 0.0), r.degree)
            d = f and any(r.degree >= per_out[c.variable] for c in r.conclusions)
            dom[label] = dom.get(label, 0) + d
        for o in ctl.outputs:
            b = best_out.get(o, 0.0)
            gaps[o] = gaps.get(o, 0) + (not (b >= epsilon if epsilon > 0 else b > 0))
    n = len(rows)
    return {
        "fired": fired,
        "dominated": dom,
        "mean": {k: v / n for k, v in total.items()},
        "max": top,
        "gaps": gaps,
    }


def write_csv(path: Path, rows: list[dict[str, float]], prefix: str = "") -> Path:
    names = list(rows[0])
    lines = [",".join(["t"] + [prefix + n for n in names])]
    lines += [",".join([str(i)] + [repr(r[n]) for n in names]) for i, r in enumerate(rows)]
    path.write_text("\n".join(lines) + "\n")
    return path


def check(cov: usage.Coverage, ref: dict[str, object], n: int) -> None:
    assert cov.rows == n
    for r in cov.rules:
        label = r.rule.split(".")[-1]
        assert r.fired == ref["fired"][label], r.rule  # type: ignore[index]
        assert r.dominated == ref["dominated"][label], r.rule  # type: ignore[index]
        assert abs(r.total / n - ref["mean"][label]) < 1e-9  # type: ignore[index]
        assert abs(r.max_degree - ref["max"][label]) < 1e-9  # type: ignore[index]
    assert cov.gap_rows == ref["gaps"]


def points(doc: fuzzyctl.model.Document, n: int, seed: int) -> list[dict[str, float]]:
    from fuzzyctl.analysis import analyze

    rng = random.Random(seed)
    a = analyze(doc, surface=False)
    return [{k: rng.uniform(lo - 1, hi + 1) for k, (lo, hi) in a.inputs.items()} for _ in range(n)]


@pytest.mark.parametrize("seed", range(6))
def test_counts_match_explain_on_random_systems(seed: int, tmp_path: Path) -> None:
    doc = fuzzyctl.load(random_system(seed))
    rows = points(doc, 150, seed)
    for eps in (0.0, 0.3):
        cov = coverage(doc, write_csv(tmp_path / "log.csv", rows), epsilon=eps)
        check(cov, brute(doc, rows, eps), len(rows))


def test_known_gap_rows_csv_parquet_and_glob(tmp_path: Path) -> None:
    doc = fuzzyctl.load(HEATER)
    rows = [{"temp": 30.0, "flow": f} for f in (0.0, 2.5, 5.0)]  # temp = 30: the gap
    rows += [{"temp": 15.0, "flow": 1.0}, {"temp": 60.0, "flow": 1.0}]  # 60: outside RANGE
    cov = coverage(doc, write_csv(tmp_path / "a.csv", rows))
    assert cov.gap_rows == {"valve": 3}
    assert cov.out_of_range == {"temp": 1, "flow": 0}
    assert "7" in cov.never_fired
    check(cov, brute(doc, rows), len(rows))
    table = pa.table({"ctl.temp": [r["temp"] for r in rows], "ctl.flow": [r["flow"] for r in rows]})
    pq.write_table(table, tmp_path / "b.parquet")
    cov_pq = coverage(doc, tmp_path / "b.parquet")
    assert cov_pq.to_json()["rules"] == cov.to_json()["rules"]
    both = coverage(doc, str(tmp_path / "*.*"))
    assert both.rows == 2 * len(rows) and both.gap_rows == {"valve": 6}
    assert [r.fired for r in both.rules] == [2 * r.fired for r in cov.rules]


def test_missing_column_is_a_clear_error(tmp_path: Path) -> None:
    from fuzzyctl.diagnostics import FuzzyctlError

    p = tmp_path / "x.csv"
    p.write_text("temp,speed\n1,2\n")
    with pytest.raises(FuzzyctlError, match="flow"):
        coverage(fuzzyctl.load(HEATER), p)


def test_simulate_trace_and_eval_output_are_accepted(tmp_path: Path) -> None:
    """A ``fuzzyctl simulate`` CSV (controller inputs as fb.NAME beside the plant's signals)
    and an ``eval --data`` output (inputs as NAME, outputs appended), made by the commands."""
    import csv

    from fuzzyctl.cli.app import main

    assert (
        main(
            ["simulate", str(ROOT / "examples" / "crane.toml"), "-o", str(tmp_path), "--no-png", "--no-html"]
        )
        == 0
    )
    trace = tmp_path / "crane.csv"
    with trace.open() as fh:
        table = list(csv.DictReader(fh))
    doc = fuzzyctl.load(ROOT / "examples" / "crane.fcl")
    rows = [{"distance": float(r["fb.distance"]), "angle": float(r["fb.angle"])} for r in table]
    cov = coverage(doc, trace)
    assert cov.columns == {"distance": "fb.distance", "angle": "fb.angle"}
    check(cov, brute(doc, rows), len(rows))
    # eval --data writes the inputs back under their own names, then the outputs
    src = write_csv(tmp_path / "in.csv", rows[:40])
    out = tmp_path / "evaluated.csv"
    assert main(["eval", str(ROOT / "examples" / "crane.fcl"), "--data", str(src), "-o", str(out)]) == 0
    cov = coverage(doc, out)
    assert cov.columns == {"distance": "distance", "angle": "angle"}
    check(cov, brute(doc, rows[:40]), 40)


def test_cli_json_table_and_plots(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """analyze --data --json adds "coverage" and keeps the other keys; --plot writes one map
    per input pair and the coverage chart."""
    import json

    from fuzzyctl.analysis import analyze
    from fuzzyctl.cli.app import main

    doc = fuzzyctl.load(HEATER)
    rows = [{"temp": 30.0, "flow": 1.0}, {"temp": 15.0, "flow": 1.0}]
    log = write_csv(tmp_path / "log.csv", rows)
    assert main(["analyze", str(HEATER), "--data", str(log), "--json", "--plot", str(tmp_path / "png")]) == 0
    obj = json.loads(capsys.readouterr().out)
    plain = analyze(doc).to_json()
    assert {k: obj[k] for k in plain} == json.loads(json.dumps(plain))
    assert obj["coverage"]["rows"] == 2 and obj["coverage"]["gap_rows"] == {"valve": 1}
    assert sorted(p.name for p in (tmp_path / "png").iterdir()) == ["coverage.png", "map_temp_flow.png"]


THREE = """\
FUNCTION_BLOCK three
VAR_INPUT a : REAL; b : REAL; c : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY a TERM l := (0, 1) (10, 0); TERM h := (0, 0) (10, 1); RANGE := (0 .. 10); END_FUZZIFY
FUZZIFY b TERM l := (0, 1) (6, 0); TERM h := (0, 0) (10, 1); RANGE := (0 .. 10); END_FUZZIFY
FUZZIFY c TERM l := (0, 1) (4, 0); TERM h := (6, 0) (10, 1); RANGE := (0 .. 10); END_FUZZIFY
DEFUZZIFY y TERM n := 0; TERM p := 1; METHOD : CoGS; DEFAULT := 0; END_DEFUZZIFY
RULEBLOCK r
  AND : MIN;
  RULE 1 : IF a IS l AND c IS l THEN y IS n;
  RULE 2 : IF a IS h AND c IS h THEN y IS p;
  RULE 3 : IF b IS l THEN y IS n;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def test_pair_maps_one_per_pair(tmp_path: Path) -> None:
    from fuzzyctl.analysis import analyze, plots

    doc = fuzzyctl.load(THREE)
    a = analyze(doc, surface=False)
    files = plots.pair_maps(doc, a, tmp_path)
    assert sorted(f.name for f in files) == ["map_a_b.png", "map_a_c.png", "map_b_c.png"]
    assert all(f.stat().st_size > 1000 for f in files)
    assert all(f.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for f in files)


CHECKED = """\
FUNCTION_BLOCK h
VAR_INPUT t : REAL; END_VAR
VAR_OUTPUT v : REAL; END_VAR
FUZZIFY t
  TERM lo := (0, 1) (10, 0);
  TERM hi := (20, 0) (30, 1);
  RANGE := (0 .. 30);
END_FUZZIFY
DEFUZZIFY v
  TERM a := 0; TERM b := 1;
  METHOD : CoGS; DEFAULT := 0;
END_DEFUZZIFY
RULEBLOCK r
  AND : MIN;
  RULE 1 : IF t IS lo THEN v IS a;
  RULE 2 : IF t IS hi THEN v IS b;
  RULE 3 : IF t IS lo AND t IS hi THEN v IS b;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def test_check_analyze_at_file_line_and_strict(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A gap (10 < t < 20) at the output's line 3, the dead rule 3 at line 17; warnings
    (exit 0), errors under --strict (exit 1), and in --json."""
    import json

    from fuzzyctl.cli.app import main

    f = tmp_path / "h.fcl"
    f.write_text(CHECKED)
    assert main(["check", str(f), "--analyze"]) == 0
    err = capsys.readouterr().err
    assert f"{f}:3:" in err and "warning: gap" in err
    assert f"{f}:17:" in err and "warning: dead rule: rule 3" in err
    assert main(["check", str(f), "--analyze", "--strict"]) == 1
    err = capsys.readouterr().err
    assert "error: gap" in err and "error: dead rule" in err
    assert main(["check", str(f), "--analyze", "--json"]) == 0
    diags = json.loads(capsys.readouterr().out)["diagnostics"]
    assert {(d["code"], d["line"]) for d in diags} >= {("analyze-gap", 3), ("analyze-dead", 17)}
    assert main(["check", str(f)]) == 0
    assert "gap" not in capsys.readouterr().err
