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
