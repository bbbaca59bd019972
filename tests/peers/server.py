"""The peer side of tests/peers/__init__.py: runs in `.venv-peers` (pyfuzzylite, scikit-fuzzy and
simpful pin numpy < 2, so they never enter the project's venv) and answers one JSON request
per line on stdin with one JSON line on stdout.

A request is ``{"code": "...", "vars": {...}}``: the code runs with ``np``, ``math``, ``fl``
(pyfuzzylite), ``fuzz`` (scikit-fuzzy) and the vars bound (lists of numbers become numpy
arrays) and leaves its answer in ``result``; numpy values come back as lists.  An exception
comes back as ``{"error": "..."}``.  This file imports nothing of fuzzyctl or of the tests."""

from __future__ import annotations

import json
import math
import sys
import traceback
import warnings
from typing import Any

import fuzzylite as fl
import numpy as np
import skfuzzy as fuzz


def _arrays(value: Any) -> Any:
    if isinstance(value, list) and value and all(isinstance(v, (int, float)) for v in value):
        return np.asarray(value, dtype=float)
    return value


def _plain(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    return value


def main() -> None:
    for line in sys.stdin:
        request = json.loads(line)
        scope: dict[str, Any] = {"np": np, "math": math, "fl": fl, "fuzz": fuzz, "warnings": warnings}
        scope.update({k: _arrays(v) for k, v in request.get("vars", {}).items()})
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                exec(request["code"], scope)  # test code from our own suite, never user input
            answer = {"result": _plain(scope.get("result"))}
        except Exception:
            answer = {"error": traceback.format_exc()}
        sys.stdout.write(json.dumps(answer) + "\n")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
