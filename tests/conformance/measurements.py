"""The "conformance measurements" section of the test report (registered in tests/conftest.py,
which the xdist controller loads too).

Conformance tests report their measurements with ``record_property``: ``("report", line)``
lines are printed as they are; ``("roundtrip", "path\tcategory\tdetail")`` items are counted
per path and category (details separated by \x1f are counted one by one).  The hook prints
them after the run, so that the numbers are visible in ``make test`` without ``-s`` (also
with pytest-xdist)."""

from __future__ import annotations

from collections import Counter
from typing import Any


def pytest_terminal_summary(terminalreporter: Any) -> None:
    lines: list[str] = []
    files: Counter[tuple[str, str]] = Counter()
    details: Counter[tuple[str, str, str]] = Counter()
    for report in terminalreporter.stats.get("passed", []) + terminalreporter.stats.get("failed", []):
        if getattr(report, "when", "call") != "call":
            continue
        for name, value in getattr(report, "user_properties", ()):
            if name == "report":
                lines.append(str(value))
            elif name == "roundtrip":
                path, category, detail = str(value).split("\t", 2)
                files[(path, category)] += 1
                for item in filter(None, detail.split("\x1f")):
                    details[(path, category, item)] += 1
    if not lines and not files:
        return
    terminalreporter.section("conformance measurements")
    for line in sorted(lines):
        terminalreporter.write_line(line)
    for path in sorted({p for p, _c in files}):
        counts = ", ".join(f"{c}: {n}" for (p, c), n in sorted(files.items()) if p == path)
        terminalreporter.write_line(f"{path}: {counts}")
        for (p, category, item), n in sorted(details.items(), key=lambda kv: (kv[0][0], kv[0][1], -kv[1])):
            if p == path:
                terminalreporter.write_line(f"    {category}: {item} ({n})")
