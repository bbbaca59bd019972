"""Execution time and memory of programs on this machine (Table 11, "execution time" and
"memory requirements"): the Python engine (one call, and per row of a batch), the generated
C through the native backend, the memory the compiled controller keeps, and the size of one
function block instance and of the code of the generated C."""

from __future__ import annotations

import functools
import math
import platform
import re
import time
import tracemalloc
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fuzzyctl.model import Document

__all__ = ["Measurement", "machine", "measure"]


@dataclass(frozen=True)
class Measurement:
    """Execution time and memory of one program on this machine."""

    name: str
    inputs: int
    outputs: int
    rules: int
    engine_us: float  # one evaluate() of the Python engine, microseconds
    batch_us: float  # per row of evaluate_batch (10 000 rows), microseconds
    native_us: float | None  # per row through the generated C (backend="native")
    python_kb: float  # memory the compiled Python controller keeps (tracemalloc), KiB
    c_instance: int | None  # bytes of one function block instance in the generated C
    c_code: int | None  # bytes of code and constant data of the generated C object (gcc -O2)


def _universe(doc: Document, name: str) -> tuple[float, float]:
    from fuzzyctl.fcl.checks import mf_params

    fb = doc.main
    var, fz = fb.variable(name), fb.fuzzify_block(name)
    rng = (var.range if var else None) or (fz.range if fz else None)
    if rng is not None:
        return rng.low, rng.high
    xs = [float(p) for t in (fz.terms if fz else ()) for p in mf_params(t.mf) if isinstance(p, int | float)]
    return (min(xs), max(xs)) if xs else (0.0, 1.0)


def _best(fn: Callable[[], object], repeat: int = 5) -> float:
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def _c_sizes(doc: Document) -> tuple[int | None, int | None]:
    """(instance bytes, code + constant bytes) of the generated C, or Nones without a C compiler."""
    import ctypes
    import subprocess
    import tempfile

    from fuzzyctl.codegen import generate_c, lower_block
    from fuzzyctl.engine.native import build, compiler

    cc = compiler()
    if cc is None:
        return None, None
    lib = ctypes.CDLL(str(build(lower_block(doc))))
    lib.fz_sizeof.restype = ctypes.c_size_t
    instance = int(lib.fz_sizeof())
    with tempfile.TemporaryDirectory() as tmp:
        files = generate_c(doc)
        for fname, text in files.items():
            Path(tmp, fname).write_text(text, encoding="utf-8")
        source = next(f for f in files if f.endswith(".c"))
        obj = Path(tmp, "fb.o")
        subprocess.run(
            [cc, "-std=c99", "-O2", "-c", str(Path(tmp, source)), "-o", str(obj)],
            check=True,
            capture_output=True,
        )
        size = (
            subprocess.run(["size", str(obj)], check=True, capture_output=True, text=True)
            .stdout.splitlines()[-1]
            .split()
        )
    return instance, int(size[0]) + int(size[1])


def measure(paths: Iterable[str | Path], *, rows: int = 10_000) -> list[Measurement]:
    """Execution time and memory of each program on this machine (inputs drawn evenly over
    their universes, a fixed seed)."""
    import numpy as np

    import fuzzyctl

    out = []
    for path in paths:
        doc = fuzzyctl.load(Path(path))
        fb = doc.main
        rng = np.random.default_rng(61131)
        data = {v.name: rng.uniform(*_universe(doc, v.name), rows) for v in fb.inputs}
        tracemalloc.start()
        base = tracemalloc.get_traced_memory()[0]
        ctl = fuzzyctl.compile(doc, out_of_range="ignore")
        kept = tracemalloc.get_traced_memory()[0] - base
        tracemalloc.stop()
        points = [{k: float(v[i]) for k, v in data.items()} for i in range(200)]

        def scalar(c: Any = ctl, pts: list[dict[str, float]] = points) -> None:
            for p in pts:
                c.evaluate(p)

        engine_us = _best(scalar) / len(points) * 1e6
        batch_us = _best(functools.partial(ctl.evaluate_batch, data), 3) / rows * 1e6
        native_us = None
        try:
            nat = fuzzyctl.compile(doc, backend="native", out_of_range="ignore")
            if type(nat).__name__ == "NativeController":
                nat.evaluate_batch(data)
                native_us = _best(functools.partial(nat.evaluate_batch, data), 5) / rows * 1e6
        except Exception:  # no C compiler, or the generator refuses the program
            native_us = None
        try:
            instance, code = _c_sizes(doc)
        except Exception:
            instance, code = None, None
        rules = sum(len(rb.rules) for rb in fb.rule_blocks)
        out.append(
            Measurement(
                Path(path).name,
                len(fb.inputs),
                len(fb.outputs),
                rules,
                engine_us,
                batch_us,
                native_us,
                kept / 1024,
                instance,
                code,
            )
        )
    return out


def machine() -> str:
    """This machine, for the measurements: CPU model, cores, Python, C compiler."""
    import os
    import subprocess

    cpu = platform.processor() or platform.machine()
    try:
        info = Path("/proc/cpuinfo").read_text(encoding="utf-8")
        m = re.search(r"^model name\s*:\s*(.+)$", info, re.M)
        cpu = m.group(1).strip() if m else cpu
    except OSError:
        pass
    cc = "no C compiler"
    try:
        from fuzzyctl.engine.native import compiler

        found = compiler()
        if found:
            cc = subprocess.run([found, "--version"], capture_output=True, text=True).stdout.splitlines()[0]
    except Exception:
        pass
    return f"{cpu}, {os.cpu_count()} cores; Python {platform.python_version()}; {cc}"
