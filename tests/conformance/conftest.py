"""Conformance tests report their measurements (worst errors, coverage counts) with
``record_property("report", line)``; this hook prints them after the run, so that the numbers
are visible in ``make test`` without ``-s`` (also with pytest-xdist)."""

from __future__ import annotations

from typing import Any


def pytest_terminal_summary(terminalreporter: Any) -> None:
    lines: list[str] = []
    for report in terminalreporter.stats.get("passed", []) + terminalreporter.stats.get("failed", []):
        if getattr(report, "when", "call") != "call":
            continue
        lines += [str(value) for name, value in getattr(report, "user_properties", ()) if name == "report"]
    if lines:
        terminalreporter.section("conformance measurements")
        for line in sorted(lines):
            terminalreporter.write_line(line)
