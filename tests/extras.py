"""Extra suites: tests that read data we may not redistribute, kept outside the repository.

A user's clone has no ``../shared``; CI has it.  Tests that need it carry a marker
``@pytest.mark.extra("NAME")`` (or ``pytestmark = pytest.mark.extra("NAME")`` for a module)
and find their files with :func:`extra_path` / :func:`extra_files`, which never fail at
collection time.  When a suite's data is absent its tests are deselected (not skipped: they
did not run and the run says so), and ``make test`` ends with one line naming the suites
that ran and those that were absent.  When the data is there, a missing file inside it is a
failure, never a skip (:func:`tests.conftest.shared_path`).

``FUZZYCTL_SHARED`` points at the shared directory when it is not next to the checkout."""

from __future__ import annotations

import functools
import hashlib
import os
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parent.parent
SHARED = Path(os.environ.get("FUZZYCTL_SHARED", ROOT.parent / "shared")).resolve()


@dataclass(frozen=True)
class ExtraSuite:
    name: str
    needs: str  # path relative to SHARED whose presence enables the suite
    what: str

    @property
    def available(self) -> bool:
        return (SHARED / self.needs).exists()


EXTRA_SUITES: dict[str, ExtraSuite] = {
    s.name: s
    for s in (
        ExtraSuite(
            "corpus", "corpus", "466 real FCL/FIS/FLL files from 118 repositories (no licence to copy)"
        ),
        ExtraSuite("seeds", "seeds", "text of the IEC 61131-7, Siemens and Schneider manuals"),
        ExtraSuite("jfl_oracle", "tools/jfuzzylogic/jfl", "live jFuzzyLogic 3.3 as an oracle"),
        ExtraSuite("matiec", "tools/matiec-src.tar.gz", "matiec, the IEC 61131-3 compiler of OpenPLC"),
        ExtraSuite(
            "reference_fmus",
            "tools/reference-fmus-src.tar.gz",
            "the Modelica Association's Reference FMUs (StateSpace as an FMU plant)",
        ),
        ExtraSuite("plcopen", "tools/plcopen/tc6_xml_v201.xsd", "PLCopen TC6 XML 2.01 schema"),
        ExtraSuite("repro", "repro/README.md", "reproducers of issue 25 (some carry corpus terms)"),
    )
}

USER_PROPERTY = "extra_suite"


def suite(name: str) -> ExtraSuite:
    try:
        return EXTRA_SUITES[name]
    except KeyError:
        raise ValueError(f"unknown extra suite {name!r}; known: {', '.join(EXTRA_SUITES)}") from None


def extra_path(name: str, *parts: str) -> Path:
    """A path inside the shared directory for suite ``name`` (may not exist: use it in tests
    marked with that suite, which only run when it does)."""
    suite(name)
    return SHARED.joinpath(*parts)


def extra_files(name: str, *parts: str, pattern: str = "*", recursive: bool = False) -> list[Path]:
    """Sorted files matching ``pattern`` under SHARED/parts; [] when suite ``name`` is absent,
    so that module-level parametrisation works in a bare clone."""
    if not suite(name).available:
        return []
    root = SHARED.joinpath(*parts)
    return sorted(root.rglob(pattern) if recursive else root.glob(pattern))


def _suites_of(item: pytest.Item) -> list[str]:
    """The suites a test needs: ``@pytest.mark.extra("corpus", "jfl_oracle")`` needs both."""
    marker = item.get_closest_marker("extra")
    if marker is None:
        return []
    if not marker.args:
        raise pytest.UsageError(f"{item.nodeid}: @pytest.mark.extra takes suite names")
    return [suite(str(a)).name for a in marker.args]


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers",
        "extra(name, ...): needs data outside the repository (tests/extras.py); deselected when absent",
    )


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    keep, drop = [], []
    for item in items:
        names = _suites_of(item)
        if all(EXTRA_SUITES[name].available for name in names):
            item.user_properties.extend((USER_PROPERTY, name) for name in names)
            keep.append(item)
        else:
            drop.append(item)
    if drop:
        config.hook.pytest_deselected(items=drop)
        items[:] = keep


def summary_line(ran: Counter[str]) -> str:
    parts = []
    for s in EXTRA_SUITES.values():
        if s.available:
            parts.append(f"{s.name} ran ({ran.get(s.name, 0)} tests)")
        else:
            parts.append(f"{s.name} ABSENT (no {SHARED / s.needs})")
    return "extra suites: " + "; ".join(parts)


def _ran(terminalreporter: Any) -> Counter[str]:
    ran: Counter[str] = Counter()
    for key in ("passed", "failed", "error", "xfailed", "xpassed"):
        for report in terminalreporter.stats.get(key, []):
            if getattr(report, "when", "call") != "call":
                continue
            for prop, value in getattr(report, "user_properties", ()):
                if prop == USER_PROPERTY:
                    ran[str(value)] += 1
    return ran


def pytest_unconfigure(config: pytest.Config) -> None:
    # After pytest's own final line, so that it is the last thing `make test` prints.
    reporter = config.pluginmanager.get_plugin("terminalreporter")
    if reporter is None or hasattr(config, "workerinput"):
        return
    line = summary_line(_ran(reporter))
    reporter.write_line(line)
    absent = [s for s in EXTRA_SUITES.values() if not s.available]
    if absent:
        reporter.write_line(
            "  (absent suites need ../shared next to the checkout or FUZZYCTL_SHARED; CI has it)"
        )


DATA = ROOT / "tests" / "data"


def _label(path: Path) -> str:
    for base, name in ((DATA, "data"), (SHARED, "shared")):
        if path.is_relative_to(base):
            return f"{name}/{path.relative_to(base)}"
    return str(path)


def real_files(*kinds: str) -> list[Any]:
    """``pytest.param`` entries, one per file, for tests parametrised over single files: the
    corpus files marked as the ``corpus`` extra suite (ids ``shared/corpus/...``), then the
    vendored ones (ids ``data/...``)."""
    return [
        pytest.param(path, marks=[pytest.mark.extra("corpus")] if source == "corpus" else [], id=_label(path))
        for source in ("corpus", "vendored")
        for path in source_files(source, kinds)
    ]


#: The two sets of real files tests run over: the corpus (extra suite) and the vendored data.
SOURCE_SETS = [pytest.param("corpus", marks=pytest.mark.extra("corpus")), "vendored"]


def source_files(source: str, kinds: tuple[str, ...]) -> list[Path]:
    """Files of the given extensions in one source set (see :data:`SOURCE_SETS`), sorted by
    kind then name, byte-identical duplicates once; the corpus set leaves out files that are
    byte-identical to a vendored one (those run in every clone already)."""
    return _source_files(source, tuple(kinds))


@functools.cache
def _digest(path: Path) -> str:
    return hashlib.sha1(path.read_bytes()).hexdigest()


@functools.cache
def _source_files(source: str, kinds: tuple[str, ...]) -> list[Path]:
    if source == "corpus":
        seen = {_digest(p) for p in _source_files("vendored", kinds)}
    elif source == "vendored":
        seen = set()
    else:
        raise ValueError(f"unknown source set {source!r}")
    out: list[Path] = []
    for kind in kinds:
        if source == "corpus":
            candidates = extra_files("corpus", "corpus", kind, pattern=f"*.{kind}")
        else:
            candidates = sorted(DATA.rglob(f"*.{kind}"))
        for path in candidates:
            if _digest(path) not in seen:
                seen.add(_digest(path))
                out.append(path)
    return out
