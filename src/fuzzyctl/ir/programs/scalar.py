"""The evaluator program of ``compile()`` for single evaluations (``Controller.evaluate``):
every output written in the IR, as the native backend's program
(:class:`~fuzzyctl.ir.programs.native.NativeBuilder`), printed as Python by
:mod:`fuzzyctl.ir.render.pysrc`.

The defuzzification a single evaluation runs is then the one the C and the Structured Text
run (:mod:`fuzzyctl.ir.builders.mamdani`, :mod:`~fuzzyctl.ir.builders.pieces`,
:mod:`~fuzzyctl.ir.builders.grid_pieces`, :mod:`~fuzzyctl.ir.builders.quadrature`), not a
hand-written Python copy of it.  Printed as Python it was measured faster per call than
the kernels of :mod:`fuzzyctl.ir.kernels.scalar` (``benchmarks/bench_engine.py --only
kernels``, CPU time, one 2-input 4-rule base per row): CoG 12.2 -> 3.6 us, LM 46 -> 23,
RM 46 -> 32, MoM 48 -> 35, CoA 45 -> 42, CoA of SUM/PROD 31 -> 3.6, a smooth (Gaussian) CoG
3144 -> 333, terms given by inputs 58 -> 9, rule activation 2.1 -> 1.1, Tsukamoto 7.6 -> 1.0.

What stays a kernel in Python, and why:

* ``AM_LINES`` for three or more MIN-activated sets on one grid interval under MAX (its twin
  :func:`fuzzyctl.ir.builders.pieces.interval` measured as fast or up to 7% slower there);
* ``MAMDANI`` (the interpreter's code) for an exact output under BSUM, PROBOR or a sum of
  MIN-activated sets, where :mod:`fuzzyctl.ir.builders.grid_pieces` cuts the sets at every
  crossing and measured 2-28% slower (:func:`ir_exact`), and for what the IR does not
  express: a method other than CoG on smooth sets, a smooth term given by variables;
* ``EXPR`` (a function term; its IR twin is
  :meth:`~fuzzyctl.ir.builders.rules.RuleBuilder.function_term`): Python's arithmetic raises
  where the expression's IEEE value is ``inf`` or NaN, which ``eval_expr`` gives;
* ``HOLD`` (DEFAULT / NC / lock-range), which every renderer prints as a few lines.

Python raises where C gives ``inf`` or NaN (a Tsukamoto sigmoid at its height: ``log(0)``):
the controller then evaluates that call with the interpreter (``Controller.evaluate``).
"""

from __future__ import annotations

from fuzzyctl.engine.plan import OutputPlan, Plan
from fuzzyctl.engine.semantics import shapes
from fuzzyctl.ir.builders import quadrature as Q
from fuzzyctl.ir.builders.rules import Contrib, Params
from fuzzyctl.ir.nodes import Ex
from fuzzyctl.ir.programs.evaluator import FastBuilder, FastProgram
from fuzzyctl.ir.programs.native import NativeBuilder
from fuzzyctl.ir.state import CodegenError
from fuzzyctl.kinds import norms
from fuzzyctl.kinds.methods import METHODS


class ScalarBuilder(NativeBuilder):
    """The native evaluator program for the Python target (``"py"``), with the kernels of the
    module docstring where the IR does not express an output."""

    def __init__(self, plan: Plan) -> None:
        super().__init__(plan, "py")

    def _mamdani_kernel(self, oi: int, op: OutputPlan, contribs: list[Contrib]) -> tuple[Ex, Ex]:
        if not (ir_exact(op) if op.exact else ir_smooth(op)):
            return FastBuilder._mamdani_kernel(self, oi, op, contribs)
        return super()._mamdani_kernel(oi, op, contribs)

    def am_lines(
        self, x0: float, x1: float, accu: str, geom: tuple[tuple[float, float, bool], ...], args: list[Ex]
    ) -> tuple[Ex, Ex]:
        """The IR (:func:`~fuzzyctl.ir.builders.pieces.max_of_two`,
        :func:`~fuzzyctl.ir.builders.pieces.interval`), except three or more MIN-activated sets
        under MAX: there the AM_LINES kernel was measured as fast or up to 7% faster, while the
        IR wins elsewhere (3.5 against 12 us a call for two sets under MAX, 18 against 24 for
        PROBOR, 25-35% less for sums and PROD-activated sets)."""
        if len(geom) <= 2 or not norms.is_max(accu) or not all(mn for _l, _r, mn in geom):
            return super().am_lines(x0, x1, accu, geom, args)
        return FastBuilder.am_lines(self, x0, x1, accu, geom, args)

    def _ts_value(
        self, op: OutputPlan, t: int, values: dict[int, Ex], zs: dict[int, Ex], coef: Params, wt: Ex
    ) -> Ex:
        """A Tsukamoto term's inverse only where its weight is positive (where it is used):
        at weight 0 it divides by 0, which C carries as inf and Python raises."""
        if op.terms[t].kind not in shapes.TSUKAMOTO_KINDS:
            return super()._ts_value(op, t, values, zs, coef, wt)
        z = self.g.let(0.0, "TZ")
        with self.g.b.if_(wt.gt(0.0)):
            self.g.b.set(z, super()._ts_value(op, t, values, zs, coef, wt))
        return z


def ir_exact(op: OutputPlan) -> bool:
    """A piecewise-linear output whose IR (:mod:`fuzzyctl.ir.builders.grid_pieces`) was measured
    faster in Python than the interpreter's code: under MAX, or SUM / NSUM of PROD-activated
    sets (merged into one set per term).  Under BSUM, PROBOR or a sum of MIN-activated sets
    the IR cuts the sets at every crossing, which Python runs slower than the interpreter
    (the dryer's PROBOR CoA: 82 against 64 us a call)."""
    accu = op.accu or "MAX"
    return norms.is_max(accu) or (norms.adds(accu) and all(norms.is_prod(c.act) for c in op.contributions))


def ir_smooth(op: OutputPlan) -> bool:
    """A smooth Mamdani output the IR integrates (:func:`fuzzyctl.ir.builders.quadrature.smooth_cog`):
    a centroid method over terms with constant parameters and no function of x."""
    return METHODS[op.method].centroid and all(Q.constant_term(t) and t.kind != "function" for t in op.terms)


def build_scalar(plan: Plan) -> FastProgram:
    """The single-evaluation program of ``plan``: :class:`ScalarBuilder`, or, for a plan it
    refuses (a Tsukamoto term whose points are inputs, ...), the evaluator with the Python
    kernels (:func:`fuzzyctl.ir.programs.evaluator.build_fast`); raises
    :class:`CodegenError` when neither expresses the plan."""
    if plan.options.emulate is not None:
        raise CodegenError(f"the {plan.options.emulate} profile is evaluated by its own evaluator")
    try:
        return ScalarBuilder(plan).build()
    except CodegenError:
        return FastBuilder(plan, "py").build()
