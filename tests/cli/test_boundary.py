"""The CLI never shows a traceback: usage errors exit 2, bugs exit 3 with a short message."""

import subprocess
import sys

from fuzzyctl.cli import main


def test_version(capsys) -> None:  # type: ignore[no-untyped-def]
    assert main(["--version"]) == 0
    assert "fuzzyctl" in capsys.readouterr().out


def test_unknown_command_is_a_usage_error(capsys) -> None:  # type: ignore[no-untyped-def]
    assert main(["no-such-command"]) == 2
    err = capsys.readouterr().err
    assert "no-such-command" in err
    assert "Traceback" not in err


def test_console_script_runs() -> None:
    out = subprocess.run(
        [sys.executable, "-c", "from fuzzyctl.cli.app import run; run()", "--version"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("fuzzyctl ")
