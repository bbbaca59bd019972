"""The libm stand-ins of the generated C (``ir/render/c_helpers.py``) against Python's math.

All helpers are compiled in one strict cc run with vectorised wrappers and evaluated on many
values spread over the whole range (tiny, huge, subnormal, near the reduction boundaries);
each must agree with Python's (correctly or nearly correctly rounded) libm to 1e-14
relative - near zeros of the function, to 1e-14 of the argument scale - and reproduce its
special values (0, inf, NaN, domain errors)."""

from __future__ import annotations

import ctypes
import math
import shutil
import subprocess
from collections.abc import Callable

import numpy as np
import pytest

from fuzzyctl.ir.render import c_helpers

UNARY = {
    "fz_sqrt": math.sqrt,
    "fz_log": math.log,
    "fz_log10": math.log10,
    "fz_fabs": math.fabs,
    "fz_sin": math.sin,
    "fz_cos": math.cos,
    "fz_tan": math.tan,
    "fz_sinh": math.sinh,
    "fz_cosh": math.cosh,
    "fz_tanh": math.tanh,
    "fz_atan": math.atan,
    "fz_asin": math.asin,
    "fz_acos": math.acos,
    "fz_floor": math.floor,
    "fz_ceil": math.ceil,
    "fz_rint": round,
}
BINARY = {"fz_pow": math.pow, "fz_atan2": math.atan2, "fz_fmod": math.fmod}
TOL = 1e-14
_NUMPY = {"pow": np.power, "asin": np.arcsin, "acos": np.arccos, "fmod": np.fmod}


@pytest.fixture(scope="module")
def lib(tmp_path_factory: pytest.TempPathFactory) -> ctypes.CDLL:
    cc = shutil.which("cc")
    if cc is None:
        pytest.fail("the C tests need the system compiler 'cc'")
    out = tmp_path_factory.mktemp("helpers")
    src = ["#include <math.h>", *c_helpers.render(set(c_helpers.HELPERS))]
    for n in UNARY:
        src.append(
            f"void v_{n}(long k, const double *a, double *o)"
            f" {{ long i; for (i = 0; i < k; i++) o[i] = {n}(a[i]); }}"
        )
    for n in BINARY:
        src.append(
            f"void v_{n}(long k, const double *a, const double *b, double *o)"
            f" {{ long i; for (i = 0; i < k; i++) o[i] = {n}(a[i], b[i]); }}"
        )
    (out / "h.c").write_text("\n".join(src) + "\n")
    cmd = [cc, "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O1", "-ffp-contract=off"]
    res = subprocess.run(
        [*cmd, "-fPIC", "-shared", "-o", str(out / "h.so"), str(out / "h.c"), "-lm"],
        capture_output=True,
        text=True,
    )
    assert res.returncode == 0, res.stderr[:4000]
    return ctypes.CDLL(str(out / "h.so"))


def _call(lib: ctypes.CDLL, name: str, *cols: np.ndarray) -> np.ndarray:
    cols = tuple(np.ascontiguousarray(c, dtype=np.float64) for c in cols)
    out = np.empty(len(cols[0]))
    fn = getattr(lib, f"v_{name}")
    fn.argtypes = [ctypes.c_long] + [ctypes.c_void_p] * (len(cols) + 1)
    fn(len(out), *(c.ctypes.data for c in cols), out.ctypes.data)
    return out


def _want(f: Callable[..., float], *cols: np.ndarray) -> np.ndarray:
    out = []
    for args in zip(*cols, strict=True):
        try:
            out.append(float(f(*args)))
        except (ValueError, OverflowError):  # math raises where C returns NaN or +-inf (as numpy)
            with np.errstate(all="ignore"):
                out.append(float(_NUMPY.get(f.__name__, getattr(np, f.__name__, None) or np.nan)(*args)))
    return np.array(out)


def _worst(got: np.ndarray, want: np.ndarray, scale: np.ndarray) -> float:
    """Largest error relative to max(|want|, scale); NaN/inf must match exactly."""
    special = ~np.isfinite(want)
    nan_diff = np.isnan(got) != np.isnan(want)
    assert not nan_diff.any(), ("NaN mismatch", got[nan_diff][:5], want[nan_diff][:5])
    assert np.array_equal(got[special & ~np.isnan(want)], want[special & ~np.isnan(want)])
    ok = ~special
    den = np.maximum(np.abs(want[ok]), scale[ok])
    den[den == 0] = 1.0
    return float(np.max(np.abs(got[ok] - want[ok]) / den)) if ok.any() else 0.0


def _values(rng: np.random.Generator, n: int) -> np.ndarray:
    """Both signs, magnitudes from subnormal to huge, plus round numbers and specials."""
    mags = 10.0 ** rng.uniform(-310, 308, n)
    small = rng.uniform(-10, 10, n)
    edge = np.array([0.0, -0.0, 0.5, 1.0, 2.0, 0.25, 1.5, 2.5, 3.5, math.pi, math.pi / 4, 1e-300, 5e-324])
    specials = [math.inf, -math.inf, math.nan]
    return np.concatenate([mags * rng.choice([-1.0, 1.0], n), small, edge, -edge, specials])


def test_unary_helpers_match_python_math(lib: ctypes.CDLL) -> None:
    rng = np.random.default_rng(7)
    xs = _values(rng, 20_000)
    report = {}
    for name, f in UNARY.items():
        x = xs
        if name in ("fz_sin", "fz_cos", "fz_tan"):  # both reductions and their seam at 2^19
            seam = 524288.0 + np.arange(-64, 65) * 0.125
            x = np.concatenate([xs, rng.uniform(-1e6, 1e6, 20_000), seam, -seam])
        if name in ("fz_floor", "fz_ceil", "fz_rint"):  # math's versions return ints
            x = np.concatenate([x[np.isfinite(x)], rng.integers(-50, 50, 2000) / 4.0])
        got = _call(lib, name, x)
        want = _want(f, x)
        # near a zero of the function (sin at n*pi, log at 1, ...) judge against the argument
        relative_only = name in ("fz_cos", "fz_log", "fz_log10")
        scale = np.zeros_like(x) if relative_only else np.minimum(np.abs(x), 1.0)
        try:
            report[name] = _worst(got, want, scale)
        except AssertionError as exc:
            raise AssertionError(name, x[np.isnan(got) != np.isnan(want)][:5]) from exc
    print("\nhelpers, worst relative error:", {k: f"{v:.1e}" for k, v in report.items()})
    bad = {k: v for k, v in report.items() if not v <= TOL}
    assert not bad, bad


def test_sin_cos_of_huge_arguments_are_libms(lib: ctypes.CDLL) -> None:
    """Payne-Hanek beyond 2^19: relative to the value itself (no argument-scale allowance),
    including the double nearest a multiple of pi/2 (Kahan-McDonald's worst case, whose
    reduced argument is about 2^-61) and the fuzzer's sin(1e20)."""
    rng = np.random.default_rng(5)
    hard = [6381956970095103.0 * 2.0**797, 1e20, 1e22, 4e15, 1.7976931348623157e308, 2.0**53]
    x = np.concatenate([10.0 ** rng.uniform(5.7, 308, 20_000), hard])
    x = np.concatenate([x, -x])
    for name, f in (("fz_sin", math.sin), ("fz_cos", math.cos)):
        got, want = _call(lib, name, x), _want(f, x)
        assert _worst(got, want, np.zeros_like(x)) <= 4e-15, name


def test_binary_helpers_match_python_math(lib: ctypes.CDLL) -> None:
    rng = np.random.default_rng(11)
    n = 20_000
    report = {}
    # pow: the shapes' range (bell: |u|^(2b)); relative error grows with |p log a| like any
    # exp(p log a), so the arguments keep the result within 1e-30 .. 1e30
    a = 10.0 ** rng.uniform(-6, 6, n)
    p = rng.uniform(-5, 5, n)
    ints = rng.integers(-7, 8, 2000).astype(float)
    neg = -(10.0 ** rng.uniform(-3, 3, 2000))
    a = np.concatenate([a, neg, neg, [0.0, 0.0, 0.0, 2.0, -2.0, 1.0, math.nan]])
    p = np.concatenate([p, ints, rng.uniform(-3, 3, 2000), [2.0, -1.0, 0.0, 0.5, 0.5, math.nan, 0.0]])
    got, want = _call(lib, "fz_pow", a, p), _want(math.pow, a, p)
    report["fz_pow"] = _worst(got, want, np.zeros(len(a)))
    # exp(p log a) inherits log's last-place error times |p log a| (the documented bound);
    # |p log a| <= 1 (bell terms near their shoulders) is within TOL outright
    with np.errstate(all="ignore"):
        z = np.nan_to_num(np.abs(p * np.log(np.abs(a))))
        rel = np.abs(got - want) / np.abs(want)
    fin = np.isfinite(want) & (want != 0)
    assert np.all(rel[fin] <= 4.5e-16 * (1.0 + z[fin])), float(np.max(rel[fin] / (1.0 + z[fin])))
    assert np.all(rel[fin & (z <= 1.0)] <= TOL)
    report["fz_pow"] = float(np.max(rel[fin] / (1.0 + z[fin])))  # per unit of |p log a|
    y = rng.uniform(-10, 10, n) * 10.0 ** rng.uniform(-5, 5, n)
    x = rng.uniform(-10, 10, n) * 10.0 ** rng.uniform(-5, 5, n)
    y = np.concatenate([y, [0.0, 1.0, -1.0, 0.0, 1.0]])
    x = np.concatenate([x, [1.0, 0.0, 0.0, -1.0, -1.0]])
    # atan2 near +-pi changes sign across the negative x axis: judge at the scale of pi
    report["fz_atan2"] = _worst(_call(lib, "fz_atan2", y, x), _want(math.atan2, y, x), np.full(len(x), 1e-16))
    fx = rng.uniform(-1, 1, n) * 10.0 ** rng.uniform(-300, 300, n)
    fy = rng.uniform(-1, 1, n) * 10.0 ** rng.uniform(-300, 300, n)
    fx = np.concatenate([fx, [5.5, -5.5, 1.0, 3.0, math.inf]])
    fy = np.concatenate([fy, [2.0, 2.0, 0.0, math.inf, 1.0]])
    got = _call(lib, "fz_fmod", fx, fy)
    want = _want(math.fmod, fx, fy)
    # fmod is exact: bit for bit
    assert np.array_equal(got, want, equal_nan=True)
    print("\nhelpers, worst relative error:", {k: f"{v:.1e}" for k, v in report.items()})
    bad = {k: v for k, v in report.items() if not v <= TOL}
    assert not bad, bad


def test_specials_are_libm_specials(lib: ctypes.CDLL) -> None:
    one = lambda name, v: float(_call(lib, name, np.array([v]))[0])  # noqa: E731
    assert one("fz_sqrt", 0.0) == 0.0 and one("fz_sqrt", math.inf) == math.inf
    assert math.isnan(one("fz_sqrt", -1.0)) and math.isnan(one("fz_log", -1.0))
    assert one("fz_log", 0.0) == -math.inf and one("fz_log", 1.0) == 0.0
    assert one("fz_sqrt", 4.0) == 2.0 and one("fz_sqrt", 2.0) == math.sqrt(2.0)
    assert math.isnan(one("fz_cos", math.inf)) and math.isnan(one("fz_asin", 1.5))
    assert one("fz_rint", 2.5) == 2.0 and one("fz_rint", 3.5) == 4.0 and one("fz_rint", -2.5) == -2.0


def test_rendered_helpers_define_each_name_once_with_callees_first() -> None:
    order = c_helpers.closure({"fz_acos"})
    assert order.index("fz_sqrt") < order.index("fz_atan") < order.index("fz_atan2") < order.index("fz_acos")
    text = "\n".join(c_helpers.render({"fz_pow", "fz_log"}))
    assert text.count("static double fz_log(") == 1 and "fz_sin" not in text
