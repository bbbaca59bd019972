"""Vectorised, bit-exact reimplementation of fdlibm's ``__ieee754_pow``.

The algorithm is that of ``e_pow.c`` from fdlibm 5.3 (Copyright (C) 1993-2004
Sun Microsystems, Inc.; "Permission to use, copy, modify, and distribute this
software is freely granted, provided that this notice is preserved").  Java's
``StrictMath.pow`` is specified to return the fdlibm result.  This file is an
independent numpy reimplementation of that published algorithm (not a copy of
its source): both branches are evaluated for every element and the right one
is selected with masks.  numpy float64 arithmetic is IEEE double without FMA,
so every intermediate rounds exactly as in the reference.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]

_L1, _L2, _L3 = 5.99999999999994648725e-01, 4.28571428578550184252e-01, 3.33333329818377432918e-01
_L4, _L5, _L6 = 2.72728123808534006489e-01, 2.30660745775561754067e-01, 2.06975017800338417784e-01
_P1, _P2, _P3 = 1.66666666666666019037e-01, -2.77777777770155933842e-03, 6.61375632143793436117e-05
_P4, _P5 = -1.65339022054652515390e-06, 4.13813679705723846039e-08
_LG2, _LG2_H, _LG2_L = 6.93147180559945286227e-01, 6.93147182464599609375e-01, -1.90465429995776804525e-09
_OVT = 8.0085662595372944372e-17  # -(1024 - log2(ovfl + .5ulp))
_CP, _CP_H, _CP_L = 9.61796693925975554329e-01, 9.61796700954437255859e-01, -7.02846165095275826516e-09
_IVLN2, _IVLN2_H, _IVLN2_L = 1.44269504088896338700e00, 1.44269502162933349609e00, 1.92596299112661746887e-08
_DP_H, _DP_L = 5.84962487220764160156e-01, 1.35003920212974897128e-08  # log2(1.5) = dp_h + dp_l
_TWO53, _HUGE, _TINY = 9007199254740992.0, 1.0e300, 1.0e-300
_HI_MASK = np.int64(-(1 << 32))  # keeps the high word, clears the low word
_QUIET = np.int64(1 << 51)  # quiet-NaN bit


def _hi(a: F64) -> I64:
    """Signed high 32-bit word."""
    return a.view(np.int64) >> 32


def _lo(a: F64) -> I64:
    """Unsigned low 32-bit word."""
    return a.view(np.int64) & 0xFFFFFFFF


def _clear_lo(a: F64) -> F64:
    return (a.view(np.int64) & _HI_MASK).view(np.float64)


def _from_words(hi: I64, lo: I64 | int = 0) -> F64:
    return ((hi << 32) | lo).astype(np.int64).view(np.float64)


def _log2_near_one(ax: F64) -> tuple[F64, F64]:
    """log2(ax) = t1 + t2 for |ax - 1| <= 2**-20 (used when |y| > 2**31)."""
    t = ax - 1.0
    w = (t * t) * (0.5 - t * (0.3333333333333333333333 - t * 0.25))
    u = _IVLN2_H * t
    v = t * _IVLN2_L - w * _IVLN2
    t1 = _clear_lo(u + v)
    return t1, v - (t1 - u)


def _log2_ext(ax: F64) -> tuple[F64, F64]:
    """log2(ax) = t1 + t2 in extended precision, t1 with a zero low word."""
    ix = _hi(ax)
    sub = ix < 0x00100000
    ax = np.where(sub, ax * _TWO53, ax)
    ix = np.where(sub, _hi(ax), ix)
    n = np.where(sub, -53, 0) + (ix >> 20) - 0x3FF
    j = ix & 0x000FFFFF
    ix = j | 0x3FF00000
    k = ((j > 0x3988E) & (j < 0xBB67A)).astype(np.int64)  # |x| in [sqrt(3/2), sqrt(3))
    big = j >= 0xBB67A
    n = n + big
    ix = ix - big * 0x00100000
    ax = _from_words(ix, _lo(ax))
    bp = np.where(k == 1, 1.5, 1.0)
    u = ax - bp
    v = 1.0 / (ax + bp)
    ss = u * v
    s_h = _clear_lo(ss)
    t_h = _from_words(((ix >> 1) | 0x20000000) + 0x00080000 + (k << 18))
    t_l = ax - (t_h - bp)
    s_l = v * ((u - s_h * t_h) - s_h * t_l)
    s2 = ss * ss
    r = s2 * s2 * (_L1 + s2 * (_L2 + s2 * (_L3 + s2 * (_L4 + s2 * (_L5 + s2 * _L6)))))
    r = r + s_l * (s_h + ss)
    s2 = s_h * s_h
    t_h = _clear_lo(3.0 + s2 + r)
    t_l = r - ((t_h - 3.0) - s2)
    u = s_h * t_h
    v = s_l * t_h + t_l * ss
    p_h = _clear_lo(u + v)
    p_l = v - (p_h - u)
    z_h = _CP_H * p_h
    z_l = _CP_L * p_h + p_l * _CP + np.where(k == 1, _DP_L, 0.0)
    dp_h = np.where(k == 1, _DP_H, 0.0)
    t = n.astype(np.float64)
    t1 = _clear_lo(((z_h + z_l) + dp_h) + t)
    return t1, z_l - (((t1 - t) - dp_h) - z_h)


def _exp2_ext(p_h: F64, p_l: F64, j: I64) -> F64:
    """2**(p_h + p_l), where j is the high word of p_h + p_l (|.| < ~1075)."""
    i = j & 0x7FFFFFFF
    big = i > 0x3FE00000  # |z| > 0.5: split off the integer n = [z + 0.5]
    k = np.clip((i >> 20) - 0x3FF, -1, 30)
    m = j + (0x00100000 >> (k + 1))
    k = np.clip(((m & 0x7FFFFFFF) >> 20) - 0x3FF, 0, 20)
    t = _from_words(m & ~(0x000FFFFF >> k))
    n = ((m & 0x000FFFFF) | 0x00100000) >> (20 - k)
    n = np.where(big, np.where(j < 0, -n, n), 0)
    p_h = np.where(big, p_h - t, p_h)
    t = _clear_lo(p_l + p_h)
    u = t * _LG2_H
    v = (p_l - (t - p_h)) * _LG2 + t * _LG2_L
    z = u + v
    w = v - (z - u)
    t = z * z
    t1 = z - t * (_P1 + t * (_P2 + t * (_P3 + t * (_P4 + t * _P5))))
    r = (z * t1) / (t1 - 2.0) - (w + z * w)
    z = 1.0 - (r - z)
    normal = ((_hi(z) + (n << 20)) >> 20) > 0
    scaled = np.ldexp(z, np.where(normal, 0, n).astype(np.int32))
    shifted = (z.view(np.int64) + (np.where(normal, n, 0) << 52)).view(np.float64)
    return np.where(normal, shifted, scaled)


def _general(x: F64, y: F64, s: F64) -> F64:
    """Finite nonzero x (not +-1), finite y not special; s is the result sign."""
    ax = np.abs(x)
    ix, hy = _hi(ax), _hi(y)
    iy = hy & 0x7FFFFFFF
    huge_y = iy > 0x41E00000  # |y| > 2**31
    t1a, t2a = _log2_ext(ax)
    t1b, t2b = _log2_near_one(ax)
    t1, t2 = np.where(huge_y, t1b, t1a), np.where(huge_y, t2b, t2a)
    y1 = _clear_lo(y)
    p_l = (y - y1) * t1 + y * t2
    p_h = y1 * t1
    z = p_l + p_h
    j, i = _hi(z), _lo(z)
    over = (j >= 0x40900000) & ((((j - 0x40900000) | i) != 0) | (p_l + _OVT > z - p_h))
    under = ~over & (j < 0x40900000) & ((j & 0x7FFFFFFF) >= 0x4090CC00)
    under &= (((j & 0xFFFFFFFF) != 0xC090CC00) | (i != 0)) | (p_l <= z - p_h)
    res = s * _exp2_ext(p_h, p_l, j)
    res = np.where(over, s * _HUGE * _HUGE, np.where(under, s * _TINY * _TINY, res))
    # |y| > 2**31 and x not close to one: certain over/underflow
    ovf = ((ix < 0x3FEFFFFF) & (hy < 0)) | ((ix > 0x3FF00000) & (hy > 0))
    unf = ((ix < 0x3FEFFFFF) & (hy >= 0)) | ((ix > 0x3FF00000) & (hy <= 0))
    res = np.where(huge_y & ovf, s * _HUGE * _HUGE, res)
    res = np.where(huge_y & unf, s * _TINY * _TINY, res)
    # |y| > 2**64: over/underflow without the sign (y is even there anyway)
    big64 = iy > 0x43F00000
    lt1 = ix <= 0x3FEFFFFF
    res = np.where(big64 & (lt1 == (hy < 0)), _HUGE * _HUGE, res)
    return np.where(big64 & (lt1 != (hy < 0)), _TINY * _TINY, res)


def _special_x(x: F64, y: F64, yisint: I64) -> F64:
    """Result for x in {+-0, +-1, +-inf}."""
    z = np.abs(x)
    z = np.where(y < 0, 1.0 / z, z)
    nan = (z - z) / (z - z)  # (-1)**non-int is NaN
    neg = np.signbit(x)
    z = np.where(neg & (yisint == 1), -z, z)
    return np.where(neg & (np.abs(x) == 1.0) & (yisint == 0), nan, z)


def pow_(x: Any, y: Any) -> F64:
    """Bit-exact equivalent of Java ``StrictMath.pow(x, y)`` (fdlibm), elementwise."""
    xa, ya = np.broadcast_arrays(np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64))
    shape = xa.shape
    x, y = np.ascontiguousarray(xa).ravel(), np.ascontiguousarray(ya).ravel()
    with np.errstate(all="ignore"):
        ay = np.abs(y)
        finite_y = np.isfinite(y)
        is_int = finite_y & (np.floor(ay) == ay)
        odd = is_int & (ay < _TWO53) & (np.fmod(ay, 2.0) == 1.0)
        yisint: I64 = np.where(odd, 1, np.where(is_int, 2, 0))
        neg = np.signbit(x)
        s = np.where(neg & (yisint == 1), -1.0, 1.0)
        res = _general(x, y, s)
        res = np.where(neg & (yisint == 0), (x - x) / (x - x), res)
        ax = np.abs(x)
        sx = (ax == 0.0) | (ax == 1.0) | np.isinf(x)
        res = np.where(sx, _special_x(x, y, yisint), res)
        res = np.where((y == 0.5) & ~neg, np.sqrt(x), res)
        res = np.where(y == 2.0, x * x, res)
        res = np.where(y == 1.0, x, np.where(y == -1.0, 1.0 / x, res))
        inf_y = np.where(
            ax == 1.0, y - y, np.where(ax > 1.0, np.where(y > 0, y, 0.0), np.where(y < 0, -y, 0.0))
        )
        res = np.where(np.isinf(y), inf_y, res)
        # x + y on x86 (as in Java): the first NaN operand, quieted.  Done with bits,
        # since numpy's SIMD loops may swap the operands of a commutative add.
        nan_xy = (np.where(np.isnan(x), x, y).view(np.int64) | _QUIET).view(np.float64)
        res = np.where(np.isnan(x) | np.isnan(y), nan_xy, res)
        res = np.where(y == 0.0, 1.0, res)
    return res.reshape(shape)
