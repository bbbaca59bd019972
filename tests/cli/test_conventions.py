"""One set of conventions across the commands (issue 27, points 4, 5, 7 and 8): -o/--output is
the file written, --target the column; lists as a,b or 'a b'; a wrong or old option names the
right one; a missing file is "no such file" everywhere; every command that reads a model
takes --from and reads every format; the tune extra is asked for only where it is needed."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.cli import main
from tests.conftest import EXAMPLES

CRANE = EXAMPLES / "crane.fcl"
TIPPER = EXAMPLES / "tipper.fis"


def _surface_csv(path: Path, n: int = 120) -> Path:
    rng = np.random.default_rng(3)
    x, y = rng.uniform(0, 10, n), rng.uniform(-2, 3, n)
    z = np.sin(x) + 0.3 * y
    rows = zip(x.tolist(), y.tolist(), z.tolist(), strict=True)
    path.write_text("x,y,z\n" + "".join(f"{a!r},{b!r},{c!r}\n" for a, b, c in rows))
    return path


# ------------------------------------------------------------------ 4: -o/--output, --target, lists


@pytest.mark.parametrize(
    "inputs",
    [["--inputs", "x,y"], ["--inputs", "x y"], ["--inputs", "x", "--inputs", "y"], ["--inputs", "x", "y"]],
)
def test_learn_takes_target_output_and_every_list_form(tmp_path: Path, inputs: list[str]) -> None:
    data = _surface_csv(tmp_path / "d.csv")
    out = tmp_path / "l.fcl"
    assert main(["learn", str(data), *inputs, "--target", "z", "--output", str(out)]) == 0
    # the same system as the Python API learns from the same columns
    want = fuzzyctl.learn(data, inputs=["x", "y"], output="z")
    assert fuzzyctl.load(out).blocks[0].rule_blocks == want.document.blocks[0].rule_blocks


def test_the_old_spelling_and_typos_name_the_right_option(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data, out = str(_surface_csv(tmp_path / "d.csv")), str(tmp_path / "l.fcl")
    # before: --output COLUMN -o FILE; click alone would take the last -o silently
    assert main(["learn", data, "--inputs", "x,y", "--output", "z", "-o", out]) == 2
    assert "--target" in capsys.readouterr().err
    # the case: --output FILE without the column
    assert main(["learn", data, "--inputs", "x,y", "--output", out]) == 2
    err = capsys.readouterr().err
    assert "--target" in err and "-o/--output names the file" in err
    assert main(["learn", data, "--inputs", "x,y", "--target", "z", "--ouptut", out]) == 2
    assert "--output" in capsys.readouterr().err
    # --out (the old file option) still works for a release, with a note
    assert main(["learn", data, "--inputs", "x,y", "--target", "z", "--out", out]) == 0
    assert "--out is now -o/--output" in capsys.readouterr().err and Path(out).is_file()
    assert main(["tune", str(CRANE), "--data", data, "--output", "z", "--out", out]) == 2
    assert "--target" in capsys.readouterr().err


# ------------------------------------------------------------------ 5: no such file, --from, check


MISSING = [
    ["eval", "{m}", "-s", "distance=1"],
    ["explain", "{m}", "-s", "distance=1"],
    ["check", "{m}"],
    ["fmt", "{m}"],
    ["codegen", "{m}"],
    ["convert", "{m}", "{tmp}/out.fcl"],
    ["blocks", "check", "{m}"],
    ["blocks", "siemens", "{m}", "{tmp}/s.csv"],
    ["blocks", "xfuz", "{m}", "{tmp}/s.csv"],
    ["tune", "{m}", "--data", "{tmp}/s.csv", "-o", "{tmp}/t.fcl", "--workers", "0"],
    ["simulate", "{m}"],
    ["learn", "{m}", "--inputs", "x", "--target", "z", "-o", "{tmp}/l.fcl"],
]


@pytest.mark.parametrize("argv", MISSING, ids=lambda a: " ".join(a[:2]))
@pytest.mark.parametrize("name", ["crane.fcI", "X.fiss", "gone.fcl"])
def test_a_missing_file_is_no_such_file_in_every_command(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str], name: str
) -> None:
    (tmp_path / "s.csv").write_text("x,z\n1,2\n")
    missing = tmp_path / name
    args = [a.format(m=missing, tmp=tmp_path) for a in argv]
    assert main(args) == 1
    err = capsys.readouterr().err
    assert "no such file" in err.lower() and name in err, err


def test_from_names_the_format_in_every_command_that_reads_a_model(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    odd = tmp_path / "crane.model"  # an extension no format claims
    shutil.copy(CRANE, odd)
    want = fuzzyctl.compile(CRANE).evaluate(distance=12, angle=3)["power"]
    assert main(["eval", str(odd), "--from", "fcl", "-s", "distance=12", "-s", "angle=3", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["power"] == pytest.approx(want, abs=1e-12)
    for argv in (
        ["explain", str(odd), "--from", "fcl", "-s", "distance=12", "-s", "angle=3", "--json"],
        ["check", str(odd), "--from", "fcl"],
        ["fmt", str(odd), "--from", "fcl"],
        ["codegen", str(odd), "--from", "fcl"],
        ["blocks", "check", str(odd), "--from", "fcl"],
        ["convert", str(odd), str(tmp_path / "c.json"), "--from", "fcl"],
    ):
        assert main(argv) == 0, (argv, capsys.readouterr().err)
        capsys.readouterr()


@pytest.mark.parametrize("model", ["tipper.fis", "dimmer_chained.fll", "fpltest.fpl", "xfuz_debit.xfuz"])
def test_check_reads_every_format_and_agrees_with_the_model_as_fcl(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], model: str
) -> None:
    """check X.fis checks the model: the conformance level is the one the same model has
    when converted to FCL and checked there, and the report names what it did not check."""
    assert main(["check", str(EXAMPLES / model), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["ok"] and report["not_checked"], report
    fcl = tmp_path / "as.fcl"
    assert main(["convert", "--lossy", str(EXAMPLES / model), str(fcl)]) == 0
    capsys.readouterr()
    assert main(["check", str(fcl), "--json"]) == 0
    as_fcl = json.loads(capsys.readouterr().out)
    assert as_fcl["not_checked"] == [] and as_fcl["level"] == report["level"]


def test_check_reports_a_model_error_of_another_format(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.json"
    doc = json.loads(fuzzyctl.formats.convert(fuzzyctl.load(CRANE), "json")[0])
    text = json.dumps(doc).replace('"far"', '"faraway"', 1)  # a rule now names a term that is not there
    bad.write_text(text)
    assert main(["check", str(bad)]) == 1
    assert "far" in capsys.readouterr().err


def test_simulate_given_a_model_says_it_needs_a_loop_configuration(
    capsys: pytest.CaptureFixture[str],
) -> None:
    for model in (CRANE, TIPPER):
        assert main(["simulate", str(model)]) == 1
        err = capsys.readouterr().err
        assert "not a loop configuration" in err and "TOML" in err and "Invalid statement" not in err


# ------------------------------------------------------------------ 7: the tune extra


def test_install_hint_works_from_a_clone() -> None:
    from fuzzyctl.extras import install_hint

    root = Path(fuzzyctl.__file__).resolve().parents[2]
    assert (root / "pyproject.toml").is_file()  # the tests run from a clone
    assert install_hint() == f"pip install -e '{root}[tune]'"


def test_learn_needs_no_extra_and_cmaes_asks_for_it(tmp_path: Path) -> None:
    """With cma and Dask unimportable (as after `make run` alone), learn works and tuning
    with CMA-ES names the extra with a command that works from this clone."""
    data = _surface_csv(tmp_path / "d.csv", 60)
    block = "import sys; [sys.modules.__setitem__(m, None) for m in ('cma', 'dask', 'distributed')]; "
    run = "from fuzzyctl.cli.app import main; sys.exit(main(sys.argv[1:]))"
    learn = ["learn", str(data), "--inputs", "x,y", "--target", "z", "-o", str(tmp_path / "l.fcl")]
    done = subprocess.run([sys.executable, "-c", block + run, *learn], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    tune = ["tune", str(tmp_path / "l.fcl"), "--data", str(data), "-o", str(tmp_path / "t.fcl")]
    tune += ["--optimizer", "cmaes", "--budget", "2", "--workers", "0"]
    done = subprocess.run([sys.executable, "-c", block + run, *tune], capture_output=True, text=True)
    assert done.returncode == 1, done.stderr
    assert "pip install -e '" in done.stderr and "[tune]'" in done.stderr, done.stderr


# ------------------------------------------------------------------ 8: dir(), compile(path), --table


def test_dir_lists_the_lazy_names_and_compile_takes_a_path() -> None:
    names = dir(fuzzyctl)
    assert {"load", "compile", "learn", "tune", "plot_terms", "__version__"} <= set(names)
    by_path = fuzzyctl.compile(str(CRANE)).evaluate(distance=7, angle=-2)
    assert by_path == fuzzyctl.compile(fuzzyctl.load(CRANE)).evaluate(distance=7, angle=-2)
    assert fuzzyctl.compile(CRANE).evaluate(distance=7, angle=-2) == by_path


def test_eval_table_shows_the_first_rows_and_counts_the_rest(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from fuzzyctl.cli.eval_data import TABLE_ROWS

    n = TABLE_ROWS + 13
    data = tmp_path / "d.csv"
    data.write_text("distance,angle\n" + "".join(f"{1000 + i},1\n" for i in range(n)))
    assert main(["eval", str(CRANE), "--data", str(data), "--table", "--out-of-range", "ignore"]) == 0
    out = capsys.readouterr().out
    assert [1000 + i for i in range(n) if str(1000 + i) in out] == [1000 + i for i in range(TABLE_ROWS)]
    assert f"{n - TABLE_ROWS} more not shown" in " ".join(out.split())


def test_list_values_after_one_flag_read_as_argparse_reads_them(tmp_path: Path) -> None:
    from fuzzyctl.cli.app import spread_lists

    data = str(_surface_csv(tmp_path / "d.csv", 20))
    assert spread_lists(["learn", "--inputs", "x", "y", data, "--target", "z"]) == [
        "learn", "--inputs", "x", "--inputs", "y", data, "--target", "z"
    ]  # fmt: skip
    assert spread_lists(["learn", "--json", data, "--inputs", "a", "b", "-o", "f"]) == [
        "learn", "--json", data, "--inputs", "a", "--inputs", "b", "-o", "f"
    ]  # fmt: skip
    assert spread_lists(["tune", "m.fcl", "--target", "a", "b", "--seed", "3"])[2:6] == [
        "--target", "a", "--target", "b"
    ]  # fmt: skip
    assert spread_lists(["eval", "m.fcl", "-s", "a=1", "b"]) == ["eval", "m.fcl", "-s", "a=1", "b"]
