"""Defuzzification of a fuzzy set known only at sample points.

The engine's own defuzzifiers integrate output sets exactly (:mod:`~fuzzyctl.engine.reference.pwl`,
:mod:`~fuzzyctl.engine.reference.quadrature`).  Some PLC blocks do not: the Schneider XFUZ block
computes its output sets on ``Discr`` points and defuzzifies those samples (XFUZ manual
2.2-5), and the singleton outputs of PLC blocks are a weighted mean.  These are the
definitions for such samples, in one place, for whoever needs them.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

__all__ = ["mean_of_maxima", "sampled_centroid", "weighted_mean"]

FloatArray = npt.NDArray[np.float64]


def sampled_centroid(xs: FloatArray | Sequence[float], mu: FloatArray | Sequence[float]) -> float | None:
    """Centre of gravity of samples: ``sum(mu x) / sum(mu)``; None when every degree is 0."""
    x = np.asarray(xs, dtype=np.float64)
    m = np.asarray(mu, dtype=np.float64)
    total = float(m.sum())
    if not total > 0.0:
        return None
    return float((m * x).sum() / total)


def mean_of_maxima(xs: FloatArray | Sequence[float], mu: FloatArray | Sequence[float]) -> float | None:
    """Mean of the abscissae where the degree is largest; None when every degree is 0."""
    x = np.asarray(xs, dtype=np.float64)
    m = np.asarray(mu, dtype=np.float64)
    if m.size == 0:
        return None
    top = float(m.max())
    if not top > 0.0:
        return None
    return float(x[m == top].mean())


def weighted_mean(values: Sequence[float], weights: Sequence[float]) -> float | None:
    """``sum(w v) / sum(w)`` (singleton outputs); None when the weights sum to 0."""
    total = float(sum(weights))
    if not total > 0.0:
        return None
    return float(sum(w * v for v, w in zip(values, weights, strict=True)) / total)
