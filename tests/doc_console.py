"""The ```console examples of README.md and docs/*.md, and how they are run (the test is
tests/test_doc_console.py; ``python -m tests.doc_console`` rewrites stale outputs).

A console block is a sequence of ``$ command`` lines, each followed by the output it prints
(stdout and stderr as a terminal shows them, then ``exit N`` when the command fails).  The
commands of one page run in order, with bash, in a scratch directory holding a copy of
examples/ and benchmarks/ (so that what one command writes, the next can read, and nothing
is written into the checkout), with this venv's ``fuzzyctl`` first on PATH and an 80-column
terminal.  ``...`` in the shown output matches anything (as in doctest), for what changes
from run to run (times, temporary paths).  Blocks fenced as ```sh are illustrations that are
not run (servers, installs)."""

from __future__ import annotations

import doctest
import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

from tests.conftest import ROOT

PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
COPIED = ("examples", "benchmarks")
TIMEOUT = 300


@dataclass(frozen=True)
class Example:
    page: Path
    line: int
    command: str
    expected: str


def examples(page: Path) -> list[Example]:
    out: list[Example] = []
    inside = False
    current: Example | None = None
    lines: list[str] = []

    def close() -> None:
        nonlocal current, lines
        if current is not None:
            out.append(Example(current.page, current.line, current.command, "\n".join(lines).rstrip("\n")))
        current, lines = None, []

    for number, text in enumerate(page.read_text(encoding="utf-8").splitlines(), start=1):
        if not inside:
            inside = text.strip() == "```console"
            continue
        if text.strip() == "```":
            close()
            inside = False
        elif text.startswith("$ "):
            close()
            current = Example(page, number, text[2:], "")
        elif current is not None:
            lines.append(text)
    return out


ALL = [e for page in PAGES for e in examples(page)]


def _command(example: Example) -> str:
    """The command without a trailing ``# comment`` (outside quotes)."""
    return re.sub(r"\s+#\s[^'\"]*$", "", example.command)


def scratch_dir(where: Path) -> Path:
    """A scratch directory with copies of what the pages' commands read."""
    for name in COPIED:
        shutil.copytree(ROOT / name, where / name, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    return where


def run(example: Example, cwd: Path) -> str:
    env = dict(os.environ)
    env.update(
        PATH=f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}",
        COLUMNS="80",
        LINES="40",
        PYTHONUNBUFFERED="1",
        NO_COLOR="1",
        TERM="dumb",
    )
    done = subprocess.run(
        ["bash", "-o", "pipefail", "-c", _command(example) + " 2>&1"],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=TIMEOUT,
        check=False,
    )
    text = "\n".join(line.rstrip() for line in (done.stdout + done.stderr).rstrip("\n").splitlines())
    if done.returncode:
        text += f"\nexit {done.returncode}"
    return text.strip("\n")


def normalised(text: str) -> str:
    return "\n".join(line.rstrip() for line in text.splitlines()).strip("\n")


def matches(example: Example, got: str) -> bool:
    return doctest.OutputChecker().check_output(
        normalised(example.expected) + "\n", got + "\n", doctest.ELLIPSIS
    )


def update(page: Path) -> int:
    """Rewrite the shown output of every console example of ``page`` that no longer matches
    (``python -m tests.doc_console [PAGE...]``); returns how many changed.  Read the diff:
    a changed number may be a regression, not a stale page."""
    import tempfile

    lines = page.read_text(encoding="utf-8").splitlines()
    changed = 0
    with tempfile.TemporaryDirectory() as tmp:
        where = scratch_dir(Path(tmp))
        results = [(e, run(e, where)) for e in examples(page)]
    for example, got in reversed(results):
        if matches(example, got):
            continue
        start = example.line  # the line after the command (1-based line of the command)
        end = start + len(example.expected.splitlines()) if example.expected else start
        lines[start:end] = got.splitlines()
        changed += 1
    if changed:
        page.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return changed


if __name__ == "__main__":
    for name in sys.argv[1:] or [str(p) for p in PAGES]:
        n = update(Path(name).resolve())
        print(f"{name}: {n} example(s) rewritten")
