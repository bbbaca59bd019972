"""Loop configurations in TOML (``fuzzyctl simulate EXAMPLE.toml``); docs/sim.md has the
full reference.  Every error names the file and the key::

    title = "Container crane"
    duration = 90                      # s
    [plant]
    model = "crane"                    # crane | pendulum | tank | fopdt
    load_mass = 20000                  # any parameter of the model
    [controller]
    structure = "direct"               # direct | fuzzy_pi | pid | precontrol | adaptive_pid
    file = "crane.fcl"                 # relative to this file
    runtime = "engine"                 # engine | siemens | xfuz | native
    cycle = 0.05                       # s, the controller's (block's) cycle time
    inputs = { distance = "target - position", angle = "angle" }
    [setpoints]
    target = 30
    [quality]
    signal = "load_position"
    setpoint = "target"
    band = 0.1
    limits = { angle = 2 }
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fuzzyctl.diagnostics import InputError
from fuzzyctl.model import Document
from fuzzyctl.sim import profiles
from fuzzyctl.sim.integrate import make_integrator
from fuzzyctl.sim.loop import Loop
from fuzzyctl.sim.pid import PID
from fuzzyctl.sim.plant import make_plant
from fuzzyctl.sim.runtimes import RUNTIMES, FuzzyRuntime, make_runtime
from fuzzyctl.sim.structures import DirectFuzzy, FuzzyPI, GainScheduledPID, PIDLoop, PreControl, Structure

STRUCTURES = ("direct", "fuzzy_pi", "pid", "precontrol", "adaptive_pid")
_TOP = {
    "title",
    "duration",
    "seed",
    "plant",
    "controller",
    "setpoints",
    "disturbances",
    "noise",
    "integrator",
    "quality",
    "plot",
    "tune",  # cost and scenarios for fuzzyctl tune (fuzzyctl.tune.plant); simulate ignores it
}
_CONTROLLER = {
    "direct": {"inputs", "outputs"},
    "fuzzy_pi": {"inputs", "output", "drive", "gain", "low", "high", "initial"},
    "pid": {"pid", "setpoint", "measurement", "drive", "feedforward"},
    "precontrol": {"pid", "inputs", "setpoint", "measurement", "drive", "correction", "gain"},
    "adaptive_pid": {"pid", "inputs", "setpoint", "measurement", "drive", "gains", "mode"},
}
_CONTROLLER_COMMON = {"structure", "file", "block", "runtime", "cycle"}
_PID_KEYS = {"kp", "ti", "td", "n", "b", "c", "low", "high", "tt", "antiwindup", "initial_output"}


@dataclass(frozen=True)
class QualitySpec:
    """Which response the quality figures are about."""

    signal: str
    setpoint: str | float
    band: float
    limits: dict[str, float] = field(default_factory=dict)
    t_step: float = 0.0


@dataclass(frozen=True)
class SimConfig:
    """A parsed loop configuration (the TOML file's content, validated)."""

    path: Path
    title: str
    duration: float
    plant: str
    plant_parameters: dict[str, Any]
    controller: dict[str, Any]
    setpoints: dict[str, Any]
    disturbances: dict[str, Any]
    noise: dict[str, float]
    seed: int
    integrator: dict[str, Any]
    quality: QualitySpec | None
    panels: list[list[str]] | None

    @property
    def runtime(self) -> str:
        return str(self.controller.get("runtime", "engine"))

    @property
    def cycle(self) -> float:
        return float(self.controller.get("cycle", 0.01))

    @property
    def fcl_path(self) -> Path | None:
        file = self.controller.get("file")
        return None if file is None else (self.path.parent / str(file)).resolve()


def _table(data: Mapping[str, Any], key: str, path: Path) -> dict[str, Any]:
    value = data.get(key, {})
    if not isinstance(value, Mapping):
        raise InputError(f"{path}: '{key}' must be a table")
    return dict(value)


def _number(value: Any, what: str, *, positive: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InputError(f"{what} must be a number, got {value!r}")
    if positive and not value > 0:
        raise InputError(f"{what} must be > 0, got {value!r}")
    return float(value)


def _unknown(keys: Any, allowed: set[str], what: str) -> None:
    extra = sorted(set(keys) - allowed)
    if extra:
        raise InputError(
            f"{what}: unknown key(s) {', '.join(map(repr, extra))} (allowed: {', '.join(sorted(allowed))})"
        )


def _not_a_model(path: Path) -> None:
    """A fuzzy system given where a loop configuration belongs (``simulate crane.fcl``) is
    said as such, not as the TOML error its first line gives."""
    from fuzzyctl.api import require_file
    from fuzzyctl.formats import available

    require_file(path)
    suffix = path.suffix.lower()
    fmt = next((f for f in available() if suffix in f.extensions and f.name != "toml"), None)
    if fmt is not None and suffix != ".toml":
        raise InputError(
            f"{path} is a fuzzy system ({fmt.name.upper()}), not a loop configuration: simulate "
            "takes a TOML file whose [controller] names the system and whose [plant] says what it "
            "controls (docs/sim.md; examples/crane.toml runs examples/crane.fcl)"
        )


def load_config(path: str | Path) -> SimConfig:
    """Read and validate a loop configuration file."""
    path = Path(path)
    _not_a_model(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: {exc}") from None
    _unknown(data, _TOP, str(path))
    title = str(data.get("title", path.stem))
    duration = _number(data.get("duration", 60.0), f"{path}: duration", positive=True)
    seed = data.get("seed", 0)
    if not isinstance(seed, int) or isinstance(seed, bool):
        raise InputError(f"{path}: seed must be a whole number, got {seed!r}")

    plant = _table(data, "plant", path)
    model = plant.pop("model", None)
    if "fmu" in plant:
        # an FMU plant (fuzzyctl.sim.plants.fmu): its file relative to this one
        if model is not None:
            raise InputError(f"{path}: [plant] give either model or fmu, not both")
        if not isinstance(plant["fmu"], str):
            raise InputError(f'{path}: [plant] fmu must be a file name, fmu = "plant.fmu"')
        fmu = path.parent / plant["fmu"]
        if not fmu.is_file():
            raise InputError(f"{path}: [plant] fmu {plant['fmu']!r}: no such file ({fmu.resolve()})")
        model, plant["fmu"] = "fmu", str(fmu.resolve())
    if not isinstance(model, str):
        raise InputError(
            f'{path}: [plant] needs model = "crane" | "pendulum" | "tank" | "fopdt" (or fmu = "plant.fmu")'
        )

    controller = _table(data, "controller", path)
    structure = controller.get("structure", "direct")
    if structure not in STRUCTURES:
        raise InputError(
            f"{path}: [controller] structure must be one of {', '.join(STRUCTURES)}, got {structure!r}"
        )
    _unknown(controller, _CONTROLLER_COMMON | _CONTROLLER[structure], f"{path}: [controller] ({structure})")
    runtime = controller.get("runtime", "engine")
    if runtime not in RUNTIMES:
        raise InputError(
            f"{path}: [controller] runtime must be one of {', '.join(RUNTIMES)}, got {runtime!r}"
        )
    if "cycle" in controller:
        _number(controller["cycle"], f"{path}: [controller] cycle", positive=True)
    if structure != "pid" and "file" not in controller:
        raise InputError(f'{path}: [controller] needs file = "<the FCL file>" for structure {structure!r}')
    if "pid" in controller:
        pid = controller["pid"]
        if not isinstance(pid, Mapping):
            raise InputError(f"{path}: [controller.pid] must be a table")
        _unknown(pid, _PID_KEYS, f"{path}: [controller.pid]")
    elif structure in ("pid", "precontrol", "adaptive_pid"):
        raise InputError(f"{path}: structure {structure!r} needs a [controller.pid] table (kp, ti, td, ...)")

    integrator = _table(data, "integrator", path)
    _unknown(integrator, {"method", "max_step", "rtol", "atol"}, f"{path}: [integrator]")
    noise = {k: _number(v, f"{path}: [noise] {k}") for k, v in _table(data, "noise", path).items()}

    quality = None
    if "quality" in data:
        q = _table(data, "quality", path)
        _unknown(q, {"signal", "setpoint", "band", "limits", "t_step"}, f"{path}: [quality]")
        if "signal" not in q or "setpoint" not in q or "band" not in q:
            raise InputError(f"{path}: [quality] needs signal, setpoint and band")
        sp = q["setpoint"]
        if not isinstance(sp, str):
            sp = _number(sp, f"{path}: [quality] setpoint")
        limits = q.get("limits", {})
        if not isinstance(limits, Mapping):
            raise InputError(f"{path}: [quality] limits must be a table of signal = limit")
        quality = QualitySpec(
            signal=str(q["signal"]),
            setpoint=sp,
            band=_number(q["band"], f"{path}: [quality] band", positive=True),
            limits={k: _number(v, f"{path}: [quality.limits] {k}") for k, v in limits.items()},
            t_step=_number(q.get("t_step", 0.0), f"{path}: [quality] t_step"),
        )
    panels = None
    if "plot" in data:
        p = _table(data, "plot", path)
        _unknown(p, {"panels"}, f"{path}: [plot]")
        raw = p.get("panels")
        if not (
            isinstance(raw, list)
            and all(isinstance(x, list) and all(isinstance(s, str) for s in x) for x in raw)
        ):
            raise InputError(f"{path}: [plot] panels must be a list of lists of signal names")
        panels = raw

    config = SimConfig(
        path=path,
        title=title,
        duration=duration,
        plant=model,
        plant_parameters=plant,
        controller=controller,
        setpoints=_table(data, "setpoints", path),
        disturbances=_table(data, "disturbances", path),
        noise=noise,
        seed=seed,
        integrator=integrator,
        quality=quality,
        panels=panels,
    )
    # Build it and run one cycle so that every mistake (an unknown signal in an expression,
    # a fuzzy input without a value) surfaces when the file is read, not mid-run.
    try:
        build_loop(config).step()
    except InputError as exc:
        msg = str(exc)
        raise InputError(msg if msg.startswith(str(path)) else f"{path}: {msg}") from None
    return config


def _pid(config: SimConfig) -> PID:
    raw = dict(config.controller["pid"])
    where = f"{config.path}: [controller.pid]"
    if "kp" not in raw:
        raise InputError(f"{where} needs kp")
    kwargs: dict[str, Any] = {}
    for key, value in raw.items():
        if key == "antiwindup":
            kwargs[key] = str(value)
        elif key in ("ti", "high", "tt") and value == "inf":
            kwargs[key] = math.inf
        elif key == "low" and value == "-inf":
            kwargs[key] = -math.inf
        else:
            kwargs[key] = _number(value, f"{where} {key}")
    try:
        return PID(**kwargs)
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None


def build_loop(
    config: SimConfig,
    *,
    runtime: str | None = None,
    cycle: float | None = None,
    model: Document | None = None,
) -> Loop:
    """A fresh :class:`~fuzzyctl.sim.loop.Loop` for the configuration; ``runtime``/``cycle``
    override the file's, ``model`` the fuzzy controller its file holds (the studio runs the
    knowledge base being edited)."""
    path = config.path
    try:
        plant = make_plant(config.plant, config.plant_parameters)
    except InputError as exc:
        raise InputError(f"{path}: [plant] {exc}") from None
    period = cycle if cycle is not None else config.cycle
    structure = _structure(config, runtime or config.runtime, period, model)
    try:
        integrator = make_integrator(
            **{
                "name": config.integrator.get("method", "rk4"),
                **{k: v for k, v in config.integrator.items() if k != "method"},
            }
        )
        setpoints = {
            k: profiles.from_config(v, where=f"{path}: [setpoints] {k}") for k, v in config.setpoints.items()
        }
        disturbances = {
            k: profiles.from_config(v, where=f"{path}: [disturbances] {k}")
            for k, v in config.disturbances.items()
        }
        loop = Loop(
            plant,
            structure,
            period=period,
            setpoints=setpoints,
            disturbances=disturbances,
            integrator=integrator,
            noise=config.noise,
            seed=config.seed,
        )
    except InputError as exc:
        msg = str(exc)
        raise InputError(msg if msg.startswith(str(path)) else f"{path}: {msg}") from None
    return loop


def _structure(config: SimConfig, runtime: str, period: float, model: Document | None = None) -> Structure:
    path, c = config.path, config.controller
    kind = c.get("structure", "direct")
    fuzzy: FuzzyRuntime | None = None
    if kind != "pid":
        import fuzzyctl

        if model is None:
            fcl = config.fcl_path
            assert fcl is not None
            if not fcl.exists():
                raise InputError(f"{path}: [controller] file {c['file']!r}: no such file ({fcl})")
            model = fuzzyctl.load(fcl)
        fuzzy = make_runtime(model, runtime, block=c.get("block"), cycle=period)
    try:
        if kind == "direct":
            assert fuzzy is not None
            return DirectFuzzy(fuzzy, _strings(c, "inputs", path), _strings(c, "outputs", path) or None)
        if kind == "fuzzy_pi":
            assert fuzzy is not None
            return FuzzyPI(
                fuzzy,
                _strings(c, "inputs", path),
                output=_required(c, "output", path),
                drive=_required(c, "drive", path),
                gain=_number(c.get("gain", 1.0), f"{path}: [controller] gain"),
                low=_number(c.get("low", -1e300), f"{path}: [controller] low"),
                high=_number(c.get("high", 1e300), f"{path}: [controller] high"),
                initial=_number(c.get("initial", 0.0), f"{path}: [controller] initial"),
            )
        pid = _pid(config)
        common = {
            "setpoint": _required(c, "setpoint", path),
            "measurement": _required(c, "measurement", path),
            "drive": _required(c, "drive", path),
        }
        if kind == "pid":
            return PIDLoop(pid, feedforward=c.get("feedforward"), **common)
        assert fuzzy is not None
        if kind == "precontrol":
            return PreControl(
                pid,
                fuzzy,
                _strings(c, "inputs", path),
                correction=_required(c, "correction", path),
                gain=_number(c.get("gain", 1.0), f"{path}: [controller] gain"),
                **common,
            )
        gains = _strings(c, "gains", path)
        return GainScheduledPID(
            pid, fuzzy, _strings(c, "inputs", path), gains=gains, mode=str(c.get("mode", "factor")), **common
        )
    except InputError as exc:
        msg = str(exc)
        raise InputError(msg if msg.startswith(str(path)) else f"{path}: {msg}") from None


def _required(c: Mapping[str, Any], key: str, path: Path) -> str:
    value = c.get(key)
    if not isinstance(value, str):
        raise InputError(f'{path}: [controller] needs {key} = "..." (a string)')
    return value


def _strings(c: Mapping[str, Any], key: str, path: Path) -> dict[str, str]:
    value = c.get(key, {})
    if not isinstance(value, Mapping) or not all(isinstance(v, (str, int, float)) for v in value.values()):
        raise InputError(f'{path}: [controller] {key} must be a table of name = "expression"')
    return {k: str(v) for k, v in value.items()}
