"""A function block as an FMI 2.0 / 3.0 co-simulation FMU (``fuzzyctl codegen --lang fmu``).

The FMU is built from the C that :func:`fuzzyctl.codegen.generate_c` writes (``NAME.h``,
``NAME.c``) and a model part rendered from ``templates/`` (``config.h``, ``model.c``) for the
Modelica Association's Reference FMUs framework, vendored with its BSD-2 licence in
``fuzzyctl/codegen/fmu/vendor/``.  It holds

* ``modelDescription.xml``: the inputs (Float64), ``ENABLE`` (Boolean input), the outputs,
  ``INFO`` (UInt8; Integer in FMI 2) and every tunable parameter entry (term points,
  singleton positions, weights, ...) as a tunable parameter (:mod:`.description`);
* ``sources/``: every file needed to compile it (a source FMU; ``buildDescription.xml`` for
  FMI 3, ``<SourceFiles>`` for FMI 2), with the licence of the framework;
* ``binaries/x86_64-linux/NAME.so`` (FMI 3) or ``binaries/linux64/NAME.so`` (FMI 2), built
  with the C compiler present (``$CC`` or ``cc``) unless ``binary=False``.

The block is evaluated when an output is read after an input or a parameter was set, so the
outputs at a communication point are the block's for the inputs set there (direct
feedthrough, one PLC cycle per communication point).  docs/codegen.md, "FMU".
"""

from __future__ import annotations

import hashlib
import io
import platform
import subprocess
import sys
import tempfile
import uuid
import zipfile
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from string import Template
from typing import Any

from fuzzyctl.codegen.fmu.description import (
    FMI_VERSIONS,
    Interface,
    build_description,
    interface,
    model_description,
)
from fuzzyctl.escape import CodegenError, c_comment, c_string

__all__ = ["FMI_VERSIONS", "FmuResult", "generate_fmu", "platform_folder"]

#: Identifiers of the Reference FMUs framework (model.h, cosimulation.h, config.h): a block
#: of one of these names would clash with them in the FMU's C.
_FRAMEWORK_WORDS = """ModelInstance ModelData ModelState InterfaceType Status ValueReference
    loggerType lockPreemptionType unlockPreemptionType intermediateUpdateType clockUpdateType
    createModelInstance freeModelInstance configurate reset setStartValues calculateValues
    activateClock getClock setClock getInterval activateModelPartition getNumberOfEventIndicators
    getNumberOfContinuousStates getContinuousStates getNominalsOfContinuousStates
    setContinuousStates getDerivatives getOutputDerivative getPartialDerivative getEventIndicators
    eventUpdate isClose invalidNumber invalidState nullPointer logError setDebugLogging logEvent
    getFMUState setFMUState doFixedStep OK Warning Discard Error Fatal Pending ModelExchange
    CoSimulation ScheduledExecution StartAndEnd ConfigurationMode Instantiated InitializationMode
    EventMode ContinuousTimeMode StepMode ClockActivationMode StepDiscarded ReconfigurationMode
    IntermediateUpdateMode Terminated StepComplete StepInProgress StepFailed StepCanceled
    M UNUSED xstr str CALL MODEL_IDENTIFIER INSTANTIATION_TOKEN CO_SIMULATION FIXED_SOLVER_STEP
    DEFAULT_STOP_TIME FMI_VERSION DISABLE_PREFIX EVENT_UPDATE"""
_TYPES = "Float32 Float64 Int8 UInt8 Int16 UInt16 Int32 UInt32 Int64 UInt64 Boolean String Binary"
FRAMEWORK_NAMES = frozenset(
    _FRAMEWORK_WORDS.split()
    + [f"{p}{t}" for p in ("get", "set") for t in _TYPES.split()]
    + [f"{p}_{t.upper()}" for p in ("GET", "SET") for t in _TYPES.split()]
)

#: The framework's time step: the block has no continuous states, a step only advances time.
SOLVER_STEP = 1e-3
_FRAMEWORK = ("model.h", "cosimulation.h", "cosimulation.c", "LICENSE.txt")
_HEADERS = {
    2: ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h", "fmi2Functions.c"),
    3: ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h", "fmi3Functions.c"),
}


@dataclass
class FmuResult:
    """What :func:`generate_fmu` wrote: the FMU, its model identifier, the FMI version,
    whether it holds a binary, and the interface (variables and value references)."""

    path: Path
    ident: str
    fmi: int
    binary: str | None
    interface: Interface
    renames: list[Any] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return {
            "fmu": str(self.path),
            "model_identifier": self.ident,
            "fmi": self.fmi,
            "binary": self.binary,
            "variables": len(self.interface.variables) + 1,
            "parameters": len(self.interface.of("parameter")),
            "renames": [r.to_dict() for r in self.renames],
        }


def platform_folder(fmi: int) -> str:
    """The binaries/ folder of this platform: ``x86_64-linux`` (FMI 3) / ``linux64`` (FMI 2)."""
    machine = {"amd64": "x86_64", "arm64": "aarch64"}.get(
        platform.machine().lower(), platform.machine().lower()
    )
    system = {"darwin": "darwin", "win32": "windows"}.get(sys.platform, "linux")
    if fmi == 3:
        return f"{machine}-{system}"
    bits = "64" if sys.maxsize > 2**32 else "32"
    return {"linux": f"linux{bits}", "darwin": f"darwin{bits}", "windows": f"win{bits}"}[system]


def _library_suffix() -> str:
    return {"darwin": ".dylib", "win32": ".dll"}.get(sys.platform, ".so")


def _check_ident(name: str) -> str:
    if name in FRAMEWORK_NAMES or name.startswith(("fmi2", "fmi3", "FMI2", "FMI3")):
        raise CodegenError(
            f"function block {name!r}: the FMU framework uses this name (rename the block, "
            "e.g. with --block and a FUNCTION_BLOCK of another name)"
        )
    return name


def _vendored(name: str) -> str:
    return resources.files("fuzzyctl.codegen.fmu").joinpath("vendor", name).read_text(encoding="utf-8")


def _template(name: str) -> Template:
    return Template(resources.files("fuzzyctl.codegen.fmu").joinpath("templates", name).read_text("utf-8"))


def render_model(iface: Interface, ident: str, token: str, fmi: int, title: str) -> dict[str, str]:
    """``config.h`` and ``model.c`` for the block ``ident`` (names are C identifiers checked
    by the C generator; text from the model only in ``c_comment``/``c_string``)."""
    values = {"ident": ident, "comment": c_comment(title), "fmi": str(fmi), "token": c_string(token)}
    config = _template("config.h.in").substitute(values, solver_step=repr(SOLVER_STEP), stop_time="1e300")
    get_float, set_float = [], []
    for v in iface.variables:
        if v.kind in ("input", "output"):
            get_float.append(f"    case {v.vr}: values[(*index)++] = fz_fb->{v.field}; return OK;")
        if v.kind == "input":
            set_float.append(f"    case {v.vr}: fz_fb->{v.field} = values[(*index)++]; return OK;")
    get_params, set_params = [], []
    for a in iface.arrays:
        test = f"    if (vr >= {a.base}u && vr < {a.base + a.size}u) {{"
        get_params.append(f"{test} values[(*index)++] = fz_fb->{a.field}[vr - {a.base}u]; return OK; }}")
        set_params.append(f"{test} fz_fb->{a.field}[vr - {a.base}u] = values[(*index)++]; return OK; }}")
    model = _template("model.c.in").substitute(
        values,
        get_float="\n".join(get_float),
        set_float="\n".join(set_float),
        get_params="\n".join(get_params),
        set_params="\n".join(set_params),
        vr_enable=str(iface.vr_enable),
        vr_info=str(iface.vr_info),
    )
    return {"config.h": config, "model.c": model}


def _compile(sources: dict[str, str], compiled: list[str], fmi: int, out: Path) -> None:
    from fuzzyctl.engine.native import compiler

    cc = compiler()
    if cc is None:
        raise CodegenError("no C compiler found for the FMU's binary (set CC or install cc; or --no-binary)")
    with tempfile.TemporaryDirectory(prefix="fuzzyctl-fmu-") as tmp:
        for name, text in sources.items():
            (Path(tmp) / name).write_text(text, encoding="utf-8")
        cmd = [
            cc, "-std=gnu99", "-O2", "-ffp-contract=off", "-fPIC", "-shared", "-fvisibility=default",
            f"-DFMI_VERSION={fmi}", "-DDISABLE_PREFIX", f"-I{tmp}",
            *(str(Path(tmp) / n) for n in compiled), "-o", str(out), "-lm",
        ]  # fmt: skip
        proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
        if proc.returncode != 0:
            raise CodegenError(
                f"the C compiler refused the FMU's sources ({cc}):\n{proc.stderr.strip()[:2000]}"
            )


def generate_fmu(
    model: Any,
    path: str | Path | None = None,
    *,
    block: str | None = None,
    fmi: int = 3,
    binary: bool = True,
    default: float | str | None = None,
    force: bool = False,
    **options: Any,
) -> FmuResult:
    """Write the FMU of one function block of ``model`` (default: the first) to ``path``
    (default: ``NAME.fmu``); ``fmi`` is 2 or 3; ``binary=False`` writes a source-only FMU.
    Raises :class:`CodegenError` for what the C generator refuses, a block name the FMU
    framework uses, or a compiler that refuses the sources.

    ```python
    >>> import fuzzyctl, tempfile, zipfile
    >>> from fuzzyctl.codegen.fmu import generate_fmu
    >>> out = generate_fmu(fuzzyctl.load("examples/figure7.fcl"), tempfile.mkdtemp() + "/f7.fmu")
    >>> out.ident, out.fmi, out.binary
    ('Fuzzy_FB', 3, 'binaries/...-linux/Fuzzy_FB.so')
    >>> "sources/buildDescription.xml" in zipfile.ZipFile(out.path).namelist()
    True

    ```
    """
    from fuzzyctl import __version__
    from fuzzyctl.codegen.api import build, plans
    from fuzzyctl.ir.render.c import render_c

    if fmi not in FMI_VERSIONS:
        raise CodegenError(f"FMI version {fmi!r}: fuzzyctl writes FMI 2 or 3")
    if block is None and hasattr(model, "main"):
        block = model.main.name
    gen = build(plans(model, block, **options)[0], "c", default)
    prog = gen.program
    ident = _check_ident(prog.name)
    header, source = render_c(prog, single=False)
    iface = interface(prog)
    digest = hashlib.sha256(f"{fmi}\n{header}\n{source}".encode()).hexdigest()
    token = "{" + str(uuid.uuid5(uuid.NAMESPACE_URL, f"fuzzyctl:{digest}")) + "}"
    files = {f"{ident}.h": header, f"{ident}.c": source, **render_model(iface, ident, token, fmi, ident)}
    files.update({name: _vendored(name) for name in (*_FRAMEWORK, *_HEADERS[fmi])})
    compiled = [f"{ident}.c", "model.c", "cosimulation.c", f"fmi{fmi}Functions.c"]
    if fmi == 2:
        # FMI 2 has no build description: one file that says FMI_VERSION and includes the rest
        files["all.c"] = "#define FMI_VERSION 2\n" + "".join(f'#include "{n}"\n' for n in compiled)
        listed = ["all.c"]
    else:
        files["buildDescription.xml"] = build_description(ident, compiled)
        listed = compiled
    xml = model_description(
        iface, ident=ident, token=token, fmi=fmi, tool=f"fuzzyctl {__version__}", sources=listed,
        description=f"fuzzy function block {ident} (IEC 61131-7), generated by fuzzyctl",
    )  # fmt: skip
    out = Path(path) if path is not None else Path(f"{ident}.fmu")
    buf = io.BytesIO()
    binary_name = None
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("modelDescription.xml", xml)
        for name in sorted(files):
            zf.writestr(f"sources/{name}", files[name])
        if binary:
            binary_name = f"binaries/{platform_folder(fmi)}/{ident}{_library_suffix()}"
            with tempfile.TemporaryDirectory(prefix="fuzzyctl-fmu-") as tmp:
                lib = Path(tmp) / f"{ident}{_library_suffix()}"
                _compile({k: v for k, v in files.items() if not k.endswith(".xml")}, compiled, fmi, lib)
                zf.writestr(binary_name, lib.read_bytes())
    from fuzzyctl.files import write_atomic

    write_atomic(out, buf.getvalue(), force=force)
    return FmuResult(out, ident, fmi, binary_name, iface, list(gen.renames))
