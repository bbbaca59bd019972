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
    """Tune a function block's parameters against data or a closed loop (docs/tune.md;
    the options are those of :func:`fuzzyctl.tune.api.tune`).

    ```python
    >>> import numpy as np, fuzzyctl
    >>> x = np.linspace(-1, 1, 41)
    >>> data = {"x": x, "y": x**2}
    >>> learned = fuzzyctl.learn(data, inputs=["x"], output="y", terms=3)
    >>> result = fuzzyctl.tune(learned.document, data=data, budget=20, workers=0)
    >>> result.optimizer, result.after <= result.before
    ('lsq', True)

    ```
    """
    from fuzzyctl.tune.api import tune as _tune

    return _tune(*args, **kwargs)


def learn(*args: Any, **kwargs: Any) -> LearnResult:
    """Learn a fuzzy system from a table (docs/tune.md; the options are those of
    :func:`fuzzyctl.tune.learning.learn`).

    ```python
    >>> import numpy as np, fuzzyctl
    >>> x = np.linspace(-1, 1, 41)
    >>> learned = fuzzyctl.learn({"x": x, "y": 2 * x + 1}, inputs=["x"], output="y", terms=3)
    >>> learned.rules, learned.scores["training RMSE"] < 1e-6     # a line is fitted exactly
    (3, True)

    ```
    """
    from fuzzyctl.tune.learning import learn as _learn

    return _learn(*args, **kwargs)


def evaluate_dataframe(*args: Any, **kwargs: Any) -> Any:
    """A lazy ``dask.dataframe`` with the controller's outputs appended (docs/tune.md; see
    :func:`fuzzyctl.tune.frames.evaluate_dataframe`).

    ```python
    >>> import dask.dataframe as dd, pandas as pd, fuzzyctl
    >>> frame = pd.DataFrame({"temp": [10.0, 3.0], "pressure": [60.0, 55.0]})
    >>> scored = fuzzyctl.evaluate_dataframe(dd.from_pandas(frame, npartitions=1),
    ...                                      fuzzyctl.load("examples/figure7.fcl"))
    >>> scored.compute(scheduler="sync")["valve"].round(6).tolist()   # as Controller.evaluate
    [51.851852, 100.0]

    ```
    """
    from fuzzyctl.tune.frames import evaluate_dataframe as _evaluate

    return _evaluate(*args, **kwargs)


__all__ = ["evaluate_dataframe", "learn", "tune"]


class _CallableModule(types.ModuleType):
    """``fuzzyctl.tune`` is this package and, called, :func:`tune`: the package name and the
    function name are the same word, and ``fuzzyctl.tune(...)`` is what users write."""

    def __call__(self, *args: Any, **kwargs: Any) -> TuneResult:
        return tune(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
