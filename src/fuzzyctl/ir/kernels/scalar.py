"""The kernels of the evaluator program (:mod:`fuzzyctl.ir.programs.evaluator`) for one sample in
Python: each is the engine's own scalar code (:mod:`~fuzzyctl.engine.reference.pwl`, the interpreter's
output methods, :mod:`~fuzzyctl.engine.semantics.selection`), bound to its constant data once, when the
program is rendered.

``make(name, data, plan)`` returns the callable the rendered source calls.

Single evaluations run the native evaluator's IR printed as Python
(:mod:`fuzzyctl.ir.programs.scalar`); of these kernels it keeps only those measured faster than
their IR twin (``benchmarks/bench_engine.py --only kernels``) or that the IR does not express:

============  ==========================================================  ====================
kernel        IR twin                                                     kept for
============  ==========================================================  ====================
``AM_LINES``  :func:`fuzzyctl.ir.builders.pieces.interval`                3+ MIN sets on an
                                                                          interval under MAX
``MAMDANI``   :mod:`fuzzyctl.ir.builders.grid_pieces`,                    BSUM, PROBOR, sums of
              :func:`fuzzyctl.ir.builders.quadrature.smooth_cog`          MIN sets; smooth sets
                                                                          under LM/RM/MoM/CoA
``EXPR``      :meth:`fuzzyctl.ir.builders.rules.RuleBuilder.function_term`  IEEE inf/NaN
``SELECT``    :meth:`fuzzyctl.ir.programs.native.NativeBuilder.select`    a plan the IR refuses
``MEMBER``    :meth:`fuzzyctl.ir.programs.native.NativeBuilder.member`    a plan the IR refuses
``TS``        :func:`fuzzyctl.ir.builders.terms.tsukamoto`                a plan the IR refuses
============  ==========================================================  ====================
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

from fuzzyctl.engine.plan import Plan, Slot, TermPlan
from fuzzyctl.engine.reference import pwl
from fuzzyctl.engine.semantics import selection, shapes
from fuzzyctl.kinds import norms
from fuzzyctl.kinds.methods import METHODS

Kernel = Callable[..., Any]


def make(name: str, data: Any, plan: Plan) -> Kernel:
    """The scalar routine of kernel ``name`` with its constant ``data``."""
    if name == "AM_LINES":
        return am_lines(*data)
    if name == "SELECT":
        return lambda *d: tuple(selection.select(data, d))
    if name == "MEMBER":
        return member(data)
    if name == "EXPR":
        return expr(*data)
    if name in ("MAMDANI", "TS"):
        return whole_output(plan, *data)
    raise AssertionError(f"no Python kernel {name}")


def am_lines(x0: float, x1: float, accu: str, geom: tuple[tuple[float, float, bool], ...]) -> Kernel:
    """Area and moment of the accumulated activated sets on ``[x0, x1]`` (each term linear
    from L to R there); arguments: the degree and weight of each set."""
    if norms.is_max(accu) and len(geom) == 2:
        return _am_two(x0, x1, geom[0], geom[1])

    def f(*hw: float) -> tuple[float, float]:
        lines: list[pwl.Line] = []
        for k, (left, right, is_min) in enumerate(geom):
            a, w = hw[2 * k], hw[2 * k + 1]
            if a * w > 0.0:
                lines.append((left, right, a, w, is_min))
        if not lines:
            return 0.0, 0.0
        pieces: list[pwl.Piece] = []
        pwl.interval_pieces(x0, x1, lines, accu, pieces)
        return pwl.area_moment(pieces)

    return f


def _am_two(x0: float, x1: float, g1: tuple[float, float, bool], g2: tuple[float, float, bool]) -> Kernel:
    """Two sets under MAX: one set alone needs no cutting beyond its own kink."""

    def f(a1: float, w1: float, a2: float, w2: float) -> tuple[float, float]:
        on1, on2 = a1 * w1 > 0.0, a2 * w2 > 0.0
        lines: list[pwl.Line] = []
        if on1:
            lines.append((g1[0], g1[1], a1, w1, g1[2]))
        if on2:
            lines.append((g2[0], g2[1], a2, w2, g2[2]))
        if not lines:
            return 0.0, 0.0
        pieces: list[pwl.Piece] = []
        pwl.interval_pieces(x0, x1, lines, "MAX", pieces)
        return pwl.area_moment(pieces)

    return f


def member(t: TermPlan) -> Kernel:
    """A membership function whose parameters are inputs (``interp.term_degree``)."""

    def f(x: float, *values: float) -> float:
        params = [values[p.index] if isinstance(p, Slot) else p for p in t.params]
        h = values[t.height.index] if isinstance(t.height, Slot) else t.height
        return shapes.membership(t.kind, params, h, x)

    return f


def expr(e: Any, refs: tuple[int, ...], n_outputs: int) -> Kernel:
    """A function term: arguments x, the inputs, then the outputs it reads."""
    from fuzzyctl.engine.semantics.expr import eval_expr

    def f(x: float, *args: float) -> float:
        n_in = len(args) - len(refs)
        outs = [math.nan] * n_outputs
        for k, o in enumerate(refs):
            outs[o] = args[n_in + k]
        return eval_expr(e, args[:n_in], outs, x)

    return f


def whole_output(plan: Plan, oi: int, earlier: tuple[int, ...], sets: tuple[tuple[int, str], ...]) -> Kernel:
    """A whole output through the interpreter's code for it (Mamdani integration the
    closed form does not cover, Tsukamoto outputs); arguments: the inputs, the outputs
    computed earlier, then the degree and weight of each activated set."""
    from fuzzyctl.engine.reference.interp import Interpreter

    interp = Interpreter(plan)
    op = plan.outputs[oi]
    n_in = len(plan.inputs)
    n_out = len(plan.outputs)
    smooth_cog = (
        op.kind == "mamdani"
        and not op.exact
        and METHODS[op.method].centroid
        and all(t.constant for t in op.terms)
    )

    def f(*args: float) -> tuple[float, bool]:
        values: Sequence[float] = args[:n_in]
        outs = [math.nan] * n_out
        for k, o in enumerate(earlier):
            outs[o] = args[n_in + k]
        base = n_in + len(earlier)
        contribs: list[tuple[int | None, float, float, str]] = []
        for k, (t, act) in enumerate(sets):
            a, w = args[base + 2 * k], args[base + 2 * k + 1]
            if a * w > 0.0:
                contribs.append((t, a, w, act))
        if smooth_cog:  # the vectorised integration of a batch, on one row
            import numpy as np

            from fuzzyctl.ir.kernels.smooth_columns import smooth_output

            sets_1 = [(t or 0, a, w, act) for t, a, w, act in contribs]
            v, fired = smooth_output(plan, op, sets_1, [np.array([x]) for x in values], [], 1)
            return float(v[0]), bool(fired[0])
        rec = interp.output_from(op, contribs, values, outs)
        return rec.value, rec.fired

    return f
