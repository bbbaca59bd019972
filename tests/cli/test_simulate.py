"""``fuzzyctl simulate``: quality figures, CSV + PNG + offline HTML, errors that name the
file and the key."""

from __future__ import annotations

import csv
import json
import shutil
from pathlib import Path

import pytest

from fuzzyctl.cli import main
from tests.conftest import EXAMPLES


def test_simulate_writes_csv_png_html_and_prints_the_figures(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    assert main(["simulate", str(EXAMPLES / "crane.toml"), "-o", str(tmp_path), "--duration", "60"]) == 0
    out = capsys.readouterr().out
    assert "ISE" in out and "settling" in out
    for ext in ("csv", "png", "html"):
        assert str(tmp_path / f"crane.{ext}") in out
    rows = list(csv.DictReader((tmp_path / "crane.csv").open()))
    assert float(rows[-1]["t"]) == pytest.approx(60.0)
    assert {"target", "position", "angle", "power", "load_position", "fb.distance", "fb.power"} <= set(
        rows[0]
    )
    # the fuzzy input is the expression of the configuration
    assert float(rows[5]["fb.distance"]) == pytest.approx(
        float(rows[5]["target"]) - float(rows[5]["position"])
    )
    assert (tmp_path / "crane.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    html = (tmp_path / "crane.html").read_text()
    # offline: plotly.js is inside the page, no script is loaded from elsewhere
    assert "Plotly.newPlot" in html and len(html) > 1_000_000
    assert _script_sources(html) == []


def _script_sources(html: str) -> list[str]:
    """The src of every <script> tag (the parser does not look inside script bodies)."""
    from html.parser import HTMLParser

    found: list[str] = []

    class Scripts(HTMLParser):
        def handle_starttag(self, tag, attrs):
            if tag == "script":
                found.extend(v or "" for k, v in attrs if k == "src")

    Scripts().feed(html)
    return found


def test_simulate_json_and_runtime_option(tmp_path: Path, capsys: pytest.CaptureFixture[str]):
    args = ["simulate", str(EXAMPLES / "crane.toml"), "--json", "--no-png", "--no-html", "--duration", "60"]
    assert main([*args, "--csv", str(tmp_path / "a.csv")]) == 0
    engine = json.loads(capsys.readouterr().out)
    assert main([*args, "--csv", str(tmp_path / "b.csv"), "-r", "siemens", "--cycle", "0.1"]) == 0
    siemens = json.loads(capsys.readouterr().out)
    assert engine["runtime"] == "engine" and siemens["runtime"] == "siemens" and siemens["cycle"] == 0.1
    assert set(engine["files"]) == {"csv"}
    assert engine["quality"]["settling_time"] < 60 and siemens["quality"]["settling_time"] < 60
    assert siemens["quality"]["ise"] == pytest.approx(engine["quality"]["ise"], rel=0.05)


def test_simulate_through_the_native_backend(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
):
    monkeypatch.setenv("FUZZYCTL_CACHE_DIR", str(tmp_path / "cache"))
    args = ["simulate", str(EXAMPLES / "crane.toml"), "--json", "--no-png", "--no-html", "--duration", "60"]
    assert main([*args, "--csv", str(tmp_path / "a.csv")]) == 0
    engine = json.loads(capsys.readouterr().out)
    assert main([*args, "--csv", str(tmp_path / "b.csv"), "-r", "native"]) == 0
    native = json.loads(capsys.readouterr().out)
    assert native["runtime"] == "native" and list((tmp_path / "cache" / "native").glob("*.so"))
    for key, value in engine["quality"].items():
        if isinstance(value, float):
            assert native["quality"][key] == pytest.approx(value, rel=1e-9, abs=1e-12), key
        else:
            assert native["quality"][key] == value, key
    # without a compiler it refuses (exit 1, a message), it does not quietly run Python
    monkeypatch.setenv("FUZZYCTL_CACHE_DIR", str(tmp_path / "empty"))
    monkeypatch.setenv("CC", str(tmp_path / "no-such-cc"))
    assert main([*args, "--csv", str(tmp_path / "c.csv"), "-r", "native"]) == 1
    assert "runtime 'native' cannot run here: no C compiler" in capsys.readouterr().err


def _broken(tmp_path: Path, old: str, new: str) -> str:
    shutil.copy(EXAMPLES / "crane.fcl", tmp_path / "crane.fcl")
    text = (EXAMPLES / "crane.toml").read_text()
    assert old in text
    path = tmp_path / "crane.toml"
    path.write_text(text.replace(old, new))
    return str(path)


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("load_mass = 25000", "load_mas = 25000", "no parameter 'load_mas'"),
        ("load_mass = 25000", "load_mass = -5", "load_mass"),
        ('runtime = "engine"', 'runtime = "plc"', "runtime must be one of"),
        ('angle = "angle"', 'angle = "angel"', "unknown signal 'angel'"),
        ('angle = "angle"', 'angle = "angle +"', "cannot read"),
        ('angle = "angle"', 'slope = "angle"', "'slope' is not an input"),
        ('file = "crane.fcl"', 'file = "nope.fcl"', "no such file"),
        ("target = 30", "target = [1, 2]", "[setpoints] target"),
        ("duration = 80", "duration = -1", "duration must be > 0"),
        ("duration = 80", "duration = 80\nspeed = 3", "unknown key(s) 'speed'"),
        ("cycle = 0.05", "cycle = 0.05\ngain = 3", "unknown key(s) 'gain'"),
        ("[setpoints]", "[setpoints\n", "crane.toml"),
    ],
)
def test_simulate_errors_name_file_and_key(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], old, new, message
):
    path = _broken(tmp_path, old, new)
    assert main(["simulate", path, "-o", str(tmp_path)]) == 1
    err = capsys.readouterr().err
    assert message in err and "crane.toml" in err
    assert "Traceback" not in err
    assert not (tmp_path / "crane.csv").exists()


def test_simulate_usage_errors(capsys: pytest.CaptureFixture[str]):
    assert main(["simulate", str(EXAMPLES / "crane.toml"), "--cycle", "0"]) == 2
    assert main(["simulate", "missing.toml"]) == 1
