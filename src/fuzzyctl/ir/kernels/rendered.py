"""An exact Mamdani output on columns of samples for a method whose registry entry names no
hand-written numpy kernel (its ``numpy`` is empty): the method's IR, rendered.

The output's IR is the native evaluator's (:meth:`fuzzyctl.ir.programs.native.NativeBuilder.exact_output`:
the pieces of :mod:`fuzzyctl.ir.builders.grid_pieces`, then the builder the entry names as
``ir``), built once per output as a small program whose inputs are the degree and the
weight of each activated set, and printed

* as numpy (:mod:`fuzzyctl.ir.render.npsrc`, if-converted: every row at once; an array
  indexed by a value that differs between rows is read with a gather and written with
  masked stores, a loop whose end does runs masked: ``gather=True``), or, should that
  printer still refuse,
* as Python (:mod:`fuzzyctl.ir.render.pysrc`), called row by row.

Where the IR has no form of the method (a grid cut at run time, an accumulation whose pieces
are not linear between the candidate points: BSUM, PROBOR), and for a row where Python raises
on an IEEE infinity, the row is the reference's (:func:`fuzzyctl.engine.reference.pwl.defuzzify_pieces`).
Every path is thus the reference or the IR the native backend compiles; none is a third copy
of the method.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from fuzzyctl.engine.plan import OutputPlan, Plan
from fuzzyctl.engine.reference import pwl
from fuzzyctl.ir.nodes import Program
from fuzzyctl.ir.state import CodegenError

Arr = npt.NDArray[np.float64]
Result = tuple[Arr, npt.NDArray[np.bool_]]
#: One activated set on columns: (term, degree, weight, MIN activation)
Group = tuple[int, Any, Any, bool]
Columns = Callable[[int, list[Any]], Result]


def output_kernel(plan: Plan, op: OutputPlan, layout: Sequence[tuple[int, str]]) -> Columns:
    """``f(n, [a0, w0, a1, w1, ...]) -> (value, fired)`` for output ``op`` whose activated
    sets are ``layout`` (term, activation) in this order: the IR printed as numpy, else as
    Python row by row, else the reference row by row (see the module docstring); the
    function's ``how`` attribute says which (``"numpy"``, ``"python rows"``,
    ``"reference rows"``)."""
    try:
        fp = _program(plan, op, layout, "np")
        from fuzzyctl.ir.render.npsrc import vectorise

        batch = vectorise(fp, gather=True)
    except CodegenError:
        pass
    else:

        def columns(n: int, cols: list[Any]) -> Result:
            # every input a column: a weight the same for every row would otherwise be a
            # Python number, whose division by 0 raises where numpy gives inf
            arrays = [np.broadcast_to(np.asarray(c, dtype=np.float64), (n,)) for c in cols]
            value, fired = batch(arrays, [], n)
            return np.asarray(value, dtype=np.float64), np.asarray(fired) > 0.0

        columns.how = "numpy"  # type: ignore[attr-defined]
        return columns
    try:
        from fuzzyctl.ir.render.pysrc import specialise

        one = specialise(_program(plan, op, layout, "py"))
    except CodegenError:
        one = None
    return _rows(op, layout, one)


def _rows(op: OutputPlan, layout: Sequence[tuple[int, str]], one: Callable[..., Any] | None) -> Columns:
    """Row by row: the IR printed as Python (``one``), else the reference."""
    from fuzzyctl.kinds import norms

    def columns(n: int, cols: list[Any]) -> Result:
        lists = [np.broadcast_to(np.asarray(c, dtype=np.float64), (n,)).tolist() for c in cols]
        value = np.full(n, np.nan)
        fired = np.zeros(n, dtype=bool)
        for i in range(n):
            row = [c[i] for c in lists]
            try:
                if one is None:
                    raise ArithmeticError
                v, f = one(row, [])
            except ArithmeticError:  # Python raises where the IEEE value is inf or NaN
                sets = [(t, row[2 * k], row[2 * k + 1], act) for k, (t, act) in enumerate(layout)]
                got = reference(op, [(t, a, w, norms.is_min(act)) for t, a, w, act in sets])
                v, f = (got, True) if got is not None else (np.nan, False)
            value[i], fired[i] = v, bool(f)
        return value, fired

    columns.how = "python rows" if one is not None else "reference rows"  # type: ignore[attr-defined]
    return columns


def reference(op: OutputPlan, sets: Sequence[tuple[int, float, float, bool]]) -> float | None:
    """The reference's value of one row on the output's constant grid (None: no rule fired)."""
    grid = op.grid
    assert grid is not None
    live = [s for s in sets if s[1] * s[2] > 0.0]
    accu = op.accu or "MAX"
    pieces = pwl.grid_pieces(grid, live, accu)
    points = list(zip(grid.xs, pwl.point_values(grid, live, accu), strict=True))
    return pwl.defuzzify_pieces(op.method, pieces, points)


def _program(plan: Plan, op: OutputPlan, layout: Sequence[tuple[int, str]], target: str) -> Any:
    """The output's IR as a program of its own: inputs ``FZ_IN{2k}`` (degree) and
    ``FZ_IN{2k+1}`` (weight) of set ``k``, outputs the value and whether a rule fired."""
    from fuzzyctl.ir.programs.evaluator import FastProgram
    from fuzzyctl.ir.programs.evaluator import Group as IrGroup
    from fuzzyctl.ir.programs.native import NativeBuilder

    builder = NativeBuilder(plan, target)
    g = builder.g
    groups = []
    names = []
    for k, (t, act) in enumerate(layout):
        a = g.declare(f"FZ_IN{2 * k}", "REAL", "input")
        w = g.declare(f"FZ_IN{2 * k + 1}", "REAL", "input")
        names += [a.name, w.name]
        groups.append(IrGroup(t, a, w, act))
    value, fired = builder.exact_output(op, groups)
    out_v = g.declare("FZ_OUT0", "REAL", "output")
    out_f = g.declare("FZ_OUT1", "REAL", "output")
    g.b.set(out_v, value)
    g.b.set(out_f, 0.0)
    with g.b.if_(fired):
        g.b.set(out_f, 1.0)
    prog = Program(f"{plan.name or 'FUZZY'}_{op.name}", g.decls, g.b.root, [], g.uses)
    return FastProgram(prog, target, names, [out_v.name, out_f.name], "FZ_PREV", plan)
