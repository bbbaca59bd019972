"""A model without inputs: a batch has as many rows as ``rows=`` (default one row for a dict,
a DataFrame's length), each the value ``evaluate({})`` gives - never 0 rows."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.diagnostics import InputError

FCL = """
FUNCTION_BLOCK z
VAR_OUTPUT y : REAL; END_VAR
DEFUZZIFY y
    RANGE(0..10);
    TERM low := TRIAN 0 1 4;
    METHOD : COG;
    DEFAULT := 7;
END_DEFUZZIFY
END_FUNCTION_BLOCK
"""


@pytest.mark.parametrize("backend", ["interpreted", "python", "native"])
def test_batch_without_inputs_has_rows(backend: str) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ctl = fuzzyctl.compile(fuzzyctl.load(FCL), backend=backend)
        one = ctl.evaluate({})["y"]
        assert one == 7.0  # no rule fires: DEFAULT
        assert ctl.evaluate_batch({})["y"].tolist() == [one]
        assert ctl.evaluate_batch({}, rows=3)["y"].tolist() == [one] * 3
        assert ctl.evaluate_batch({}, rows=0)["y"].tolist() == []


def test_rows_must_match_the_columns() -> None:
    ctl = fuzzyctl.compile(
        fuzzyctl.load(FCL.replace("VAR_OUTPUT", "VAR_INPUT x : REAL; END_VAR\nVAR_OUTPUT"))
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert len(ctl.evaluate_batch({"x": np.array([1.0, 2.0])}, rows=2)["y"]) == 2
        with pytest.raises(InputError, match="rows=3"):
            ctl.evaluate_batch({"x": np.array([1.0, 2.0])}, rows=3)
        with pytest.raises(InputError, match="non-negative"):
            ctl.evaluate_batch({"x": np.array([1.0])}, rows=-1)
