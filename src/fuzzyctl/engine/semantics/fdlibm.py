"""Java's ``StrictMath.exp``, ``cos`` and ``pow``, vectorised: the algorithms of fdlibm 5.3
(Sun Microsystems' freely distributable math library, which Java specifies as the reference
for ``StrictMath``), reimplemented here on numpy arrays, bit for bit.

Why: jFuzzyLogic samples an output set at 1000 points, and MM, LM, RM and COA compare those
samples for equality.  When two samples of a Gaussian, bell, sigmoid or cosine term are equal
in one math library and one ulp apart in another, the tie goes the other way and the result
moves by a sample step.  C's libm (what :mod:`math` calls) and numpy's vector code (which
changes with the CPU) give another last bit on about 10% of a Gaussian's exponents and 3% of
a cosine's phases.  fdlibm is what
``StrictMath`` computes on every JVM, and what ``Math`` computes when HotSpot's libm
intrinsics are off (``-XX:-UseLibmIntrinsic``); docs/engine.md says where that matters.

numpy's float64 arithmetic is IEEE double without fused multiply-add, as Java's is, so each
operation below rounds as fdlibm's C does.  ``tests/engine/test_fdlibm.py`` compares every
bit with Java's ``StrictMath`` on millions of arguments.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from fuzzyctl.engine.semantics.fdlibm_pow import pow_

Arr = Any  # float64 arrays (or floats) broadcasting together

__all__ = ["cos", "exp", "pow_"]


def _f(bits: int) -> float:
    """The double whose IEEE bits are ``bits`` (the constants as fdlibm writes them)."""
    return float(np.array(bits, dtype=np.uint64).view(np.float64))


def _high(x: np.ndarray) -> np.ndarray:
    """The high 32-bit word of each double, as a signed integer (fdlibm's ``__HI``)."""
    return (x.view(np.int64) >> 32).astype(np.int32)


def _with_high(x: np.ndarray, high: np.ndarray) -> np.ndarray:
    """``x`` with its high word replaced (fdlibm's ``SET_HIGH_WORD``)."""
    low = x.view(np.uint64) & np.uint64(0xFFFFFFFF)
    return ((high.astype(np.int64).astype(np.uint64) << np.uint64(32)) | low).view(np.float64)


# ------------------------------------------------------------------------------------ exp

_LN2_HI = _f(0x3FE62E42FEE00000)
_LN2_LO = _f(0x3DEA39EF35793C76)
_INV_LN2 = _f(0x3FF71547652B82FE)
_P1 = _f(0x3FC555555555553E)
_P2 = _f(0xBF66C16C16BEBD93)
_P3 = _f(0x3F11566AAF25DE2C)
_P4 = _f(0xBEBBBD41C5D26BF1)
_P5 = _f(0x3E66376972BEA4D0)
_O_THRESHOLD = _f(0x40862E42FEFA39EF)
_U_THRESHOLD = _f(0xC0874910D52D3051)
_TWO_M1000 = 2.0**-1000


def exp(x: Arr) -> np.ndarray:
    """``StrictMath.exp`` (fdlibm ``__ieee754_exp``) of every element."""
    x = np.asarray(x, dtype=np.float64)
    shape = x.shape
    x = x.reshape(-1)
    with np.errstate(all="ignore"):
        hx = _high(x) & 0x7FFFFFFF
        neg = x < 0
        # |x| in (0.5 ln2, 1.5 ln2): k = +-1 exactly
        near = (hx > 0x3FD62E42) & (hx < 0x3FF0A2B2)
        far = hx >= 0x3FF0A2B2
        kf = np.trunc(_INV_LN2 * x + np.where(neg, -0.5, 0.5))  # C's (int) truncates
        k = np.where(near, np.where(neg, -1, 1), np.where(far, kf, 0)).astype(np.int64)
        t = k.astype(np.float64)
        hi = np.where(near, x - np.where(neg, -_LN2_HI, _LN2_HI), np.where(far, x - t * _LN2_HI, x))
        lo = np.where(near, np.where(neg, -_LN2_LO, _LN2_LO), np.where(far, t * _LN2_LO, 0.0))
        r = hi - lo
        tt = r * r
        c = r - tt * (_P1 + tt * (_P2 + tt * (_P3 + tt * (_P4 + tt * _P5))))
        y0 = 1.0 - ((r * c) / (c - 2.0) - r)
        y = 1.0 - ((lo - (r * c) / (2.0 - c)) - hi)
        normal = k >= -1021
        kk = np.where(normal, k, k + 1000)
        scaled = _with_high(y, _high(y) + (kk << 20).astype(np.int32))
        scaled = np.where(normal, scaled, scaled * _TWO_M1000)
        out = np.where(k == 0, y0, scaled)
        out = np.where(hx < 0x3E300000, 1.0 + x, out)  # |x| < 2**-28
        out = np.where(x > _O_THRESHOLD, math.inf, out)
        out = np.where(x < _U_THRESHOLD, 0.0, out)
        out = np.where(np.isnan(x), x, out)
    return out.reshape(shape)


# ------------------------------------------------------------------------------------ cos

_C = [_f(b) for b in (0x3FA555555555554C, 0xBF56C16C16C15177, 0x3EFA01A019CB1590,
                      0xBE927E4F809C52AD, 0x3E21EE9EBDB4B1C4, 0xBDA8FAE9BE8838D4)]  # fmt: skip
_S = [_f(b) for b in (0xBFC5555555555549, 0x3F8111111110F8A6, 0xBF2A01A019C161D5,
                      0x3EC71DE357B1FE7D, 0xBE5AE5E68A2B9CEB, 0x3DE5D93A5ACFD57C)]  # fmt: skip
_INV_PIO2 = _f(0x3FE45F306DC9C883)
_PIO2 = [_f(b) for b in (0x3FF921FB54400000, 0x3DD0B4611A600000, 0x3BA3198A2E000000)]
_PIO2T = [_f(b) for b in (0x3DD0B4611A626331, 0x3BA3198A2E037073, 0x397B839A252049C1)]


def _kernel_cos(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    ix = _high(x) & 0x7FFFFFFF
    z = x * x
    r = z * (_C[0] + z * (_C[1] + z * (_C[2] + z * (_C[3] + z * (_C[4] + z * _C[5])))))
    small = 1.0 - (0.5 * z - (z * r - x * y))
    qx = np.where(ix > 0x3FE90000, 0.28125, _with_high(np.zeros_like(x), ix - 0x00200000))
    large = (1.0 - qx) - ((0.5 * z - qx) - (z * r - x * y))
    out = np.where(ix < 0x3FD33333, small, large)
    return np.where(ix < 0x3E400000, 1.0, out)  # |x| < 2**-27


def _kernel_sin(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """fdlibm ``__kernel_sin(x, y, 1)``: sin(x + y) with y the tail of a reduced argument."""
    ix = _high(x) & 0x7FFFFFFF
    z = x * x
    v = z * x
    r = _S[1] + z * (_S[2] + z * (_S[3] + z * (_S[4] + z * _S[5])))
    out = x - ((z * (0.5 * y - v * r) - y) - v * _S[0])
    return np.where(ix < 0x3E400000, x, out)


#: high words of n pi/2, n = 1..31: where x's high word differs, the first round is enough
_NPIO2_HW = np.array(
    [int(np.float64(n * (math.pi / 2)).view(np.int64) >> 32) for n in range(1, 32)], dtype=np.int32
)


def _rem_pio2(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """fdlibm ``__ieee754_rem_pio2`` for pi/4 < |x| <= 2**19 pi/2: (n, y0, y1) with
    x = n pi/2 + y0 + y1; further rounds of pi/2 where the first ones cancelled."""
    hx = _high(x)
    ix = hx & 0x7FFFFFFF
    t = np.abs(x)
    n = np.trunc(t * _INV_PIO2 + 0.5)
    r = t - n * _PIO2[0]
    w = n * _PIO2T[0]
    y0 = r - w
    ni = n.astype(np.int64)
    quick = (ni < 32) & (ix != _NPIO2_HW[np.clip(ni - 1, 0, 30)])
    j = ix >> 20
    need = ~quick
    for step, bits in ((1, 16), (2, 49)):
        need = need & (j - ((_high(y0) >> 20) & 0x7FF) > bits)
        w2 = n * _PIO2[step]
        r2 = r - w2
        w2 = n * _PIO2T[step] - ((r - r2) - w2)
        r = np.where(need, r2, r)
        w = np.where(need, w2, w)
        y0 = np.where(need, r - w, y0)
    y1 = (r - y0) - w
    # |x| < 3pi/4: n = 1, with the second part of pi/2 next to pi/2 itself
    special = ix < 0x4002D97C
    at_half_pi = ix == 0x3FF921FB
    z = t - _PIO2[0]
    z = np.where(at_half_pi, z - _PIO2[1], z)
    tail = np.where(at_half_pi, _PIO2T[1], _PIO2T[0])
    s0 = z - tail
    n = np.where(special, 1.0, n)
    y1 = np.where(special, (z - s0) - tail, y1)
    y0 = np.where(special, s0, y0)
    sign = np.where(hx < 0, -1.0, 1.0)
    return (n * sign).astype(np.int64), y0 * sign, y1 * sign


def cos(x: Arr) -> np.ndarray:
    """``StrictMath.cos`` (fdlibm) of every element; beyond 2**19 pi/2, where fdlibm takes
    its multi-precision reduction, C's libm (correctly rounded there in practice)."""
    x = np.asarray(x, dtype=np.float64)
    shape = x.shape
    x = x.reshape(-1)
    with np.errstate(all="ignore"):
        ix = _high(x) & 0x7FFFFFFF
        n, y0, y1 = _rem_pio2(x)
        q = n & 3
        c, s = _kernel_cos(y0, y1), _kernel_sin(y0, y1)
        reduced = np.where(q == 0, c, np.where(q == 1, -s, np.where(q == 2, -c, s)))
        out = np.where(ix <= 0x3FE921FB, _kernel_cos(x, np.zeros_like(x)), reduced)
        huge = ix > 0x413921FB
        if huge.any():
            out[huge] = [math.cos(v) if math.isfinite(v) else math.nan for v in x[huge]]
    return out.reshape(shape)
