"""The real-world corpus (extra suite ``corpus``) and the vendored conformance FCL files: load
rate, the defects of the files that do not load, and write -> read round trips."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from fuzzyctl.fcl import load_file, load_text, write
from tests.conftest import DATA, shared_path

HERE = Path(__file__).resolve().parent.parent / "fcl"


def _rejected() -> dict[str, tuple[int, str, str]]:
    out: dict[str, tuple[int, str, str]] = {}
    with open(HERE / "rejected.tsv", encoding="utf-8") as handle:
        for row in csv.reader((line for line in handle if not line.startswith("#")), delimiter="\t"):
            out[row[0]] = (int(row[1]), row[2], row[3])
    return out


@pytest.fixture(scope="module")
def corpus() -> dict[str, object]:
    files = sorted(shared_path("corpus", "fcl").glob("*.fcl"))
    return {f.name: load_file(f) for f in files}


@pytest.mark.extra("corpus")
def test_corpus_load_rate_and_rejected_files(corpus: dict[str, object]) -> None:
    rejected = _rejected()
    loaded = [name for name, r in corpus.items() if r.ok]  # type: ignore[attr-defined]
    rate = len(loaded) / len(corpus)
    print(f"\nFCL corpus: {len(loaded)}/{len(corpus)} files load ({rate:.1%})")
    assert len(corpus) >= 240
    assert rate >= 0.95
    failed = {name for name, r in corpus.items() if not r.ok}  # type: ignore[attr-defined]
    assert failed == set(rejected), "rejected.tsv must list exactly the files that do not load"
    for name in sorted(failed):
        line, keyword, _defect = rejected[name]
        first = next(d for d in corpus[name].diagnostics if d.is_error)  # type: ignore[attr-defined]
        assert first.span is not None and first.span.line == line, (name, first.render())
        assert keyword in first.message, (name, first.message)


@pytest.mark.extra("corpus")
def test_corpus_round_trip(corpus: dict[str, object]) -> None:
    for name, result in corpus.items():
        if not result.ok:  # type: ignore[attr-defined]
            continue
        doc = result.document  # type: ignore[attr-defined]
        again = load_text(write(doc), name)
        assert again.document == doc, name


def test_conformance_fcl_files_load_and_round_trip() -> None:
    files = sorted(DATA.rglob("*.fcl"))
    assert len(files) > 90
    for f in files:
        result = load_file(f)
        assert result.ok, [d.render() for d in result.diagnostics if d.is_error]
        assert load_text(write(result.document), str(f)).document == result.document  # type: ignore[arg-type]
