"""fuzzyctl.engine.semantics.fdlibm against Java's own ``StrictMath``, bit for bit, on millions of
arguments: the shapes' ranges (Gaussian and sigmoid exponents, cosine phases, bell powers),
random bit patterns over every exponent, and the special values.  Needs ``javac`` (make
system-deps installs a JDK)."""

from __future__ import annotations

import math
import shutil
import subprocess
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from fuzzyctl.engine.semantics import fdlibm

JAVA_SOURCE = Path(__file__).resolve().parent / "java" / "StrictMathBatch.java"
N = 1_000_000
Strict = Callable[..., np.ndarray]


@pytest.fixture(scope="module")
def strict(tmp_path_factory: pytest.TempPathFactory) -> Strict:
    javac = shutil.which("javac")
    assert javac is not None, "javac missing: run make system-deps"
    out = tmp_path_factory.mktemp("strictmath")
    subprocess.run([javac, "-d", str(out), str(JAVA_SOURCE)], check=True, capture_output=True)

    def run(fn: str, *args: np.ndarray) -> np.ndarray:
        flat = np.stack([np.ravel(a) for a in args], axis=1).astype("<f8")
        (out / "in.bin").write_bytes(flat.tobytes())
        cmd = ["java", "-cp", str(out), "StrictMathBatch", fn, str(out / "in.bin"), str(out / "out.bin")]
        subprocess.run(cmd, check=True, capture_output=True)
        return np.frombuffer((out / "out.bin").read_bytes(), dtype="<f8")

    return run


def _mismatches(ours: np.ndarray, java: np.ndarray) -> np.ndarray:
    same = (ours.view(np.uint64) == java.view(np.uint64)) | (np.isnan(ours) & np.isnan(java))
    return np.nonzero(~same)[0]


def _bits(rng: np.random.Generator, n: int) -> np.ndarray:
    return rng.integers(0, 2**64, n, dtype=np.uint64).view(np.float64)


SPECIAL = np.array([0.0, -0.0, math.inf, -math.inf, math.nan, 1.0, -1.0, 0.5, -0.5, 2.0, -2.0, 3.0, -3.0,
                    2.0**-1074, -(2.0**-1074), 2.0**-1022, 1.7976931348623157e308, -1.7976931348623157e308,
                    2.0**31, -(2.0**31), 2.0**64, -(2.0**64), 2.0**-28, 2.0**-27, 709.782712893384,
                    -745.1332191019411, math.pi / 4, math.pi / 2, math.pi, 3 * math.pi / 4,
                    1e-300])  # fmt: skip


def test_exp_is_strictmath(strict: Strict) -> None:
    rng = np.random.default_rng(1)
    x = np.concatenate([-rng.random(N) * 40, (rng.random(N) - 0.5) * 1500, (rng.random(N // 10) - 0.5) * 1e-6,
                        _bits(rng, N), SPECIAL])  # fmt: skip
    bad = _mismatches(fdlibm.exp(x), strict("exp", x))
    assert bad.size == 0, [(x[i], fdlibm.exp(x[i]), strict("exp", x[i : i + 1])) for i in bad[:3]]


def test_cos_is_strictmath_up_to_its_medium_arguments(strict: Strict) -> None:
    """Exact to 2**19 pi/2 (fdlibm's multi-precision reduction beyond is not reimplemented:
    no membership function takes the cosine of such an argument)."""
    rng = np.random.default_rng(2)
    near = np.concatenate([k * (math.pi / 2) + rng.integers(-8, 9, 500) * np.spacing(k * (math.pi / 2))
                           for k in range(1, 70)])  # fmt: skip
    bits = _bits(rng, N)
    bits = bits[np.abs(bits) <= 2**19 * math.pi / 2]
    x = np.concatenate([(rng.random(N) * 2 - 1) * math.pi * 1.01, (rng.random(N) - 0.5) * 2**20, near, bits,
                        SPECIAL])  # fmt: skip
    bad = _mismatches(fdlibm.cos(x), strict("cos", x))
    assert bad.size == 0, [(x[i], fdlibm.cos(x[i])) for i in bad[:3]]
    huge = np.array([1e6, -3e9, 1e300, math.inf])  # beyond: C's libm, within an ulp
    assert np.allclose(fdlibm.cos(huge[:3]), strict("cos", huge[:3]), rtol=0, atol=1e-15)
    assert math.isnan(fdlibm.cos(huge[3:])[0])


def test_pow_is_strictmath(strict: Strict) -> None:
    rng = np.random.default_rng(3)
    x = np.concatenate([rng.random(N) * 1e3, _bits(rng, N), np.repeat(SPECIAL, SPECIAL.size)])
    y = np.concatenate([rng.random(N) * 20, _bits(rng, N), np.tile(SPECIAL, SPECIAL.size)])
    bad = _mismatches(fdlibm.pow_(x, y), strict("pow", x, y))
    assert bad.size == 0, [(x[i], y[i], fdlibm.pow_(x[i], y[i])) for i in bad[:3]]


def test_a_libm_is_not_enough(strict: Strict) -> None:
    """Why this module exists: C's libm (and numpy's vector code) differ from StrictMath in
    the last bit on some of a Gaussian's arguments, which decides jFuzzyLogic's ties."""
    x = -np.random.default_rng(4).random(100_000) * 40
    java = strict("exp", x)
    assert _mismatches(np.array([math.exp(v) for v in x]), java).size > 0
    assert _mismatches(fdlibm.exp(x), java).size == 0
