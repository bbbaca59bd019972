"""``codegen --lang fmu``: the FMU is valid for FMPy (FMI 2 and 3), FMPy's simulation of it
gives the engine's outputs (within 1e-9 of each output's range on a test signal), its tunable
parameters change what it computes as the same change in the model does, its sources compile
on their own, and the command's errors are messages."""

from __future__ import annotations

import re
import subprocess
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")

import fuzzyctl  # noqa: E402
from fuzzyctl.cli import main  # noqa: E402
from fuzzyctl.codegen.fmu import generate_fmu  # noqa: E402
from fuzzyctl.engine.native import compiler  # noqa: E402
from fuzzyctl.escape import CodegenError  # noqa: E402
from fuzzyctl.fcl import load_text  # noqa: E402
from tests.conftest import EXAMPLES  # noqa: E402

pytestmark = pytest.mark.skipif(compiler() is None, reason="no C compiler (cc or $CC) for the FMU's binary")

SYSTEMS = ["tank.fcl", "figure7.fcl", "crane.fcl", "pendulum.fcl"]


def hull(fmu: Path, var: str) -> tuple[float, float]:
    """The span of a variable's term points (its ``FZ_var_X`` / ``FZ_var_S`` parameters)."""
    md = fmpy.read_model_description(str(fmu))
    xs = [float(v.start) for v in md.modelVariables if v.name.startswith((f"FZ_{var}_X[", f"FZ_{var}_S["))]
    return (min(xs), max(xs)) if xs else (-1.0, 1.0)


def signal(ctl: fuzzyctl.engine.controller.Controller, fmu: Path, n: int = 400) -> np.ndarray:
    """Each input swept over 1.2 x its terms' span by a sine of its own frequency."""
    t = np.arange(n) * 0.01
    cols = [("time", t)]
    for k, name in enumerate(ctl.inputs):
        lo, hi = hull(fmu, name)
        mid, half = (lo + hi) / 2, 0.6 * (hi - lo)
        cols.append((name, mid + half * np.sin(2 * np.pi * t * (0.7 + 0.37 * k))))
    return np.array(list(zip(*(c for _, c in cols), strict=True)), dtype=[(n, float) for n, _ in cols])


@pytest.mark.parametrize("fmi", [2, 3])
@pytest.mark.parametrize("name", SYSTEMS)
def test_valid_and_equal_to_the_engine(name: str, fmi: int, tmp_path: Path) -> None:
    model = fuzzyctl.load(EXAMPLES / name)
    out = generate_fmu(model, tmp_path / "b.fmu", fmi=fmi)
    from fmpy.validation import validate_fmu

    assert validate_fmu(str(out.path)) == []
    ctl = fuzzyctl.compile(model, out_of_range="ignore")
    sig = signal(ctl, out.path)
    ins, outs = list(ctl.inputs), list(ctl.outputs)
    res = fmpy.simulate_fmu(
        str(out.path), input=sig, output=[*ins, *outs, "INFO"], step_size=0.01,
        stop_time=float(sig["time"][-1]), output_interval=0.01,
    )  # fmt: skip
    assert len(res) == len(sig)
    # the inputs the FMU computed with, row by row (FMPy interpolates the signal)
    rows = [{k: float(r[k]) for k in ins} for r in res]
    expected = [ctl.evaluate(row) for row in rows]
    for o in outs:
        lo, hi = hull(out.path, o)
        diff = np.max(np.abs(np.array([e[o] for e in expected]) - res[o]))
        assert diff <= 1e-9 * (hi - lo), (o, diff)
        assert np.ptp(res[o]) > 0.1 * (hi - lo)  # the signal moved the output


def test_description_lists_inputs_outputs_and_every_parameter(tmp_path: Path) -> None:
    out = generate_fmu(fuzzyctl.load(EXAMPLES / "figure7.fcl"), tmp_path / "f.fmu")
    md = fmpy.read_model_description(str(out.path))
    by = {v.name: v for v in md.modelVariables}
    assert by["temp"].causality == "input" and by["pressure"].causality == "input"
    assert by["valve"].causality == "output" and by["INFO"].type == "UInt8"
    assert by["ENABLE"].type == "Boolean" and by["ENABLE"].start in ("true", True)
    params = {n: v for n, v in by.items() if v.causality == "parameter"}
    assert all(v.variability == "tunable" for v in params.values())
    # 4 + 4 term points of temp and pressure (x and degree each), 3 singletons, 1 WITH weight
    assert len(params) == 2 * 4 + 2 * 4 + 3 + 1
    assert float(params["FZ_valve_S[2]"].start) == 100.0 and "inlet" in params["FZ_valve_S[2]"].description
    assert float(params["FZ_W[0]"].start) == 0.8


@pytest.mark.parametrize("fmi", [2, 3])
def test_a_tuned_parameter_is_the_changed_model(fmi: int, tmp_path: Path) -> None:
    text = (EXAMPLES / "figure7.fcl").read_text()
    out = generate_fmu(load_text(text).raise_for_errors(), tmp_path / "f.fmu", fmi=fmi)
    changed = re.sub(r"TERM inlet := 100", "TERM inlet := 50", text)
    assert changed != text
    ctl = fuzzyctl.compile(load_text(changed).raise_for_errors())
    sig = signal(ctl, out.path, 100)
    res = fmpy.simulate_fmu(
        str(out.path), input=sig, output=["temp", "pressure", "valve"], step_size=0.01,
        stop_time=float(sig["time"][-1]), start_values={"FZ_valve_S[2]": 50.0},
    )  # fmt: skip
    expected = [
        ctl.evaluate({"temp": float(r["temp"]), "pressure": float(r["pressure"])})["valve"] for r in res
    ]
    assert np.max(np.abs(np.array(expected) - res["valve"])) < 1e-9 * 200


def test_sources_compile_on_their_own(tmp_path: Path) -> None:
    out = generate_fmu(fuzzyctl.load(EXAMPLES / "tank.fcl"), tmp_path / "t.fmu", binary=False)
    assert out.binary is None
    with zipfile.ZipFile(out.path) as zf:
        names = zf.namelist()
        assert not any(n.startswith("binaries/") for n in names)
        assert "sources/LICENSE.txt" in names
        zf.extractall(tmp_path / "x")
    src = tmp_path / "x" / "sources"
    build = ET.parse(src / "buildDescription.xml").getroot()
    files = [e.get("name") for e in build.iter("SourceFile")]
    assert "tank.c" in files and "model.c" in files
    proc = subprocess.run(
        [str(compiler()), "-std=gnu99", "-c", "-DFMI_VERSION=3", f"-I{src}", *(str(src / f) for f in files)],
        cwd=tmp_path, capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr


def test_block_named_like_the_framework_is_refused() -> None:
    text = (EXAMPLES / "figure7.fcl").read_text().replace("FUNCTION_BLOCK Fuzzy_FB", "FUNCTION_BLOCK reset")
    with pytest.raises(CodegenError, match="'reset': the FMU framework uses this name"):
        generate_fmu(load_text(text).raise_for_errors(), "never.fmu", binary=False)


def test_cli(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    fmu = tmp_path / "f7.fmu"
    assert (
        main(["codegen", str(EXAMPLES / "figure7.fcl"), "--lang", "fmu", "--fmi", "2", "-o", str(fmu)]) == 0
    )
    assert "FMI 2 co-simulation, binary binaries/linux64/Fuzzy_FB.so" in capsys.readouterr().err
    assert fmpy.read_model_description(str(fmu)).fmiVersion == "2.0"
    for args, message in [
        (["--fmi", "4"], "FMI version 4: give 2 or 3"),
        (["--lreal"], "do not apply to --lang fmu"),
        (["-o", str(tmp_path)], "is a directory"),
    ]:
        assert main(["codegen", str(EXAMPLES / "figure7.fcl"), "--lang", "fmu", *args]) == 2
        assert message in capsys.readouterr().err
    text = (EXAMPLES / "figure7.fcl").read_text().replace("FUNCTION_BLOCK Fuzzy_FB", "FUNCTION_BLOCK Status")
    (tmp_path / "s.fcl").write_text(text)
    assert main(["codegen", str(tmp_path / "s.fcl"), "--lang", "fmu", "-o", str(tmp_path / "s.fmu")]) == 1
    err = capsys.readouterr().err
    assert "the FMU framework uses this name" in err and "Traceback" not in err


def test_docstring_example(monkeypatch: pytest.MonkeyPatch) -> None:
    import doctest

    import fuzzyctl.codegen.fmu as module
    from tests.conftest import ROOT

    monkeypatch.chdir(ROOT)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0


def _cmake_for_fmpy() -> str | None:
    """A cmake that FMPy's build files configure with (its CMakeLists.txt sets cache variables
    without a value, which CMake 4 reads as empty), or None."""
    import shutil

    for cmake in (shutil.which("cmake"), "/usr/bin/cmake"):
        if cmake and Path(cmake).exists():
            out = subprocess.run([cmake, "--version"], capture_output=True, text=True, check=False).stdout
            match = re.search(r"version (\d+)\.", out)
            if match and int(match.group(1)) < 4:
                return cmake
    return None


@pytest.mark.parametrize("fmi", [2, 3])
def test_fmpy_builds_the_source_fmu(fmi: int, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A source-only FMU compiled by an importer (FMPy's CMake build from buildDescription.xml
    or <SourceFiles>) simulates like the engine."""
    cmake = _cmake_for_fmpy()
    if cmake is None:
        pytest.skip("no CMake 3 for FMPy's source build")
    from fmpy.build import build_platform_binary

    monkeypatch.setenv("PATH", f"{Path(cmake).parent}:{__import__('os').environ['PATH']}")
    out = generate_fmu(fuzzyctl.load(EXAMPLES / "figure7.fcl"), tmp_path / "s.fmu", fmi=fmi, binary=False)
    with zipfile.ZipFile(out.path) as zf:
        zf.extractall(tmp_path / "u")
    (tmp_path / "b").mkdir()
    build_platform_binary(str(tmp_path / "u"), build_dir=str(tmp_path / "b"))
    signal = np.array(
        [(0.0, 10.0, 60.0, True), (0.1, 10.0, 60.0, True)],
        dtype=[("time", float), ("temp", float), ("pressure", float), ("ENABLE", bool)],
    )
    res = fmpy.simulate_fmu(
        str(tmp_path / "u"), input=signal, output=["valve"], stop_time=0.1, step_size=0.05
    )
    ctl = fuzzyctl.compile(fuzzyctl.load(EXAMPLES / "figure7.fcl"))
    assert res["valve"][-1] == pytest.approx(
        ctl.evaluate({"temp": 10.0, "pressure": 60.0})["valve"], abs=1e-12
    )


def test_no_compiler_is_a_message(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("CC", "no-such-cc")
    args = ["codegen", str(EXAMPLES / "figure7.fcl"), "--lang", "fmu", "-o", str(tmp_path / "f.fmu")]
    assert main(args) == 1
    assert "no C compiler found" in capsys.readouterr().err and not (tmp_path / "f.fmu").exists()
    assert main([*args, "--no-binary"]) == 0  # a source FMU needs none
