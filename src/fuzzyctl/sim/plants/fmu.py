"""A co-simulation FMU (FMI 2.0 or 3.0) as the plant of a loop, stepped through FMPy.

``[plant] fmu = "plant.fmu"`` in a loop configuration (docs/sim.md, "FMU plants")::

    [plant]
    fmu = "StateSpace.fmu"            # relative to the TOML file
    inputs = { u = "u" }              # loop input name = FMU input variable (default: all, same names)
    outputs = { y = "y" }             # measurement name = FMU output variable (default: all)
    n = 2                             # any other key: a parameter of the FMU (start value);
    A = [[0, 1], [-2, -3]]            # arrays as (nested) lists, row-major

Each loop cycle sets the inputs, calls ``doStep(t, period)`` and reads the outputs at the
next cycle.  An FMU variable mapped to a signal must hold one value (a scalar, or an array of
one element once the structural parameters are set).  Structural parameters of an FMI 3 FMU
are set in configuration mode, the others before initialisation.  The FMU instance is the
loop's plant state: ``Loop.reset()`` starts a new instance (the old one is freed).

FMPy is imported only here, when a loop uses an FMU (``pip install 'fuzzyctl[fmi]'``).
"""

from __future__ import annotations

import atexit
import contextlib
import math
import re
import shutil
import weakref
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

from fuzzyctl.diagnostics import InputError
from fuzzyctl.sim.integrate import Integrator
from fuzzyctl.sim.plant import Plant, Port, register

#: Keys of ``[plant]`` that are not FMU parameters.
RESERVED = ("fmu", "inputs", "outputs")
_NUMERIC = {"Real", "Integer", "Boolean", "Float64", "Float32", "Int8", "UInt8", "Int16", "UInt16",
            "Int32", "UInt32", "Int64", "UInt64"}  # fmt: skip
_EXTRACTED: dict[tuple[str, int, int], Any] = {}
_ELEMENT = re.compile(r"^(.+)\[([1-9][0-9]*)\]$")


def _quiet(env: Any, status: int, category: Any, message: Any) -> None:
    """FMI 3 log messages: kept out of the terminal; the errors come back as call failures."""


def _fmpy() -> Any:
    try:
        import fmpy
    except ModuleNotFoundError:
        raise InputError(
            "an FMU plant needs FMPy: pip install 'fuzzyctl[fmi]' (or pip install fmpy)"
        ) from None
    return fmpy


def _cleanup() -> None:
    for model in _EXTRACTED.values():
        shutil.rmtree(model.directory, ignore_errors=True)
    _EXTRACTED.clear()


atexit.register(_cleanup)


@dataclass(frozen=True)
class FmuFile:
    """An FMU read and extracted (once per process and file version)."""

    path: Path
    directory: str
    description: Any  # fmpy.model_description.ModelDescription
    fmi: int

    @property
    def variables(self) -> dict[str, Any]:
        return {v.name: v for v in self.description.modelVariables}

    def names(self, causality: str) -> list[str]:
        return [v.name for v in self.description.modelVariables if v.causality == causality]


def open_fmu(path: str | Path) -> FmuFile:
    """Read and extract a co-simulation FMU; errors name the file and what is wrong."""
    fmpy = _fmpy()
    p = Path(path)
    if not p.is_file():
        raise InputError(f"fmu {str(path)!r}: no such file")
    st = p.stat()
    key = (str(p.resolve()), st.st_mtime_ns, st.st_size)
    if key in _EXTRACTED:
        return _EXTRACTED[key]  # type: ignore[no-any-return]
    import zipfile

    if not zipfile.is_zipfile(p):
        raise InputError(f"{p}: not an FMU (an FMU is a zip archive with a modelDescription.xml)")
    try:
        md = fmpy.read_model_description(str(p), validate=False)
    except Exception as exc:  # FMPy raises bare exceptions for unreadable descriptions
        raise InputError(f"{p}: not a readable FMU: {exc}") from None
    version = 3 if md.fmiVersion.startswith("3") else 2 if md.fmiVersion == "2.0" else 0
    if version == 0:
        raise InputError(f"{p}: FMI {md.fmiVersion}: fuzzyctl steps FMI 2.0 and 3.0 FMUs")
    if md.coSimulation is None:
        kinds = "model exchange" if md.modelExchange is not None else "no co-simulation"
        raise InputError(
            f"{p}: the FMU is {kinds} only; fuzzyctl steps co-simulation FMUs (doStep with the loop's "
            "cycle): export it for co-simulation"
        )
    ident = md.coSimulation.modelIdentifier
    here = fmpy.platform_tuple if version == 3 else fmpy.platform
    if here not in _platforms(p):
        raise InputError(
            f"{p}: no binary for this platform ({here}) in binaries/ (it has: "
            f"{', '.join(_platforms(p)) or 'none'}); build {ident} for it"
        )
    directory = fmpy.extract(str(p))
    model = FmuFile(p, directory, md, version)
    _EXTRACTED[key] = model
    return model


def _platforms(path: Path) -> list[str]:
    import zipfile

    with zipfile.ZipFile(path) as zf:
        return sorted(
            {n.split("/")[1] for n in zf.namelist() if n.startswith("binaries/") and n.count("/") >= 2}
        )


def _size(var: Any, structural: Mapping[str, float], variables: Mapping[str, Any]) -> int:
    """The number of values of ``var`` (1 for a scalar): each dimension's start, or the
    structural parameter it refers to (as set, else its start value)."""
    n = 1
    for dim in getattr(var, "dimensions", None) or []:
        if dim.start is not None:
            n *= int(dim.start)
            continue
        ref = next(v for v in variables.values() if v.valueReference == dim.valueReference)
        n *= int(structural.get(ref.name, float(ref.start or 0)))
    return n


def _number(x: Any) -> float:
    """A start value as a number (FMI writes Booleans as true/false)."""
    if isinstance(x, str) and x.lower() in ("true", "false"):
        return 1.0 if x.lower() == "true" else 0.0
    return float(x)


def _flatten(value: Any) -> list[Any]:
    if isinstance(value, list | tuple):
        return [x for item in value for x in _flatten(item)]
    return [value]


class FmuState:
    """A running FMU instance (the loop's plant state)."""

    def __init__(self, slave: Any, fmi: int) -> None:
        self.slave, self.fmi = slave, fmi
        self._finalizer = weakref.finalize(self, _free, slave)


def _free(slave: Any) -> None:
    with contextlib.suppress(Exception):  # an instance that failed to start cannot terminate
        slave.terminate()
    slave.freeInstance()


@register
class FmuPlant(Plant[FmuState]):
    """A co-simulation FMU: ``inputs``/``outputs`` map loop names to FMU variables (default:
    every input/output of the FMU under its own name), ``parameters`` FMU parameter names to
    start values (numbers, booleans, lists for arrays)."""

    kind: ClassVar[str] = "fmu"
    title: ClassVar[str] = "FMU"

    def __init__(
        self,
        fmu: str | Path,
        inputs: Mapping[str, str] | None = None,
        outputs: Mapping[str, str] | None = None,
        parameters: Mapping[str, Any] | None = None,
    ) -> None:
        self.file = open_fmu(fmu)
        self.parameter_values = dict(parameters or {})
        variables = self.file.variables
        where = self.file.path.name
        self.structural = self._check_parameters(variables, where)
        self.input_map = self._mapping(inputs, "input", "inputs", variables, where)
        self.output_map = self._mapping(outputs, "output", "outputs", variables, where)
        self.inputs = tuple(self._port(n, variables[v], i, True) for n, (v, i) in self.input_map.items())  # type: ignore[misc]
        self.outputs = tuple(self._port(n, variables[v], i, False) for n, (v, i) in self.output_map.items())  # type: ignore[misc]
        # an array input is set whole: the elements no loop input drives keep their start values
        self.held = {v: self._start_values(variables[v]) for v, _ in self.input_map.values()}
        self.kind = f"FMU {where}"  # type: ignore[misc]

    @classmethod
    def configure(cls, parameters: Mapping[str, Any] | None) -> FmuPlant:
        """The plant of a ``[plant]`` table: ``fmu``, ``inputs``, ``outputs``; other keys are
        FMU parameters."""
        table = dict(parameters or {})
        fmu = table.pop("fmu", None)
        if not isinstance(fmu, str | Path):
            raise InputError('needs fmu = "<the .fmu file>"')
        maps = {}
        for key in ("inputs", "outputs"):
            value = table.pop(key, None)
            if value is not None and (
                not isinstance(value, Mapping) or not all(isinstance(v, str) for v in value.values())
            ):
                raise InputError(f'{key} must be a table of loop name = "FMU variable"')
            maps[key] = value
        return cls(fmu, maps["inputs"], maps["outputs"], table)

    @classmethod
    def parameters(cls) -> tuple[Any, ...]:
        return ()  # an FMU's parameters are in its modelDescription.xml, not fields of a class

    def replace(self, **changes: Any) -> FmuPlant:
        def names(m: Mapping[str, tuple[str, int]]) -> dict[str, str]:
            return {k: f"{v}[{i + 1}]" if self._size_of(v) > 1 else v for k, (v, i) in m.items()}

        return FmuPlant(
            self.file.path,
            names(self.input_map),
            names(self.output_map),
            {**self.parameter_values, **changes},
        )

    def _size_of(self, name: str) -> int:
        return _size(self.file.variables[name], self.structural, self.file.variables)

    # ---------------------------------------------------------------- checks

    def _check_parameters(self, variables: Mapping[str, Any], where: str) -> dict[str, float]:
        structural: dict[str, float] = {}
        for name, value in self.parameter_values.items():
            var = variables.get(name)
            if var is None or var.causality not in ("parameter", "structuralParameter"):
                known = [
                    v.name for v in variables.values() if v.causality in ("parameter", "structuralParameter")
                ]
                raise InputError(
                    f"{where} has no parameter {name!r} (parameters: {', '.join(known) or 'none'})"
                )
            if var.variability == "constant" or var.type not in _NUMERIC:
                raise InputError(f"{where}: parameter {name!r} ({var.type}, {var.variability}) cannot be set")
            for x in _flatten(value):
                bad = isinstance(x, bool) or not isinstance(x, int | float) or not math.isfinite(x)
                if bad and not (isinstance(x, bool) and var.type == "Boolean"):
                    raise InputError(f"{where}: parameter {name!r} must be numbers, got {value!r}")
            if var.causality == "structuralParameter":
                structural[name] = float(_flatten(value)[0])
        for name, value in self.parameter_values.items():
            var = variables[name]
            n = _size(var, structural, variables)
            if len(_flatten(value)) != n:
                raise InputError(f"{where}: parameter {name!r} has {n} value(s), got {len(_flatten(value))}")
        return structural

    def _mapping(
        self,
        given: Mapping[str, str] | None,
        causality: str,
        key: str,
        variables: Mapping[str, Any],
        where: str,
    ) -> dict[str, tuple[str, int]]:
        """loop name -> (FMU variable, 0-based element); ``"y[2]"`` is element 2 of array ``y``
        (1-based, as FMI's structured names count)."""
        names = [n for n in self.file.names(causality) if variables[n].type in _NUMERIC]
        mapping = dict(given) if given is not None else {n: n for n in names}
        out: dict[str, tuple[str, int]] = {}
        for loop_name, fmu_name in mapping.items():
            base, element = fmu_name, 0
            match = _ELEMENT.match(fmu_name)
            if fmu_name not in names and match and match.group(1) in names:
                base, element = match.group(1), int(match.group(2)) - 1
            if base not in names:
                raise InputError(
                    f"{key}.{loop_name}: {fmu_name!r} is not an {causality} of {where} "
                    f"({causality}s: {', '.join(names) or 'none'})"
                )
            if not loop_name.isidentifier():
                raise InputError(
                    f"{key}: the FMU {causality} {fmu_name!r} needs a loop name that is an identifier: "
                    f'{key} = {{ name = "{fmu_name}" }}'
                )
            n = _size(variables[base], self.structural, variables)
            if (base == fmu_name and n != 1) or element >= n:
                raise InputError(
                    f"{key}.{loop_name}: {base!r} of {where} has {n} values: map one element, "
                    f'"{base}[1]" .. "{base}[{n}]"'
                )
            out[loop_name] = (base, element)
        return out

    def _start_values(self, var: Any) -> list[float]:
        n = _size(var, self.structural, self.file.variables)
        raw = (
            var.start.split()
            if isinstance(var.start, str)
            else _flatten(var.start if var.start is not None else 0)
        )
        values = [_number(x) for x in raw] or [0.0]
        return (values * n)[:n] if len(values) < n else values[:n]

    def _port(self, name: str, var: Any, element: int, is_input: bool) -> Port:
        unit = var.unit or (var.declaredType.unit if var.declaredType is not None else None) or ""
        start = self._start_values(var)[element] if is_input else 0.0
        low = float(var.min) if is_input and var.min is not None else -math.inf
        high = float(var.max) if is_input and var.max is not None else math.inf
        return Port(name, unit, var.description or f"FMU {var.causality} {var.name}", start, low, high)

    # ---------------------------------------------------------------- running

    def start(self) -> FmuState:
        fmpy = _fmpy()
        md, f = self.file.description, self.file
        cls = fmpy.fmi3.FMU3Slave if f.fmi == 3 else fmpy.fmi2.FMU2Slave
        slave = cls(
            guid=md.guid,
            unzipDirectory=f.directory,
            modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName="plant",
        )
        variables = f.variables
        try:
            slave.instantiate(logMessage=_quiet) if f.fmi == 3 else slave.instantiate()
            state = FmuState(slave, f.fmi)
            if self.structural:
                slave.enterConfigurationMode()
                for name, value in self.structural.items():
                    self._set(slave, variables[name], [value])
                slave.exitConfigurationMode()
            if f.fmi == 2:
                slave.setupExperiment(startTime=0.0)
            for name, values in self.parameter_values.items():
                if name not in self.structural:
                    self._set(slave, variables[name], _flatten(values))
            if f.fmi == 3:
                slave.enterInitializationMode(startTime=0.0)
            else:
                slave.enterInitializationMode()
            slave.exitInitializationMode()
        except Exception as exc:
            raise InputError(f"{f.path.name}: the FMU refused to start: {exc}") from None
        return state

    @staticmethod
    def _set(slave: Any, var: Any, values: list[Any]) -> None:
        kind = {"Real": "Real", "Integer": "Integer", "Boolean": "Boolean"}.get(var.type, var.type)
        if var.type == "Boolean":
            values = [bool(v) for v in values]
        elif var.type not in ("Real", "Float64", "Float32"):
            values = [int(v) for v in values]
        getattr(slave, f"set{kind}")([var.valueReference], values)

    def advance(
        self, state: FmuState, u: Mapping[str, float], t: float, dt: float, integrator: Integrator
    ) -> FmuState:
        variables = self.file.variables
        try:
            arrays = {k: list(v) for k, v in self.held.items()}
            for name, (fmu_name, element) in self.input_map.items():
                arrays[fmu_name][element] = u[name]
            for fmu_name, values in arrays.items():
                self._set(state.slave, variables[fmu_name], values)
            result = state.slave.doStep(currentCommunicationPoint=t, communicationStepSize=dt)
        except Exception as exc:
            raise InputError(f"{self.file.path.name}: doStep at t = {t:g} s failed: {exc}") from None
        if state.fmi == 3 and result[1]:
            raise InputError(
                f"{self.file.path.name}: the FMU asked to end the simulation at t = {t + dt:g} s"
            )
        return state

    def measure(self, state: FmuState) -> dict[str, float]:
        variables = self.file.variables
        out = {}
        for name, (fmu_name, element) in self.output_map.items():
            var = variables[fmu_name]
            n = _size(var, self.structural, variables)
            values = (
                getattr(state.slave, f"get{var.type}")([var.valueReference], n)
                if n > 1
                else (getattr(state.slave, f"get{var.type}")([var.valueReference]))
            )
            out[name] = float(values[element])
        return out
