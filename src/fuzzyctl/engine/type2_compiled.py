"""Interval type-2 evaluation through the IR (:mod:`fuzzyctl.ir.programs.type2`): the
evaluator program printed as Python (single rows), numpy (batches) or C (the native
backend), every Mamdani output sampled at ``samples`` points.  It computes what
``Type2Controller(fb, samples=N)`` computes (tested to 1e-12); ``explain`` is that
controller's (the firing intervals and type-reduced intervals of the same samples).
"""

from __future__ import annotations

import ctypes
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.engine import ranges as rg
from fuzzyctl.engine.type2 import SAMPLES, Type2Controller
from fuzzyctl.escape import CodegenError
from fuzzyctl.model import FunctionBlock

#: Rows x samples per numpy chunk (the aggregated sets of a chunk: 2 x 8 bytes each).
CHUNK_VALUES = 1 << 22


class Type2Compiled(Type2Controller):
    """A type-2 controller evaluating the IR program: ``backend`` ``"native"`` (C, one call
    per batch) or ``"python"`` (generated Python per row, numpy per batch)."""

    def __init__(
        self,
        fb: FunctionBlock,
        backend: str = "python",
        *,
        samples: int | None = None,
        method: str | None = None,
    ) -> None:
        from fuzzyctl.ir.programs.type2 import build_type2_fast

        n = samples or SAMPLES
        super().__init__(fb, samples=n, method=method)  # checks the system; explain
        self.backend = backend
        self._names = [v.name for v in fb.inputs]
        self._out_names = [d.variable for d in fb.defuzzify]
        try:
            if backend == "native":
                self._native(build_type2_fast(fb, "c", n, method).fast)
            else:
                from fuzzyctl.ir.render.npsrc import vectorise
                from fuzzyctl.ir.render.pysrc import specialise

                prog = build_type2_fast(fb, "py", n, method)
                self.info = prog.info
                self._row = specialise(prog.fast)
                self._batch = vectorise(build_type2_fast(fb, "np", n, method).fast)
        except CodegenError as exc:
            raise FuzzyctlError(f"interval type-2 system {fb.name}: {exc}") from None

    def _native(self, fast: Any) -> None:
        from fuzzyctl.engine.native import build_source
        from fuzzyctl.ir.render.c import render_native

        lib = ctypes.CDLL(str(build_source(render_native(fast))))
        vp = ctypes.c_void_p
        lib.fz_eval.argtypes = [vp, vp, vp]
        lib.fz_batch.argtypes = [vp, ctypes.c_size_t, vp, vp]
        self._lib = lib
        n_out = max(1, len(self._out_names))
        self._prev = (ctypes.c_double * n_out)()
        self._in1 = (ctypes.c_double * max(1, len(self._names)))()
        self._out1 = (ctypes.c_double * n_out)()

    # ------------------------------------------------------------------ evaluation

    def evaluate(
        self, inputs: Mapping[str, Any] | None = None, *, out_of_range: str | None = None, **kw: Any
    ) -> dict[str, float]:
        x = self._values({**(inputs or {}), **kw}, out_of_range)
        values = [x[n] for n in self._names]
        if self.backend == "native":
            for i, v in enumerate(values):
                self._in1[i] = v
            self._lib.fz_eval(self._prev, self._in1, self._out1)
            return {name: self._out1[i] for i, name in enumerate(self._out_names)}
        out = self._row(values, [0.0])
        return dict(zip(self._out_names, out, strict=True))

    def evaluate_batch(
        self, data: Any, *, out_of_range: str | None = None, rows: int | None = None, **options: Any
    ) -> dict[str, np.ndarray]:
        """Every row of ``data`` (input name -> sequence) in one call: numpy columns, or one C
        loop (native).  ``on_invalid="nan"`` gives NaN outputs for rows with a NaN or
        infinite input (else such a row raises)."""
        cols = [np.ascontiguousarray(np.asarray(data[k], dtype=float)) for k in self._names]
        n = len(cols[0]) if cols else int(rows or 0)
        invalid = np.zeros(n, dtype=bool)
        for name, c in zip(self._names, cols, strict=True):
            bad = ~np.isfinite(c)
            if bad.any() and options.get("on_invalid") != "nan":
                i = int(np.argmax(bad))
                raise FuzzyctlError(f"input {name}: row {i} is {c[i]} (not a finite number)")
            invalid |= bad
        cols = self._in_range(cols, out_of_range or self.out_of_range)
        if self.backend == "native":
            outs = [np.empty(n) for _ in self._out_names]
            src = (ctypes.c_void_p * max(1, len(cols)))(*[c.ctypes.data for c in cols])
            dst = (ctypes.c_void_p * max(1, len(outs)))(*[o.ctypes.data for o in outs])
            self._lib.fz_batch(self._prev, n, src, dst)
        else:  # in chunks: each sample of a Mamdani output is a column of the chunk's rows
            step = int(options.get("chunk") or max(256, CHUNK_VALUES // (self.samples or SAMPLES)))
            outs = [np.empty(n) for _ in self._out_names]
            for start in range(0, n, step):
                stop = min(n, start + step)
                part = self._batch([c[start:stop] for c in cols], [0.0], stop - start)
                for o, p in zip(outs, part, strict=True):
                    o[start:stop] = p
        if invalid.any():
            for o in outs:
                o[invalid] = math.nan
        return dict(zip(self._out_names, outs, strict=True))

    def _in_range(self, cols: list[np.ndarray], mode: str) -> list[np.ndarray]:
        """The columns as ``out_of_range`` says (as for type-1 batches)."""
        checked = rg.check_columns(self.input_ranges, self._names, list(cols), mode)
        return [c for c in checked if c is not None]

    def __repr__(self) -> str:
        return f"<Type2Compiled {self.model.name!r} ({self.backend}, {self.samples} samples)>"
