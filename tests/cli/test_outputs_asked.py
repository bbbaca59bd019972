"""What the CLI writes: only the files asked for, with the permissions a user expects, and
tables that never cut a number short."""

from __future__ import annotations

import os
import stat
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from fuzzyctl.cli import main
from tests.conftest import EXAMPLES

CRANE = EXAMPLES / "crane.toml"


@pytest.fixture
def umask_022() -> Iterator[None]:
    old = os.umask(0o022)
    try:
        yield
    finally:
        os.umask(old)


def _quick(tmp_path: Path) -> list[str]:
    return ["simulate", str(CRANE), "--duration", "2"]


def test_simulate_json_writes_nothing_it_was_not_asked_for(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    assert main([*_quick(tmp_path), "--json", "--no-html"]) == 0
    assert '"files": {}' in capsys.readouterr().out
    assert list(tmp_path.iterdir()) == []


def test_simulate_writes_only_the_named_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    assert main([*_quick(tmp_path), "--png", "x.png", "--no-csv"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.png"]


def test_simulate_without_options_writes_all_three_here(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(_quick(tmp_path)) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["crane.csv", "crane.html", "crane.png"]
    assert "csv: crane.csv" in capsys.readouterr().out


@pytest.mark.parametrize("columns", [40, 60, 120])
def test_tables_never_cut_numbers(tmp_path: Path, columns: int) -> None:
    env = {**os.environ, "COLUMNS": str(columns), "NO_COLOR": "1"}
    fuzzyctl = str(Path(sys.executable).parent / "fuzzyctl")
    commands = [
        [
            fuzzyctl,
            "simulate",
            str(EXAMPLES / "tank.toml"),
            "--duration",
            "600",
            "--no-csv",
            "--no-png",
            "--no-html",
        ],
        [fuzzyctl, "eval", str(EXAMPLES / "figure7.fcl"), "-s", "temp=6", "-s", "pressure=85"],
        [fuzzyctl, "explain", str(EXAMPLES / "figure7.fcl"), "-s", "temp=6", "-s", "pressure=85"],
        [
            fuzzyctl,
            "eval",
            str(EXAMPLES / "figure7.fcl"),
            "--data",
            str(EXAMPLES / "figure7_inputs.csv"),
            "--table",
        ],
    ]
    for command in commands:
        done = subprocess.run(command, capture_output=True, text=True, env=env, cwd=tmp_path, check=True)
        assert "…" not in done.stdout, (command[1], columns, done.stdout)
    # the numbers are all there, if wrapped: figure 7 at (6, 85) by hand is 12.82051282...
    joined = "".join(line.strip(" │┃") for line in done.stdout.splitlines())
    assert "12.82051282" in "".join(joined.split())


def _modes(path: Path) -> int:
    return stat.S_IMODE(path.stat().st_mode)


@pytest.mark.usefixtures("umask_022")
@pytest.mark.parametrize(
    "command",
    [
        ["fmt", "{src}", "-o", "{out}"],
        ["convert", "{src}", "{out}.json"],
        ["codegen", "{src}", "--lang", "st", "-o", "{out}.st"],
        ["explain", "{src}", "-s", "temp=10", "-s", "pressure=60", "--png", "{out}.png"],
        ["eval", "{src}", "--data", "{csv}", "-o", "{out}.csv"],
    ],
    ids=lambda c: c[0],
)
def test_written_files_keep_their_mode_or_get_the_umask_default(
    command: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src = tmp_path / "figure7.fcl"
    src.write_text((EXAMPLES / "figure7.fcl").read_text())
    data = tmp_path / "in.csv"
    data.write_text("temp,pressure\n10,60\n")
    out = tmp_path / "out"
    argv = [a.format(src=src, out=out, csv=data) for a in command]
    target = Path(next(a for a in argv if a.startswith(str(out))))
    assert main(argv) == 0
    assert _modes(target) == 0o644  # a new file: 0666 & ~umask, not mkstemp's 0600
    target.chmod(0o664)
    assert main(argv) == 0
    assert _modes(target) == 0o664  # replaced: the old file's mode kept
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []  # no temp left


@pytest.mark.usefixtures("umask_022")
def test_fmt_in_place_keeps_the_mode(tmp_path: Path) -> None:
    src = tmp_path / "figure7.fcl"
    src.write_text((EXAMPLES / "figure7.fcl").read_text())
    src.chmod(0o664)
    assert main(["fmt", str(src), "-i"]) == 0
    assert _modes(src) == 0o664
