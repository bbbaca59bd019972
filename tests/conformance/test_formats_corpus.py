"""Every .fis and .fll of the shared corpus (extra suite ``corpus``) loads, or is rejected at
its real defect; written back, it reads again to the same model (also the vendored
fuzzylite files, in every clone)."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from fuzzyctl.diagnostics import DiagnosticError
from fuzzyctl.formats import decode, get
from tests.conftest import DATA, ROOT, shared_path

REJECTED = ROOT / "tests" / "formats" / "rejected.tsv"


def _rejected() -> dict[str, tuple[int, str]]:
    lines = [line for line in REJECTED.read_text(encoding="utf-8").splitlines() if not line.startswith("#")]
    return {row["file"]: (int(row["line"]), row["code"]) for row in csv.DictReader(lines, delimiter="\t")}


def _files(kind: str) -> list[Path]:
    return sorted(shared_path("corpus", kind).glob(f"*.{kind}"))


@pytest.mark.extra("corpus")
@pytest.mark.parametrize("kind", ["fis", "fll"])
def test_load_rate_and_rejections(kind: str, record_property: pytest.RecordProperty) -> None:
    rejected = {k: v for k, v in _rejected().items() if k.startswith(f"{kind}/")}
    files = _files(kind)
    assert files, "corpus is empty"
    loaded, failures = 0, {}
    for path in files:
        try:
            get(kind).read(decode(path.read_bytes()), str(path))
            loaded += 1
        except DiagnosticError as exc:
            failures[f"{kind}/{path.name}"] = next(d for d in exc.diagnostics if d.is_error)
    well_formed = len(files) - len(rejected)
    rate = loaded / well_formed
    summary = (
        f"load rate {kind}: {loaded}/{len(files)} files load; {loaded}/{well_formed} well-formed = "
        f"{rate:.1%}; {len(failures)} rejected at their defect"
    )
    print("\n" + summary)
    record_property("report", summary)  # shown in the "conformance measurements" section
    assert rate >= 0.98
    for name, diagnostic in failures.items():
        assert name in rejected, f"{name} rejected but listed as well-formed: {diagnostic.render()}"
        line, code = rejected[name]
        assert diagnostic.code == code and diagnostic.span is not None and diagnostic.span.line == line, (
            f"{name}: expected {code} at line {line}, got {diagnostic.render()}"
        )
        # what the user sees names the file, the line and the problem
        assert f"{Path(name).name}:{line}:" in diagnostic.render() and diagnostic.message
    unexpected_loads = set(rejected) - set(failures)
    assert not unexpected_loads, f"listed as broken but loaded: {sorted(unexpected_loads)}"


@pytest.mark.parametrize("source", [pytest.param("corpus", marks=pytest.mark.extra("corpus")), "vendored"])
@pytest.mark.parametrize("kind", ["fis", "fll"])
def test_written_back_reads_to_the_same_model(kind: str, source: str) -> None:
    fmt = get(kind)
    files = _files(kind) if source == "corpus" else sorted((DATA / "fuzzylite").rglob(f"*.{kind}"))
    same = lossy = written = 0
    for path in files:
        try:
            document = fmt.read(decode(path.read_bytes()), str(path)).document
        except DiagnosticError:
            continue
        adapted, losses = fmt.adapt(document)
        if losses:
            lossy += 1
            continue
        text = fmt.write(adapted)
        again = fmt.read(text, None).document
        # The writer may say a thing differently (points that form a triangle become trimf),
        # so the model read back must write the very same text again.
        assert fmt.write(fmt.adapt(again)[0]) == text, path.name
        same += again.main == adapted.main
        written += 1
    print(
        f"\n{source} {kind} -> model -> {kind}: {written} files written and read back to the same text "
        f"({same} to an identical model), {lossy} not expressible"
    )
    assert written >= 0.95 * (written + lossy)
    assert same >= 0.9 * written
