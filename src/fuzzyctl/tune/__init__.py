"""Design from data and from the plant: tune and learn fuzzy controllers, scale out on Dask.

* :func:`tune` - move the parameters a user frees (term points, singletons, Takagi-Sugeno
  coefficients, weights) against data or a closed-loop cost, every candidate valid;
* :func:`learn` - an initial system from data (grid partition or clustering, consequents
  by least squares);
* :func:`evaluate_dataframe` - score a ``dask.dataframe`` partition by partition.

See docs/tune.md.
"""

from __future__ import annotations

import sys
import types
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from fuzzyctl.tune.api import TuneResult
    from fuzzyctl.tune.learning import LearnResult


def tune(*args: Any, **kwargs: Any) -> TuneResult:
    """See :func:`fuzzyctl.tune.api.tune`."""
    from fuzzyctl.tune.api import tune as _tune

    return _tune(*args, **kwargs)


def learn(*args: Any, **kwargs: Any) -> LearnResult:
    """See :func:`fuzzyctl.tune.learning.learn`."""
    from fuzzyctl.tune.learning import learn as _learn

    return _learn(*args, **kwargs)


def evaluate_dataframe(*args: Any, **kwargs: Any) -> Any:
    """See :func:`fuzzyctl.tune.frames.evaluate_dataframe`."""
    from fuzzyctl.tune.frames import evaluate_dataframe as _evaluate

    return _evaluate(*args, **kwargs)


__all__ = ["evaluate_dataframe", "learn", "tune"]


class _CallableModule(types.ModuleType):
    """``fuzzyctl.tune`` is this package and, called, :func:`tune`: the package name and the
    function name are the same word, and ``fuzzyctl.tune(...)`` is what users write."""

    def __call__(self, *args: Any, **kwargs: Any) -> TuneResult:
        return tune(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
