"""The figures README.md quotes for simulate and tune (issue 27, point 15): each is measured
here by the command the page names, so a change that moves one fails until the page says the
new figure, and each quoted command stays runnable."""

from __future__ import annotations

import json
import re
import shlex
import shutil
from pathlib import Path

import pytest

from fuzzyctl.cli import main
from tests.conftest import EXAMPLES, ROOT

README = (ROOT / "README.md").read_text(encoding="utf-8")


def _settling(config: Path, runtime: str, capsys: pytest.CaptureFixture[str]) -> float:
    argv = ["simulate", str(config), "--runtime", runtime, "--json", "--no-csv", "--no-png", "--no-html"]
    assert main(argv) == 0
    return float(json.loads(capsys.readouterr().out)["quality"]["settling_time"])


def test_engine_and_siemens_block_figures(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    quoted = re.search(r"settles in ([\d.]+) s\s+on the engine and ([\d.]+) s on the block", README)
    both = re.search(r"both settle in ([\d.]+) s", README)
    assert quoted and both, "README no longer quotes the crane's settling times"
    engine, block = (
        _settling(EXAMPLES / "crane.toml", "engine", capsys),
        _settling(EXAMPLES / "crane.toml", "siemens", capsys),
    )
    assert (f"{engine:.1f}", f"{block:.1f}") == quoted.groups()
    # the same crane written ACCU : NSUM (the sum the block computes): the runs agree
    shutil.copy(EXAMPLES / "crane.toml", tmp_path / "crane.toml")
    fcl = (EXAMPLES / "crane.fcl").read_text(encoding="utf-8")
    assert "ACCU : MAX" in fcl
    (tmp_path / "crane.fcl").write_text(fcl.replace("ACCU : MAX", "ACCU : NSUM"), encoding="utf-8")
    nsum = [_settling(tmp_path / "crane.toml", r, capsys) for r in ("engine", "siemens")]
    assert [f"{v:.1f}" for v in nsum] == [both.group(1)] * 2


def test_the_quoted_tune_command_runs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """README's tune command (35 s for budget 100 on two idle cores), run with a budget of 2
    in this process: the figure is a measurement, the command must keep working."""
    block = re.search(r"\$ (fuzzyctl tune examples/crane\.fcl .*?)#", README, re.S)
    assert block, "README no longer shows the crane tune command"
    argv = shlex.split(block.group(1).replace("\\\n", " "))[1:]
    assert argv[argv.index("--budget") + 1] == "100"
    assert re.search(r"--report build/crane_tune\s+# CMA-ES, 2 idle cores: 35 s", README)
    argv[argv.index("--budget") + 1] = "2"
    argv[argv.index("-o") + 1] = str(tmp_path / "crane_tuned.fcl")
    argv[argv.index("--report") + 1] = str(tmp_path / "report")
    monkeypatch.chdir(ROOT)
    assert main([*argv, "--workers", "0", "--json"]) == 0
    assert (tmp_path / "crane_tuned.fcl").is_file() and (tmp_path / "report" / "report.md").is_file()
