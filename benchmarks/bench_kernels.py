"""Section 7 of benchmarks/bench_engine.py (``--only kernels``): each hand-written kernel of
the evaluator program against its IR twin rendered in the same language, on one small rule
base per kernel, so that a kernel stays only where the rendered IR was measured slower.

* scalar (Python, us per call, CPU time, best of several rounds): ``kernels`` = the evaluator
  with the Python kernels of ir/kernels/scalar.py (``FastBuilder(plan, "py")``), ``IR`` = the
  native evaluator's IR printed as Python (``NativeBuilder(plan, "py")``), ``used`` = what
  ``Controller.evaluate`` runs (ir/programs/scalar.py: the IR, a kernel where it was slower);
* numpy (ns per row of a 20,000-row batch, one core): ``kernels`` = ir/kernels/columns.py
  (what ``evaluate_batch`` runs), ``IR`` = the native IR printed as numpy (``nan``: the IR
  indexes arrays by a value that differs between rows, which numpy's if-conversion cannot
  print), ``gather`` = the same IR printed with gathers and masked loops for those
  (``npsrc.vectorise(..., gather=True)``, what a method without a numpy kernel runs:
  ir/kernels/rendered.py).

Run alone: ``python benchmarks/bench_kernels.py [--quick]``.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import functools
import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import fuzzyctl
from fuzzyctl.engine.plan import Plan

FCL = """
FUNCTION_BLOCK kernels
VAR_INPUT a : REAL; b : REAL; c : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY a RANGE := (0 .. 10); TERM lo := (0, 1) ({knee}, 0); TERM hi := ({knee}, 0) (10, 1); END_FUZZIFY
FUZZIFY b RANGE := (0 .. 10); TERM lo := (0, 1) (10, 0); TERM hi := (0, 0) (10, 1); END_FUZZIFY
FUZZIFY c RANGE := (1 .. 9); TERM any := (0, 1) (10, 1); END_FUZZIFY
DEFUZZIFY y RANGE := (0 .. 10); {terms} METHOD : {method}; DEFAULT := 0; END_DEFUZZIFY
RULEBLOCK r AND : MIN; ACT : {act}; ACCU : {accu};
RULE 1 : IF a IS lo AND b IS lo THEN y IS s;
RULE 2 : IF a IS hi AND b IS lo THEN y IS m WITH {w};
RULE 3 : IF a IS lo AND b IS hi THEN y IS m;
RULE 4 : IF a IS hi AND b IS hi THEN y IS l;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""
SETS = "TERM s := (0,0) (2,1) (4,0); TERM m := (3,0) (5,1) (7,0); TERM l := (6,0) (8,1) (10,0);"
WIDE = "TERM s := (0,0) (4,1) (8,0); TERM m := (2,0) (5,1) (8,0); TERM l := (3,0) (7,1) (10,0);"
SMOOTH = "TERM s := GAUSSIAN 2 1; TERM m := GAUSSIAN 5 1.2; TERM l := GAUSSIAN 8 0.8;"
POINTS = "TERM s := 2; TERM m := 5; TERM l := 8;"
TSUKAMOTO = "TERM s := RAMP 2 6; TERM m := SIGMOID 5 1.5; TERM l := (2, 1) (5, 0.6) (9, 0);"

#: (row, the kernel it times, terms, METHOD, ACT, ACCU, WITH of rule 2, knee of a, activation)
ROWS: tuple[tuple[str, str, str, str, str, str, str, str, str | None], ...] = (
    ("CoG, 2 sets/interval", "AM_LINES", SETS, "COG", "MIN", "MAX", "1", "10", None),
    ("CoG, 3 sets/interval", "AM_LINES", WIDE, "COG", "MIN", "MAX", "0.7", "10", None),
    ("CoG PROBOR", "AM_LINES", SETS, "COG", "MIN", "PROBOR", "0.7", "10", None),
    ("CoA", "MAMDANI", SETS, "COA", "MIN", "MAX", "0.7", "10", None),
    ("LM", "MAMDANI", SETS, "LM", "MIN", "MAX", "0.7", "10", None),
    ("RM", "MAMDANI", SETS, "RM", "MIN", "MAX", "0.7", "10", None),
    ("MoM", "MAMDANI", SETS, "MOM", "MIN", "MAX", "0.7", "10", None),
    ("CoA SUM/PROD", "MAMDANI", SETS, "COA", "PROD", "SUM", "0.7", "10", None),
    ("CoA PROBOR", "MAMDANI", SETS, "COA", "MIN", "PROBOR", "1", "10", None),
    ("MoM BSUM", "MAMDANI", SETS, "MOM", "MIN", "BSUM", "0.7", "10", None),
    ("smooth CoG", "MAMDANI", SMOOTH, "COG", "MIN", "MAX", "1", "10", None),
    ("points from input", "MEMBER", SETS, "RM", "MIN", "MAX", "1", "c", None),
    ("rule activation", "SELECT", POINTS, "COGS", "MIN", "MAX", "1", "10", "Highest 2"),
    ("Tsukamoto", "TS", TSUKAMOTO, "WTAVER", "PROD", "MAX", "1", "10", None),
)


def plan_of(row: tuple[str, str, str, str, str, str, str, str, str | None]) -> Plan:
    _label, _kernel, terms, method, act, accu, w, knee, activation = row
    fb = fuzzyctl.load(FCL.format(terms=terms, method=method, act=act, accu=accu, w=w, knee=knee)).main
    if activation is not None:  # fuzzylite's rule activation: no FCL spelling
        blocks = tuple(dataclasses.replace(rb, rule_activation=activation) for rb in fb.rule_blocks)
        fb = dataclasses.replace(fb, rule_blocks=blocks)
    return fuzzyctl.compile(fb, backend="python").plan


def _best(fn: Callable[[], Any], rounds: int) -> float:
    best = float("inf")
    for _ in range(rounds):
        t0 = time.process_time()
        fn()
        best = min(best, time.process_time() - t0)
    return best


def scalar_us(plan: Plan, rows: list[list[float]], rounds: int) -> dict[str, float]:
    """us per call of the three scalar programs (module docstring), interleaved."""
    from fuzzyctl.ir.programs.evaluator import FastBuilder
    from fuzzyctl.ir.programs.native import NativeBuilder
    from fuzzyctl.ir.programs.scalar import build_scalar
    from fuzzyctl.ir.render.pysrc import specialise

    fns = {
        "kernels": specialise(FastBuilder(plan, "py").build()),
        "IR": specialise(NativeBuilder(plan, "py").build()),
        "used": specialise(build_scalar(plan)),
    }
    state: list[float | None] = [None] * len(plan.outputs)

    def loop(fn: Any) -> None:
        for r in rows:
            with contextlib.suppress(ArithmeticError, ValueError):  # the interpreter's call
                fn(r, state)

    best = dict.fromkeys(fns, float("inf"))
    for _ in range(rounds):
        for k, fn in fns.items():
            best[k] = min(best[k], _best(functools.partial(loop, fn), 1))
    return {k: v / len(rows) * 1e6 for k, v in best.items()}


def numpy_ns(plan: Plan, cols: list[np.ndarray], rounds: int) -> dict[str, float]:
    """ns per row of the batch with the numpy kernels and with the IR printed as numpy."""
    from fuzzyctl.ir.programs.evaluator import build_fast
    from fuzzyctl.ir.programs.native import NativeBuilder
    from fuzzyctl.ir.render.npsrc import vectorise
    from fuzzyctl.ir.state import CodegenError

    n = len(cols[0])
    fns = {"kernels": vectorise(build_fast(plan, "np"))}
    out = {"IR": math.nan, "gather": math.nan}  # NaN: the IR cannot be if-converted
    with contextlib.suppress(CodegenError):
        fns["IR"] = vectorise(NativeBuilder(plan, "np").build())
    with contextlib.suppress(CodegenError):
        fns["gather"] = vectorise(NativeBuilder(plan, "np").build(), gather=True)
    state: list[float | None] = [0.0] * len(plan.outputs)
    for k, fn in fns.items():
        fn(cols, state, n)
        out[k] = _best(functools.partial(fn, cols, state, n), rounds) / n * 1e9
    return out


def section_kernels(args: argparse.Namespace, work: Path, results: dict[str, Any]) -> None:
    """7. Each hand-written kernel against its rendered IR twin (module docstring)."""
    import warnings

    quick = bool(getattr(args, "quick", False))
    rounds = 5 if quick else 15
    rng = np.random.default_rng(7)
    n = 5_000 if quick else 20_000
    cols = [rng.uniform(0, 10, n), rng.uniform(0, 10, n), rng.uniform(1, 9, n)]
    rows = [[float(c[i]) for c in cols] for i in range(100)]
    print("\n7. kernels: hand-written against the IR rendered in the same language")
    print(
        f"{'row':22s} {'kernel':9s} {'py kernels':>10s} {'py IR':>8s} {'py used':>8s} "
        f"{'np kernels':>10s} {'np IR':>8s} {'np gather':>9s}"
    )
    out: dict[str, Any] = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for row in ROWS:
            plan = plan_of(row)
            py = scalar_us(plan, rows, rounds)
            npy = numpy_ns(plan, cols, max(3, rounds // 3))
            out[row[0]] = {"kernel": row[1], "py_us": py, "np_ns": npy}
            print(
                f"{row[0]:22s} {row[1]:9s} {py['kernels']:8.2f}us {py['IR']:6.2f}us {py['used']:6.2f}us "
                f"{npy['kernels']:8.0f}ns {npy['IR']:6.0f}ns {npy['gather']:7.0f}ns"
            )
    results["kernels"] = out


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    section_kernels(ap.parse_args(), Path("."), {})
