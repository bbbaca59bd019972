"""An FMU as the plant of a loop (``[plant] fmu = ...``), proved on a plant nobody here wrote:
the Modelica Association's Reference FMU ``StateSpace`` (FMI 3), built with CMake from
``../shared/tools/reference-fmus-src.tar.gz`` (the ``reference_fmus`` extra suite: deselected
in a bare clone without ../shared), set to G(s) = 2 / (s^2 + 3 s + 2) under the fuzzy PI
``tests/data/fmu/pi.fcl``.

The reference is python-control's simulation of the same loop (``fuzzyctl.control.iosys``
for the controller, the plant as a ``control.ss``): with the plant sampled exactly (zero-order
hold) the loops agree to 1e-3 (measured 1.1e-4 over a response spanning 1.02: StateSpace
integrates with forward Euler at its fixed 1 ms step); with the plant discretised as the FMU
does (100 Euler steps per 0.1 s cycle) to 1e-9 (measured 3e-14).

Without ../shared, an FMU exported by ``codegen --lang fmu`` (FMI 2 and 3) serves as the plant
of a PI loop, checked sample by sample against the engine.
"""

from __future__ import annotations

import json
import shutil
import zipfile
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("fmpy")
ct = pytest.importorskip("control")

import fuzzyctl  # noqa: E402
import fuzzyctl.control as fc  # noqa: E402
from fuzzyctl.cli import main  # noqa: E402
from fuzzyctl.sim.config import build_loop, load_config  # noqa: E402
from tests.conftest import data_path  # noqa: E402

#: the tests on StateSpace need the Reference FMUs' source (deselected without ../shared)
needs_reference_fmus = pytest.mark.extra("reference_fmus")

A = np.array([[0.0, 1.0], [-2.0, -3.0]])
B = np.array([[0.0], [1.0]])
C = np.array([[2.0, 0.0]])
EULER_STEP = 1e-3  # StateSpace's FIXED_SOLVER_STEP (its config.h)


@pytest.fixture(scope="session")
def statespace_fmu() -> Path:
    if shutil.which("cmake") is None:
        pytest.skip("cmake not found: the Reference FMUs are built with CMake")
    from tests.sim import reference_fmus

    return reference_fmus.build("StateSpace")


@pytest.fixture
def loop_dir(statespace_fmu: Path, tmp_path: Path) -> Path:
    for name in ("statespace.toml", "pi.fcl"):
        shutil.copy(data_path("fmu", name), tmp_path / name)
    shutil.copy(statespace_fmu, tmp_path / "StateSpace.fmu")
    return tmp_path


def reference(dt: float, n: int, method: str) -> tuple[np.ndarray, np.ndarray]:
    """y and u of the loop simulated by python-control: w = 1, e = w - y, de = backward
    difference of e (0 at the first cycle, as ddt), K the fuzzy PI, G the plant."""
    if method == "zoh":
        G = ct.ss(ct.sample_system(ct.ss(A, B, C, 0), dt, method="zoh"), inputs="u", outputs="y", name="G")
    else:  # forward Euler at the FMU's step, input held over the cycle
        steps = round(dt / EULER_STEP)
        E = np.eye(2) + EULER_STEP * A
        Ad = np.linalg.matrix_power(E, steps)
        Bd = sum(np.linalg.matrix_power(E, k) for k in range(steps)) @ (EULER_STEP * B)
        G = ct.ss(Ad, Bd, C, 0, dt, inputs="u", outputs="y", name="G")
    K = fc.iosys(
        data_path("fmu", "pi.fcl"), integrate={"du": fc.Integral(gain=0.5, low=-5, high=5)}, dt=dt, name="K"
    )
    D = ct.ss([[0.0]], [[1.0]], [[-1 / dt]], [[1 / dt]], dt, inputs="e", outputs="de", name="D")
    err = ct.summing_junction(inputs=["w", "-y"], output="e", dt=dt, name="sum")
    loop = ct.interconnect(
        [K, D, G, err],
        connections=[
            ["K.error", "sum.e"],
            ["D.e", "sum.e"],
            ["K.derror", "D.de"],
            ["G.u", "K.du"],
            ["sum.y", "G.y"],
        ],
        inplist=["sum.w"],
        outlist=["G.y", "K.du"],
        inputs="w",
        outputs=["y", "u"],
    )
    x0 = [1.0 if label.startswith("D_") else 0.0 for label in loop.state_labels]  # e(-1) = e(0) = 1
    T = np.arange(n) * dt
    y, u = ct.input_output_response(loop, T, np.ones_like(T), X0=x0).outputs
    return y, u


@needs_reference_fmus
def test_closed_loop_equals_python_control(loop_dir: Path) -> None:
    config = load_config(loop_dir / "statespace.toml")
    trace = build_loop(config).run(config.duration)
    y, u = np.asarray(trace["y"]), np.asarray(trace["u"])
    assert np.ptp(y) > 1.0 and abs(y[-1] - 1.0) < 0.01  # the loop moved and settled
    ref_y, ref_u = reference(config.cycle, len(y), "zoh")
    assert np.max(np.abs(y - ref_y)) < 1e-3  # measured 1.1e-4 (the FMU's Euler at 1 ms)
    ref_y, ref_u = reference(config.cycle, len(y), "euler")
    assert np.max(np.abs(y - ref_y)) < 1e-9  # measured 3e-14
    assert np.max(np.abs(u[:-1] - ref_u[:-1])) < 1e-9


@needs_reference_fmus
def test_reset_starts_a_new_instance(loop_dir: Path) -> None:
    loop = build_loop(load_config(loop_dir / "statespace.toml"))
    first = [loop.step()["y"] for _ in range(20)]
    loop.reset()
    again = [loop.step()["y"] for _ in range(20)]
    assert first == again and max(first) > 0.05


@needs_reference_fmus
def test_tune_improves_the_cost(loop_dir: Path) -> None:
    r = fuzzyctl.tune(
        loop_dir / "pi.fcl", plant_config=loop_dir / "statespace.toml", budget=12, workers=0, seed=0
    )
    assert r.kind == "plant"
    assert r.after < r.before


@needs_reference_fmus
def test_tune_cli(loop_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    args = ["tune", str(loop_dir / "pi.fcl"), "--plant", str(loop_dir / "statespace.toml")]
    assert main([*args, "--budget", "8", "--workers", "0", "--json", "-o", str(loop_dir / "tuned.fcl")]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["cost"]["after"] <= out["cost"]["before"]


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new))


def _model_exchange_only(src: Path, dst: Path) -> None:
    """StateSpace with its <CoSimulation> element removed: a model-exchange-only FMU."""
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "modelDescription.xml":
                text = data.decode()
                start = text.index("<CoSimulation")
                data = (text[:start] + text[text.index("/>", start) + 2 :]).encode()
            zout.writestr(item, data)


@needs_reference_fmus
@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (('fmu = "StateSpace.fmu"', 'fmu = "nope.fmu"'), "[plant] fmu 'nope.fmu': no such file"),
        (
            ('inputs = { u = "u[1]" }', 'inputs = { u = "v" }'),
            "[plant] inputs.u: 'v' is not an input of StateSpace.fmu",
        ),
        (('inputs = { u = "u[1]" }', 'inputs = { u = "u" }'), "inputs.u: 'u' of StateSpace.fmu has 3 values"),
        (
            ('outputs = { y = "y[1]" }', 'outputs = { y = "y[4]" }'),
            "outputs.y: 'y' of StateSpace.fmu has 3 values",
        ),
        (("D = [[0,", "DD = [[0,"), "StateSpace.fmu has no parameter 'DD'"),
        (
            ("D = [[0, 0, 0], [0, 0, 0], [0, 0, 0]]", "D = [[0, 0], [0, 0]]"),
            "parameter 'D' has 9 value(s), got 4",
        ),
        (('fmu = "StateSpace.fmu"', 'fmu = "StateSpace.fmu"\nmodel = "fopdt"'), "give either model or fmu"),
        (('fmu = "StateSpace.fmu"', 'fmu = "me.fmu"'), "me.fmu: the FMU is model exchange only"),
        (('fmu = "StateSpace.fmu"', 'fmu = "pi.fcl"'), "pi.fcl: not an FMU"),
    ],
)
def test_errors_name_the_file_and_the_key(
    loop_dir: Path, capsys: pytest.CaptureFixture[str], edit: tuple[str, str], message: str
) -> None:
    _model_exchange_only(loop_dir / "StateSpace.fmu", loop_dir / "me.fmu")
    toml = loop_dir / "statespace.toml"
    _edit(toml, *edit)
    assert main(["simulate", str(toml), "--json", "--no-png", "--no-html", "--no-csv"]) == 1
    err = capsys.readouterr().err
    assert message in " ".join(err.split()) and "statespace.toml" in err
    assert "Traceback" not in err


@needs_reference_fmus
def test_simulate_cli_with_an_fmu_plant(loop_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    toml = loop_dir / "statespace.toml"
    assert main(["simulate", str(toml), "--json", "--csv", str(loop_dir / "run.csv")]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["quality"]["settling_time"] < 15 and abs(out["quality"]["final_error"]) < 0.01
    header = (loop_dir / "run.csv").read_text().splitlines()[0].split(",")
    assert header[:4] == ["t", "w", "y", "u"]


@pytest.mark.parametrize("fmi", [2, 3])
def test_an_exported_fuzzy_block_as_the_plant(fmi: int, tmp_path: Path) -> None:
    """No ../shared needed: ``codegen --lang fmu`` of a static map (``saturation.fcl``, u = e
    limited to [-1, 1]) is the plant of a PI loop, FMI 2 and 3.  Each cycle the loop sets the
    input, steps and measures the next cycle, so u(k) is the engine's map of e(k - 1)."""
    from fuzzyctl.codegen.fmu import generate_fmu
    from fuzzyctl.engine.native import compiler

    if compiler() is None:
        pytest.skip("no C compiler for the FMU's binary")
    model = fuzzyctl.load(data_path("control", "saturation.fcl"))
    generate_fmu(model, tmp_path / "sat.fmu", fmi=fmi)
    (tmp_path / "loop.toml").write_text(
        'duration = 8\n[plant]\nfmu = "sat.fmu"\n'
        '[controller]\nstructure = "pid"\nsetpoint = "w"\nmeasurement = "u"\ndrive = "e"\ncycle = 0.1\n'
        "[controller.pid]\nkp = 0.5\nti = 0.4\n[setpoints]\nw = { steps = [[0, 1.5], [2, 0.5]] }\n"
    )
    config = load_config(tmp_path / "loop.toml")
    trace = build_loop(config).run(config.duration)
    e, u = np.asarray(trace["e"]), np.asarray(trace["u"])
    assert {"ENABLE", "INFO"} <= set(trace.names)  # every FMU input and output, by default
    ctl = fuzzyctl.compile(model, out_of_range="ignore")
    expected = [0.0] + [ctl.evaluate({"e": float(x)})["u"] for x in e[:-1]]
    assert np.max(np.abs(u - expected)) < 1e-12
    assert np.max(u) == pytest.approx(1.0) and np.max(e) > 1.5  # held at the limit (w = 1.5)
    assert abs(u[-1] - 0.5) < 0.01  # then settled at w = 0.5
