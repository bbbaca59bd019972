"""The native backend: ``compile(model, backend="native")``.

The plan is generated as C (double), compiled once with the system C compiler into a shared
library kept in a cache directory, and called through :mod:`ctypes`.  A batch crosses the
boundary once (one C loop over the rows), a single evaluation is one call.

Cache: ``$FUZZYCTL_CACHE_DIR`` or ``$XDG_CACHE_HOME/fuzzyctl`` (default ``~/.cache/fuzzyctl``),
``native/<sha256 of the source, the flags and the compiler>.so``.  A library is compiled into a
temporary file and renamed into place, so concurrent builds of the same system never see a
half-written file.  Without a C compiler (``$CC`` or ``cc``) ``compile`` warns and returns the
Python controller.
"""

from __future__ import annotations

import ctypes
import functools
import hashlib
import os
import shutil
import subprocess
import tempfile
import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from fuzzyctl.codegen.context import CodegenError
from fuzzyctl.codegen.program import build_program
from fuzzyctl.codegen.render_c import render_c
from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.engine.controller import Controller, merge_inputs
from fuzzyctl.engine.plan import Plan
from fuzzyctl.model import FunctionBlock

#: -ffp-contract=off: no fused multiply-add, so that the C rounds like Python does.
CFLAGS = ("-std=c99", "-O3", "-fPIC", "-shared", "-fvisibility=hidden", "-ffp-contract=off")

_WRAPPER = """
#include "{name}.c"
#define FZ_API __attribute__((visibility("default")))
FZ_API size_t fz_sizeof(void) {{ return sizeof({name}); }}
FZ_API void fz_init(void *fb) {{ {name}_init(({name} *)fb); }}
FZ_API unsigned char fz_batch(void *fb, size_t n, const double *in, double *out)
{{ return {name}_batch(({name} *)fb, n, in, out); }}
FZ_API void fz_get_prev(const void *fb, double *out)
{{ size_t i; for (i = 0; i < {n_prev}; i++) out[i] = (double)(({name} *)fb)->{prev}[i]; }}
FZ_API void fz_set_prev(void *fb, const double *in)
{{ size_t i; for (i = 0; i < {n_prev}; i++) (({name} *)fb)->{prev}[i] = ({name}_real)in[i]; }}
"""


class NativeError(FuzzyctlError):
    """The native library could not be built."""


def cache_dir() -> Path:
    env = os.environ.get("FUZZYCTL_CACHE_DIR")
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "fuzzyctl"


def compiler() -> str | None:
    """The C compiler to use (``$CC`` or ``cc``), or None when there is none."""
    cc = os.environ.get("CC", "cc")
    return shutil.which(cc)


@functools.cache
def _compiler_id(cc: str) -> str:
    try:
        out = subprocess.run([cc, "--version"], capture_output=True, text=True, timeout=60)
        return out.stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return cc


def sources(plan: Plan) -> tuple[str, dict[str, str]]:
    """(block name, {file name: text}) of the native library of ``plan``."""
    prog = build_program(plan, "c")
    header, source = render_c(prog)
    prev = next(d for d in prog.of("state") if d.name.startswith("FZ_PREV"))
    wrapper = _WRAPPER.format(name=prog.name, prev=prev.name, n_prev=len(plan.outputs))
    return prog.name, {f"{prog.name}.h": header, f"{prog.name}.c": source, "fz_native.c": wrapper}


def build(plan: Plan) -> Path:
    """Compile (or find in the cache) the shared library of ``plan``."""
    cc = compiler()
    if cc is None:
        raise NativeError("no C compiler found (set CC or install cc)")
    _name, files = sources(plan)
    key = hashlib.sha256()
    for fname in sorted(files):
        key.update(fname.encode() + b"\0" + files[fname].encode() + b"\0")
    key.update(" ".join(CFLAGS).encode() + b"\0" + _compiler_id(cc).encode())
    out_dir = cache_dir() / "native"
    lib = out_dir / f"{key.hexdigest()[:32]}.so"
    if lib.exists():
        return lib
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="fuzzyctl-build-") as tmp:
        for fname, text in files.items():
            Path(tmp, fname).write_text(text)
        fd, tmp_name = tempfile.mkstemp(dir=out_dir, prefix=f".{lib.stem}.", suffix=".tmp")
        os.close(fd)
        partial = Path(tmp_name)  # unique per build (threads share a pid)
        cmd = [cc, *CFLAGS, "-o", str(partial), str(Path(tmp, "fz_native.c")), "-lm"]
        res = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        if res.returncode != 0:
            partial.unlink(missing_ok=True)
            raise NativeError(f"the C compiler failed on the generated code:\n{res.stderr.strip()}")
        os.replace(partial, lib)  # atomic: a concurrent build of the same key writes the same bytes
    return lib


class NativeController(Controller):
    """A :class:`~fuzzyctl.engine.Controller` evaluating through the compiled C.

    ``explain`` runs the Python interpreter on the same NC state (read from and written back
    to the native instance), so it stays consistent with ``evaluate``."""

    def __init__(self, plan: Plan, library: Path, model: FunctionBlock | None = None) -> None:
        super().__init__(plan, specialise=False, model=model)
        self.library = library
        lib = ctypes.CDLL(str(library))
        lib.fz_sizeof.restype = ctypes.c_size_t
        lib.fz_init.argtypes = [ctypes.c_void_p]
        lib.fz_batch.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p, ctypes.c_void_p]
        lib.fz_batch.restype = ctypes.c_ubyte
        lib.fz_get_prev.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
        lib.fz_set_prev.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
        self._lib = lib
        self._inst = ctypes.create_string_buffer(int(lib.fz_sizeof()))
        self._inst_p = ctypes.cast(self._inst, ctypes.c_void_p)
        lib.fz_init(self._inst_p)
        self._out_index = [i for i, o in enumerate(plan.outputs) if o.is_output]
        self._n_in = len(plan.inputs)
        self._in1 = (ctypes.c_double * max(1, self._n_in))()
        self._out1 = (ctypes.c_double * max(1, len(self._out_index)))()
        self._prev = (ctypes.c_double * max(1, len(plan.outputs)))()
        self._names = [plan.outputs[i].name for i in self._out_index]
        self._batch_fn = lib.fz_batch

    def evaluate(self, inputs: Mapping[str, Any] | None = None, /, **values_by_name: Any) -> dict[str, float]:
        values = self._values(merge_inputs(inputs, values_by_name))
        buf = self._in1
        for i, v in enumerate(values):
            buf[i] = v
        self._batch_fn(self._inst_p, 1, buf, self._out1)
        out = self._out1
        return {n: out[k] for k, n in enumerate(self._names)}

    def evaluate_reference(
        self, inputs: Mapping[str, Any] | None = None, /, **values_by_name: Any
    ) -> dict[str, float]:
        self._pull_state()
        res = super().evaluate_reference(inputs, **values_by_name)
        self._push_state()
        return res

    def explain(self, inputs: Mapping[str, Any] | None = None, /, **values_by_name: Any) -> Any:
        self._pull_state()
        res = super().explain(inputs, **values_by_name)
        self._push_state()
        return res

    def _batch_chunk(self, part: list[npt.NDArray[np.float64]]) -> list[npt.NDArray[np.float64]]:
        m = len(part[0]) if part else 0
        data = np.ascontiguousarray(np.column_stack(part) if part else np.zeros((m, 0)), dtype=np.float64)
        out = np.empty((m, max(1, len(self._out_index))), dtype=np.float64)
        if m:
            self._batch_fn(self._inst_p, m, data.ctypes.data, out.ctypes.data)
        res = [np.full(m, np.nan) for _ in self.plan.outputs]
        for k, oi in enumerate(self._out_index):
            res[oi] = out[:, k].copy()
        return res

    def evaluate_batch(
        self, data: Any, *, chunk: int = 1 << 20, on_invalid: str = "raise"
    ) -> dict[str, npt.NDArray[np.float64]]:
        return super().evaluate_batch(data, chunk=chunk, on_invalid=on_invalid)

    def reset(self) -> None:
        super().reset()
        self._lib.fz_init(self._inst_p)

    def _pull_state(self) -> None:
        self._lib.fz_get_prev(self._inst_p, self._prev)
        self._state = [self._prev[i] for i in range(len(self.plan.outputs))]

    def _push_state(self) -> None:
        for i, v in enumerate(self._state):
            self._prev[i] = 0.0 if v is None else v
        self._lib.fz_set_prev(self._inst_p, self._prev)

    def __repr__(self) -> str:
        return f"NativeController({self.name!r}, inputs={list(self.inputs)}, outputs={list(self.outputs)})"


def compile_native(plan: Plan, model: FunctionBlock | None = None) -> Controller:
    """A native controller for ``plan``, or the Python one (with a warning) when there is no
    compiler or the plan uses something the C generator cannot express."""
    try:
        return NativeController(plan, build(plan), model)
    except (CodegenError, NativeError) as exc:
        warnings.warn(
            f"native backend unavailable, using the numpy path: {exc}", RuntimeWarning, stacklevel=3
        )
        return Controller(plan, specialise=True, model=model)
