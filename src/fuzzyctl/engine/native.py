"""The native backend: the evaluator program of ``compile()`` as C, compiled once with the
system C compiler into a shared library kept in a cache directory, called through
:mod:`ctypes`.

* What is compiled: the evaluator program (:mod:`fuzzyctl.ir.programs.evaluator`, every output
  written in the IR by :mod:`fuzzyctl.ir.programs.native`, printed by
  :func:`fuzzyctl.ir.render.c.render_native`: constants inlined, closed forms on the
  output grid): the whole evaluation runs in C, nothing is called back.  A system the IR
  builders cannot express is refused with the reason (a warning when native was asked for).
  Tested against the reference interpreter.
* The library exports ``fz_state_size``, ``fz_init``, ``fz_eval`` (one row), ``fz_batch``
  (a loop over columns: one call per batch, no Python per row) and ``fz_get_prev`` /
  ``fz_set_prev`` (the DEFAULT := NC state, shared with ``explain``).
* Batches whose rows are independent (no output keeps its previous value) run on all cores,
  one thread per slice of rows (ctypes releases the GIL); with NC the rows run in order.
* Cache: ``$FUZZYCTL_CACHE_DIR`` or ``$XDG_CACHE_HOME/fuzzyctl`` (default
  ``~/.cache/fuzzyctl``), ``native/<key>.so``, the key a hash of the plan, the generator's
  code, the flags and the compiler, so a library is found without generating C.  A library is
  compiled into a temporary file and renamed into place (concurrent builds never see a half
  written file); the directory is kept under ``$FUZZYCTL_CACHE_MB`` megabytes (default 256)
  by removing the least recently used libraries.
"""

from __future__ import annotations

import ctypes
import functools
import hashlib
import os
import shutil
import struct
import sys
import tempfile
import threading
import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from fuzzyctl import cache
from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.engine.controller import Controller, merge_inputs
from fuzzyctl.engine.plan import Plan
from fuzzyctl.escape import CodegenError

if TYPE_CHECKING:
    from fuzzyctl.model import FunctionBlock

#: -ffp-contract=off: no fused multiply-add, so that the C rounds like Python does.
CFLAGS = ("-std=c99", "-O3", "-fPIC", "-shared", "-fvisibility=hidden", "-ffp-contract=off")
#: Rows per thread below which a batch is not split.
THREAD_ROWS = 1 << 16

_FAST_STATE = """
FZ_API int fz_is_fast(void) {{ return 1; }}
FZ_API size_t fz_state_size(void) {{ return {n_prev} * sizeof(double); }}
FZ_API void fz_get_prev(const double *prev, double *out)
{{ size_t i; for (i = 0; i < {n_prev}; i++) out[i] = prev[i]; }}
FZ_API void fz_set_prev(double *prev, const double *in)
{{ size_t i; for (i = 0; i < {n_prev}; i++) prev[i] = in[i]; }}
"""


class NativeError(FuzzyctlError):
    """The native library could not be built."""


def cache_dir() -> Path:
    return cache.cache_dir()


def compiler() -> str | None:
    """The C compiler to use (``$CC`` or ``cc``), or None when there is none."""
    cc = os.environ.get("CC", "cc")
    return shutil.which(cc)


@functools.cache
def _compiler_id(cc: str) -> str:
    """The compiler's identity for cache keys: its resolved path, size and time stamp (a
    ``stat``, not a ``cc --version`` run: keys are computed at every start)."""
    try:
        real = os.path.realpath(cc)
        st = os.stat(real)
        return f"{real}:{st.st_size}:{st.st_mtime_ns}"
    except OSError:
        return cc


def binary_tables() -> bool:
    """Whether large constant tables go to the library as data (``.incbin``, GNU assembler
    on ELF: Linux and the BSDs) rather than as C initialisers."""
    return sys.platform.startswith(("linux", "freebsd", "netbsd", "openbsd"))


def sources(plan: Plan) -> tuple[str, dict[str, str | bytes]]:
    """(kind, {file name: text or bytes}) of the native library of ``plan``: kind ``"fast"``,
    the evaluator program written wholly in the IR (:mod:`fuzzyctl.ir.programs.native`),
    with its large tables as ``.bin`` files where :func:`binary_tables`.  Raises
    :class:`CodegenError` saying what the IR builders cannot express."""
    from fuzzyctl.ir.programs.native import build_native
    from fuzzyctl.ir.render.c import render_native

    fp = build_native(plan)
    tables: dict[str, bytes] | None = {} if binary_tables() else None
    text = render_native(fp, tables) + _FAST_STATE.format(n_prev=max(1, len(plan.outputs)))
    return "fast", {"fz_native.c": text, **(tables or {})}


def library_key(plan: Plan, cc: str) -> str:
    """The cache key of ``plan``'s library: the plan itself (its repr is exact: floats
    round-trip), the generator's code, the flags and the compiler."""
    h = hashlib.sha256()
    h.update(repr(plan).encode())
    h.update(cache.code_fingerprint().encode())
    h.update(" ".join(CFLAGS).encode() + b"\0" + _compiler_id(cc).encode())
    return h.hexdigest()[:32]


def _named_key(content_key: str, cc: str) -> str:
    h = hashlib.sha256(b"plan-key\0" + content_key.encode())
    h.update(cache.code_fingerprint().encode())
    h.update(" ".join(CFLAGS).encode() + b"\0" + _compiler_id(cc).encode())
    return h.hexdigest()[:32]


def build(plan: Plan, hint: Path | None = None, content_key: str | None = None) -> Path:
    """Compile (or find in the cache) the shared library of ``plan``.  ``hint`` is a file
    naming the library of this plan, written here (it saves hashing a large plan);
    ``content_key``, the plan's own cache key (derived from the bytes of the file it came
    from and the options), names the library instead of a hash of the plan's repr (0.2 s
    for 10,000 rules)."""
    out_dir = cache_dir() / "native"
    if hint is not None:
        try:
            lib = out_dir / hint.read_text().strip()
            if lib.suffix == ".so" and lib.parent == out_dir and lib.exists():
                cache.touch(lib)
                return lib
        except OSError:
            pass
    cc = compiler()
    if cc is None:
        raise NativeError("no C compiler found (set CC or install cc)")
    lib = out_dir / f"{library_key(plan, cc) if content_key is None else _named_key(content_key, cc)}.so"
    if hint is not None:
        cache.write_atomic(hint, lib.name.encode())
    if lib.exists():
        cache.touch(lib)
        return lib
    _kind, files = sources(plan)
    compile_files(lib, files, cc)
    return lib


def compile_files(lib: Path, files: Mapping[str, str | bytes], cc: str) -> None:
    """Compile ``fz_native.c`` of ``files`` (with its tables) into the library ``lib``
    (atomically: a temporary file renamed into place), then prune the cache."""
    out_dir = lib.parent
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="fuzzyctl-build-") as tmp:
        for fname, content in files.items():
            if isinstance(content, bytes):
                Path(tmp, fname).write_bytes(content)
            else:
                Path(tmp, fname).write_text(content)
        fd, tmp_name = tempfile.mkstemp(dir=out_dir, prefix=f".{lib.stem}.", suffix=".tmp")
        os.close(fd)
        partial = Path(tmp_name)  # unique per build (threads share a pid)
        cmd = [cc, *CFLAGS, "-o", str(partial), "fz_native.c", "-lm"]
        import subprocess

        # run in the build directory: the C includes its tables by relative name
        res = subprocess.run(cmd, capture_output=True, text=True, timeout=600, cwd=tmp)
        if res.returncode != 0:
            partial.unlink(missing_ok=True)
            raise NativeError(f"the C compiler failed on the generated code:\n{res.stderr.strip()}")
        os.replace(partial, lib)  # atomic: a concurrent build of the same key writes the same bytes
    cache.prune(out_dir, cache.limit_bytes(), keep=lib)


def build_source(text: str) -> Path:
    """Compile (or find in the cache) a library from the C source ``text`` alone (the
    type-2 evaluator), keyed by the text, the flags and the compiler."""
    cc = compiler()
    if cc is None:
        raise NativeError("no C compiler found (set CC or install cc)")
    h = hashlib.sha256(b"source\0" + text.encode())
    h.update(" ".join(CFLAGS).encode() + b"\0" + _compiler_id(cc).encode())
    lib = cache_dir() / "native" / f"{h.hexdigest()[:32]}.so"
    if lib.exists():
        cache.touch(lib)
        return lib
    compile_files(lib, {"fz_native.c": text}, cc)
    return lib


class NativeController(Controller):
    """A :class:`~fuzzyctl.engine.Controller` evaluating through the compiled C.

    ``explain`` runs the Python interpreter on the same NC state (read from and written back
    to the native instance), so it stays consistent with ``evaluate``."""

    def __init__(self, plan: Plan, library: Path, model: FunctionBlock | None = None) -> None:
        super().__init__(plan, specialise=False, model=model)
        self.library = library
        lib = ctypes.CDLL(str(library))
        vp = ctypes.c_void_p
        lib.fz_state_size.restype = ctypes.c_size_t
        lib.fz_init.argtypes = [vp]
        lib.fz_eval.argtypes = [vp, vp, vp]
        lib.fz_batch.argtypes = [vp, ctypes.c_size_t, vp, vp]
        lib.fz_get_prev.argtypes = [vp, vp]
        lib.fz_set_prev.argtypes = [vp, vp]
        self._lib = lib
        self._state_size = int(lib.fz_state_size())
        self._inst = ctypes.create_string_buffer(self._state_size)
        self._inst_p = ctypes.cast(self._inst, ctypes.c_void_p)
        lib.fz_init(self._inst_p)
        self._out_index = [i for i, o in enumerate(plan.outputs) if o.is_output]
        self._n_in = len(plan.inputs)
        self._in1 = (ctypes.c_double * max(1, self._n_in))()
        self._n_res = len(plan.outputs)
        self._out1 = (ctypes.c_double * max(1, self._n_res))()
        self._prev = (ctypes.c_double * max(1, len(plan.outputs)))()
        self._names = [(plan.outputs[i].name, i) for i in self._out_index]
        self._eval_fn = lib.fz_eval
        self._nc = [oi for oi, op in enumerate(plan.outputs) if op.no_change and op.kind != "degree"]
        # slices of a batch can run in parallel when the state is only the previous outputs
        # (the evaluator's) and no output reads another (a NC value is then only copied)
        self._parallel = not _outputs_read(plan)

    def result_layout(self) -> tuple[list[tuple[str, int]], int]:
        """Where ``fz_eval`` writes each declared output (its name and index in the result
        array), and how many results it writes: what a caller of the library without this
        class needs (the CLI's quick path).  The evaluator writes every result."""
        slots = list(self._names)
        return slots, self._n_res

    def evaluate(
        self,
        inputs: Mapping[str, Any] | None = None,
        /,
        *,
        out_of_range: str | None = None,
        **values_by_name: Any,
    ) -> dict[str, float]:
        values = self._values(merge_inputs(inputs, values_by_name), out_of_range)
        buf = self._in1
        for i, v in enumerate(values):
            buf[i] = v
        self._eval_fn(self._inst_p, buf, self._out1)
        out = self._out1
        return {n: out[i] for n, i in self._names}

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

    def _run_batch(self, full: list[Any], n: int, chunk: int) -> dict[str, Any]:
        """One C call over the whole batch (one per thread when slices run in parallel)."""
        import numpy as np

        columns = full
        columns = [np.ascontiguousarray(c, dtype=np.float64) for c in columns]
        n_cols = self._n_res
        outs = [np.empty(n) for _ in range(n_cols)]
        parts = 1
        if self._parallel and n >= 2 * THREAD_ROWS:
            parts = max(1, min(os.cpu_count() or 1, n // THREAD_ROWS))
        if parts == 1:
            self._call_batch(self._inst_p, 0, n, columns, outs)
        else:
            self._threaded(n, parts, columns, outs)
        return {o.name: arr for o, arr in zip(self.plan.outputs, outs, strict=True) if o.is_output}

    def _call_batch(self, inst: Any, start: int, stop: int, columns: list[Any], outs: list[Any]) -> None:
        if stop <= start:
            return
        cols = (ctypes.c_void_p * max(1, len(columns)))(*[c[start:].ctypes.data for c in columns])
        dsts = (ctypes.c_void_p * max(1, len(outs)))(*[o[start:].ctypes.data for o in outs])
        self._lib.fz_batch(inst, stop - start, cols, dsts)

    def _threaded(self, n: int, parts: int, columns: list[Any], outs: list[Any]) -> None:
        """One slice of rows per thread.  The first slice starts from the instance's state;
        the others start with a marker (a NaN with its own payload) as the previous value of
        each NC output, which the rows before a slice's first firing copy; afterwards those
        rows get the previous slice's last value, in order - the result of running the rows
        one after the other.  The state afterwards is the last row's outputs."""
        import numpy as np

        bounds = [n * k // parts for k in range(parts + 1)]
        first = np.frombuffer(self._inst.raw, dtype=np.float64).copy()
        marked = first.copy()
        marked[self._nc] = _MARKER
        insts = [
            ctypes.create_string_buffer((first if k == 0 else marked).tobytes(), self._state_size)
            for k in range(parts)
        ]
        threads = [
            threading.Thread(
                target=self._call_batch,
                args=(ctypes.cast(insts[k], ctypes.c_void_p), bounds[k], bounds[k + 1], columns, outs),
            )
            for k in range(parts)
        ]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        for oi in self._nc:
            col = outs[oi]
            for k in range(1, parts):
                seg = col[bounds[k] : bounds[k + 1]]
                seg[seg.view(np.int64) == _MARKER_BITS] = col[bounds[k] - 1]
        last = np.array([o[-1] for o in outs], dtype=np.float64)
        ctypes.memmove(self._inst, last.tobytes(), min(self._state_size, last.nbytes))

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


_MARKER_BITS = 0x7FF8DEADBEEF0001  # a quiet NaN no computation produces
_MARKER = float(struct.unpack("<d", struct.pack("<Q", _MARKER_BITS))[0])


def _outputs_read(plan: Plan) -> bool:
    """Whether some term reads an output computed earlier (a function term)."""
    from fuzzyctl.engine.plan import EBinary, ECall, EOutput, EUnary, ExprPlan

    def reads(e: ExprPlan | None) -> bool:
        if isinstance(e, EOutput):
            return True
        if isinstance(e, EUnary):
            return reads(e.operand)
        if isinstance(e, EBinary):
            return reads(e.left) or reads(e.right)
        if isinstance(e, ECall):
            return any(reads(a) for a in e.args)
        return False

    return any(reads(t.expr) for op in plan.outputs for t in op.terms)


_NOTICE_SHOWN = False


def notice(message: str) -> None:
    """A one-line notice on stderr, once per process (the default backend falling back)."""
    global _NOTICE_SHOWN
    if _NOTICE_SHOWN or os.environ.get("FUZZYCTL_QUIET"):
        return
    _NOTICE_SHOWN = True
    import sys

    print(f"fuzzyctl: {message}", file=sys.stderr)


def compile_native(
    plan: Plan,
    model: FunctionBlock | None = None,
    *,
    explicit: bool = True,
    hint: Path | None = None,
    content_key: str | None = None,
) -> Controller:
    """A native controller for ``plan``, or the Python one when there is no compiler or the
    plan uses something the C generators cannot express: with a warning when native was
    asked for (``explicit``), otherwise a one-line notice on stderr (once per process for a
    missing compiler, once per reason for a system the C cannot express)."""
    try:
        return NativeController(plan, build(plan, hint, content_key), model)
    except NativeError as exc:
        if explicit:
            warnings.warn(
                f"native backend unavailable, using the numpy path: {exc}", RuntimeWarning, stacklevel=3
            )
        elif compiler() is None:
            notice("no C compiler (cc or $CC): evaluating with the Python path")
        else:
            warnings.warn(
                f"native backend unavailable, using the numpy path: {exc}", RuntimeWarning, stacklevel=3
            )
    except CodegenError as exc:
        if explicit:
            warnings.warn(
                f"native backend unavailable, using the numpy path: {exc}", RuntimeWarning, stacklevel=3
            )
        else:  # never a silent fallback: the default backend says why, once per reason
            _not_native(str(exc))
    return Controller(plan, specialise=True, model=model)


_REASONS_SHOWN: set[str] = set()


def _not_native(reason: str) -> None:
    """A one-line notice on stderr, once per process and reason: the default backend
    evaluates a system the C generator cannot express with the numpy path."""
    if reason in _REASONS_SHOWN or os.environ.get("FUZZYCTL_QUIET"):
        return
    _REASONS_SHOWN.add(reason)
    print(f"fuzzyctl: not evaluated natively ({reason}): using the numpy path", file=sys.stderr)
