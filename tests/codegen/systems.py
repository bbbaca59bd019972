"""The systems the code generators are checked on, and random inputs for them.

* every FCL file in examples/ (all must be expressible in C and ST);
* every conformance system (tests/data/, vendored) the engine evaluates, minus the ones the
  C generator refuses (listed in :data:`NOT_EXPRESSIBLE_C` with the reason; a test checks
  the list is exactly what the generator refuses).
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Iterator
from functools import cache
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.diagnostics import DiagnosticError
from fuzzyctl.engine.plan import Plan, Slot
from fuzzyctl.model import Document
from tests.conftest import DATA, EXAMPLES


@pytest.fixture(scope="module", autouse=True)
def private_cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """The module's builds go to a fresh cache directory (and the user's cache is left
    alone); a test module takes it with ``private_cache = S.private_cache``."""
    path = tmp_path_factory.mktemp("cache")
    old = os.environ.get("FUZZYCTL_CACHE_DIR")
    os.environ["FUZZYCTL_CACHE_DIR"] = str(path)
    yield path
    if old is None:
        del os.environ["FUZZYCTL_CACHE_DIR"]
    else:
        os.environ["FUZZYCTL_CACHE_DIR"] = old


#: Conformance systems the C generator refuses, and why (docs/codegen.md repeats this).
NOT_EXPRESSIBLE_C = {
    "fuzzylite/tsukamoto/tsukamoto.fcl": "Tsukamoto (monotonic) output terms",
}


def example_files() -> list[Path]:
    return sorted(EXAMPLES.glob("*.fcl"))


def conformance_files() -> list[tuple[str, Path]]:
    """(relative name, path) of every conformance FCL the engine compiles."""
    root = DATA
    out = []
    for p in sorted(root.rglob("*.fcl")):
        if "original" in p.parts:
            continue
        try:
            fuzzyctl.compile(fuzzyctl.load(p))
        except DiagnosticError:
            continue  # refused by the engine itself (e.g. no RANGE): nothing to generate
        out.append((str(p.relative_to(root)), p))
    return out


@cache
def load(path: Path) -> Document:
    return fuzzyctl.load(path)


def plan_of(path: Path, name: str | None = None) -> Plan:
    """The engine's plan, renamed (C symbols must be unique when many systems share one
    library)."""
    plan = fuzzyctl.compile(load(path), backend="interpreted").plan
    return dataclasses.replace(plan, name=name) if name else plan


def input_bounds(plan: Plan, i: int) -> tuple[float, float]:
    """Where input ``i`` lives: [0, 1] for degrees, else the hull of the constant parameters
    of the terms it is fuzzified by or is a parameter of, with a 10 % margin."""
    if plan.inputs[i].degree:
        return 0.0, 1.0
    xs: list[float] = []
    for fi in plan.fuzzy_inputs:
        for t in fi.terms:
            refers = fi.slot == i or any(isinstance(p, Slot) and p.index == i for p in t.params)
            if not refers:
                continue
            if t.pwl is not None:
                xs += [x for x, _y in t.pwl]
            elif t.kind in ("points",):
                xs += [float(p) for p in t.params[0::2] if not isinstance(p, Slot)]
            else:
                xs += [float(p) for p in t.params[:1] if not isinstance(p, Slot)]
                if t.kind in ("gaussian", "bell", "spike", "cosine"):
                    c, w = t.params[0], t.params[1]
                    if not isinstance(c, Slot) and not isinstance(w, Slot):
                        xs += [float(c) - 3 * abs(float(w)), float(c) + 3 * abs(float(w))]
                elif len(t.params) > 1:
                    xs += [float(p) for p in t.params[1:] if not isinstance(p, Slot)]
    if not xs:
        return 0.0, 1.0
    lo, hi = min(xs), max(xs)
    w = (hi - lo) or 1.0
    return lo - 0.1 * w, hi + 0.1 * w


def random_inputs(plan: Plan, n: int, seed: int = 0, single: bool = False) -> np.ndarray:
    """(n, inputs) float64 samples; ``single``: values representable as float32 (what a REAL
    input holds), so that REAL code and the engine see the same numbers."""
    rng = np.random.default_rng(seed)
    cols = []
    for i in range(len(plan.inputs)):
        lo, hi = input_bounds(plan, i)
        cols.append(rng.uniform(lo, hi, n))
    data = np.column_stack(cols) if cols else np.zeros((n, 0))
    if single:
        data = data.astype(np.float32).astype(np.float64)
        if any(p.degree for p in plan.inputs):
            data = np.clip(data, 0.0, 1.0)
    return data


def output_scale(plan: Plan, oi: int, reference: np.ndarray) -> float:
    """The size errors are measured against: the output's range, else the spread of the
    reference values (at least 1)."""
    op = plan.outputs[oi]
    if op.low is not None and op.high is not None:
        return op.high - op.low
    finite = reference[np.isfinite(reference)]
    spread = float(finite.max() - finite.min()) if finite.size else 0.0
    return max(1.0, spread, float(np.abs(finite).max()) if finite.size else 1.0)


def reference(plan: Plan, data: np.ndarray, how: str = "fastest") -> np.ndarray:
    """The engine's outputs for successive rows of one instance: (n, is_output outputs).

    ``how``: ``"scalar"`` (the specialised scalar path, ``Controller.evaluate``), ``"batch"``
    (the numpy path; the engine's suite checks both against its interpreter) or ``"fastest"``
    (whichever is quicker on this system: the numpy path is slow on some many-rule outputs)."""
    import time

    from fuzzyctl.engine.controller import Controller

    if how == "fastest":
        probe = data[:200]
        times = {}
        for h in ("scalar", "batch"):
            t0 = time.perf_counter()
            reference(plan, probe, h)
            times[h] = time.perf_counter() - t0
        how = min(times, key=lambda h: times[h])
    ctl = Controller(plan, specialise=True)
    outs = [o.name for o in plan.outputs if o.is_output]
    if how == "batch" and plan.inputs:  # (no input column tells the row count of a batch)
        got = ctl.evaluate_batch({inp.name: data[:, i] for i, inp in enumerate(plan.inputs)})
        cols = [got[n] for n in outs]
        return np.column_stack(cols) if cols else np.zeros((len(data), 0))
    names = ctl.inputs
    rows = [ctl.evaluate(dict(zip(names, r, strict=True))) for r in data.tolist()]
    return np.array([[r[n] for n in outs] for r in rows], dtype=np.float64).reshape(len(data), len(outs))


def max_error(plan: Plan, got: np.ndarray, want: np.ndarray) -> float:
    """Largest |got - want| relative to each output's scale (NaN matches NaN)."""
    worst = 0.0
    outs = [oi for oi, o in enumerate(plan.outputs) if o.is_output]
    for k, oi in enumerate(outs):
        a, b = got[:, k], want[:, k]
        same = (np.isnan(a) & np.isnan(b)) | (a == b)
        with np.errstate(invalid="ignore"):
            err = np.where(same, 0.0, np.abs(a - b))
        err = np.where(np.isnan(err), np.inf, err)
        worst = max(worst, float(err.max(initial=0.0)) / output_scale(plan, oi, b))
    return worst
