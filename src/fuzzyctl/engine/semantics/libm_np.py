"""The C library's transcendental functions (what :mod:`math` and the native backend call),
element by element on numpy arrays.

Why: numpy's vector ``exp``, ``cos``, ``power``... (SIMD code chosen by the CPU) round the
last bit differently from libm on a few percent of arguments.  Where a result feeds an exact
comparison (fuzzylite's ``Highest`` / ``Lowest`` / ``Threshold`` activations, the maximum
methods) one ulp moves the answer: a rule block with ``activation: Highest 1`` whose rules
tie at 1.0 under libm picked the other rule in the batch path.  The batch path therefore
computes these functions with the same libm calls as the scalar paths, so every path gives one
answer (docs/engine.md, "One answer on every path").  Exact operations (sqrt, abs, floor,
arithmetic) stay numpy's: IEEE rounds them identically everywhere.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = [
    "acos",
    "asin",
    "atan",
    "atan2",
    "cos",
    "cosh",
    "exp",
    "log",
    "log10",
    "pow_",
    "sin",
    "sinh",
    "tan",
    "tanh",
]


def _lift(fm: Callable[..., float], fn: Any, nargs: int) -> Callable[..., Any]:
    """``fm`` (math) applied to each element; where math raises (overflow, outside the domain)
    the element is numpy's ``fn`` (inf, nan), as the vector version gave before."""

    def one(*a: float) -> float:
        try:
            return fm(*a)
        except (ValueError, OverflowError, ZeroDivisionError):
            with np.errstate(all="ignore"):
                return float(fn(*(np.float64(v) for v in a)))

    ufunc = np.frompyfunc(one, nargs, 1)

    def apply(*args: Any) -> Any:
        arrays = np.broadcast_arrays(*(np.asarray(a, dtype=np.float64) for a in args))
        shape = arrays[0].shape
        try:  # the common case, about 3x faster than the ufunc: no argument raises
            got = np.fromiter(map(fm, *(a.ravel().tolist() for a in arrays)), np.float64, arrays[0].size)
        except (ValueError, OverflowError, ZeroDivisionError):
            with np.errstate(all="ignore"):  # numpy flags what math already answered
                got = ufunc(*arrays).astype(np.float64)
        return got.reshape(shape) if shape else np.float64(got.reshape(()))

    apply.__name__ = getattr(fm, "__name__", "libm")
    apply.__doc__ = f"libm's ``{apply.__name__}`` element by element (numpy's special values)."
    return apply


exp = _lift(math.exp, np.exp, 1)
cos = _lift(math.cos, np.cos, 1)
sin = _lift(math.sin, np.sin, 1)
tan = _lift(math.tan, np.tan, 1)
acos = _lift(math.acos, np.arccos, 1)
asin = _lift(math.asin, np.arcsin, 1)
atan = _lift(math.atan, np.arctan, 1)
cosh = _lift(math.cosh, np.cosh, 1)
sinh = _lift(math.sinh, np.sinh, 1)
tanh = _lift(math.tanh, np.tanh, 1)
log = _lift(math.log, np.log, 1)
log10 = _lift(math.log10, np.log10, 1)
pow_ = _lift(math.pow, np.power, 2)
atan2 = _lift(math.atan2, np.arctan2, 2)
