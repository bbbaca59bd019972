"""Lowering of outputs: method, accumulation, range and grid (used by
:mod:`~fuzzyctl.engine.lowering.lower`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Protocol

from fuzzyctl import model as m
from fuzzyctl.engine.lowering.grid import build_grid
from fuzzyctl.engine.lowering.terms import LowerContext, first_terms, lower_term, uses_x
from fuzzyctl.engine.plan import Contribution, GridPlan, OutputPlan, PParam, RulePlan, Slot, TermPlan
from fuzzyctl.engine.semantics import operators as ops
from fuzzyctl.engine.semantics import shapes, universe
from fuzzyctl.kinds import methods
from fuzzyctl.kinds import shapes as registry

#: other names of methods -> the code evaluated (kinds/methods.py)
METHOD_ALIASES = methods.lowering_aliases()


# --------------------------------------------------------------------------- outputs


class BlockSoFar(Protocol):
    """What lowering an output reads of its function block lowered so far (the block state of
    :mod:`~fuzzyctl.engine.lowering.lower` is one)."""

    rules: list[RulePlan]
    output_names: dict[str, int]
    concluded_terms: dict[str, list[tuple[int, m.Conclusion]]]
    concluded_bare: dict[str, list[tuple[int, m.Conclusion]]]

    def accu_for(self, name: str, db: m.DefuzzifyBlock | None) -> str | None: ...


@dataclass(frozen=True)
class _Defuzzified:
    """What every kind of plan of an output with a DEFUZZIFY block is made of."""

    var: m.Variable
    db: m.DefuzzifyBlock
    tps: tuple[TermPlan, ...]
    kinds: frozenset[str]
    method: str | None
    accu: str | None
    contributions: tuple[Contribution, ...]
    default: float | None
    no_change: bool

    def plan(
        self, kind: str, method: str, accu: str | None, terms: tuple[TermPlan, ...] | None = None, **more: Any
    ) -> OutputPlan:
        """The output's plan as ``kind`` (``terms``: other terms than its own; ``more``: the
        universe and grid of a Mamdani one)."""
        tps = self.tps if terms is None else terms
        return OutputPlan(
            self.var.name, kind, method, accu, tps, self.contributions, self.default, self.no_change, **more
        )


def lower_output(ctx: LowerContext, var: m.Variable, oi: int, b: BlockSoFar) -> OutputPlan | None:
    """The plan of output ``var`` (number ``oi``): a degree output without DEFUZZIFY block,
    else its terms, method and accumulation (None: an error was reported)."""
    db = ctx.fb.defuzzify_block(var.name)
    contributions = [
        Contribution(ri, ci, c.term, r.act, c.weight)
        for ri, r in enumerate(b.rules)
        for ci, c in enumerate(r.conclusions)
        if oi in c.outputs
    ]
    if db is None:
        if var.name in b.concluded_terms:
            ctx.err(
                f"output {var.name} is concluded with terms but has no DEFUZZIFY block",
                var.span,
                "no-defuzzify",
            )
            return None
        if var.name not in b.concluded_bare:
            ctx.warn(
                f"output {var.name} is never concluded by a rule and has no DEFUZZIFY block; it stays 0",
                var.span,
                "output-unused",
            )
        accu = b.accu_for(var.name, None) or "MAX"
        return OutputPlan(var.name, "degree", "DEGREE", accu, (), tuple(contributions), 0.0, False)
    if var.name in b.concluded_bare:
        ctx.err(
            f"output {var.name} has a DEFUZZIFY block but a rule concludes it without a term",
            b.concluded_bare[var.name][0][1].span,
            "bare-on-defuzzified",
        )
        return None
    return _defuzzified(ctx, var, db, b, contributions)


def _defuzzified(
    ctx: LowerContext,
    var: m.Variable,
    db: m.DefuzzifyBlock,
    b: BlockSoFar,
    contributions: list[Contribution],
) -> OutputPlan | None:
    """An output with a DEFUZZIFY block: its kind (singleton, Takagi-Sugeno, Tsukamoto,
    Mamdani) from its terms and method."""
    accu_for, output_names = b.accu_for, b.output_names
    terms = [lower_term(ctx, t, var.name, output_names, True) for t in first_terms(ctx, var.name, db.terms)]
    if any(t is None for t in terms):
        return None
    tps = tuple(t for t in terms if t is not None)
    default = db.default.value if db.default is not None else None
    no_change = db.default.no_change if db.default is not None else True
    method_raw = (db.method or "").upper() or None
    method = METHOD_ALIASES.get(method_raw, method_raw) if method_raw else None
    if method is not None and method not in m.DEFUZZ_METHODS:
        ctx.err(f"DEFUZZIFY {var.name}: unknown method {db.method!r}", db.span, "method-unknown")
        return None
    if not contributions:
        # Nothing is ever accumulated: the output is its DEFAULT (NC: its previous value), so
        # neither its universe nor how its terms combine matters (jFuzzyLogic's noRules test).
        ctx.warn(
            f"output {var.name}: no rule concludes it; it always gives its DEFAULT",
            db.span,
            "output-unused",
        )
        # (the jfuzzylogic profile keeps the terms: a condition may test its crisp value)
        kept = tps if ctx.options.emulate == "jfuzzylogic" else ()
        return OutputPlan(
            var.name, "singleton", "COGS", accu_for(var.name, db) or "MAX", kept, (), default, no_change
        )
    accu = accu_for(var.name, db)
    # a function of x is a fuzzy set (smooth, integrated numerically), not a Sugeno value
    kinds = {"function_of_x" if t.kind == "function" and uses_x(t.expr) else t.kind for t in tps}
    if not tps:
        ctx.err(f"DEFUZZIFY {var.name} has no terms", db.span, "no-terms")
        return None
    if ctx.options.emulate == "jfuzzylogic" and not _jfl_terms_fit(ctx, var, db, method, kinds):
        return None
    out = _Defuzzified(var, db, tps, frozenset(kinds), method, accu, tuple(contributions), default, no_change)
    singletonish = kinds <= {"singleton", "singletons"}
    ts_terms = bool(kinds & shapes.TS_KINDS)
    if (
        method in methods.WEIGHTED
        and kinds <= shapes.TSUKAMOTO_KINDS
        and all(t.kind != "points" or (t.pwl is not None and shapes.monotone(t.pwl)) for t in tps)
        and ctx.options.emulate is None
    ):
        # Tsukamoto: a weighted average of where each monotonic term reaches its degree
        if "points" in kinds:
            ctx.warn(
                f"DEFUZZIFY {var.name}: {method} over monotonic point terms is Tsukamoto inference "
                "(jfuzzyqt): each rule contributes where its term reaches the rule's degree",
                db.span,
                "tsukamoto-points",
            )
        return _ts_plan(ctx, out)
    if ts_terms or (singletonish and method in methods.TAKAGI_SUGENO):
        return _ts_output(ctx, out)
    if method is not None and methods.METHODS[method].on_pieces and (singletonish or ts_terms):
        ctx.err(
            f"DEFUZZIFY {var.name}: {method} applies to piecewise-linear fuzzy sets only",
            db.span,
            "method-terms",
        )
        return None
    if singletonish:
        if method is not None and methods.METHODS[method].bisects:
            ctx.err(
                f"DEFUZZIFY {var.name}: CoA is not applicable to singletons (IEC 61131-7 Table 1, note 3)",
                db.span,
                "coa-singletons",
            )
            return None
        meth = methods.singleton_method(method)
        s_accu = accu or ctx.options.singleton_default_accu or "MAX"
        return out.plan("singleton", meth, s_accu)
    if kinds & {"singleton", "singletons"}:
        ctx.err(
            f"DEFUZZIFY {var.name}: singletons cannot be mixed with fuzzy sets in one output",
            db.span,
            "mixed-terms",
        )
        return None
    return _mamdani_output(ctx, out)


def _ts_output(ctx: LowerContext, out: _Defuzzified) -> OutputPlan | None:
    """A Takagi-Sugeno output (constant, linear, function terms; singletons under WTAVER)."""
    fb, var, db = ctx.fb, out.var, out.db
    if not out.kinds <= shapes.TS_KINDS | {"singleton"}:
        ctx.err(
            f"DEFUZZIFY {var.name}: Takagi-Sugeno terms (constant, linear, function) "
            "cannot be mixed with fuzzy sets",
            db.span,
            "mixed-terms",
        )
        return None
    if out.method is not None and not (
        out.method in methods.WEIGHTED or methods.METHODS[out.method].centroid
    ):
        ctx.err(
            f"DEFUZZIFY {var.name}: {out.method} does not apply to Takagi-Sugeno terms (use WTAVER or WTSUM)",
            db.span,
            "method-ts",
        )
        return None
    for t in out.tps:
        if registry.flag(t.kind, "ts_linear") and len(t.params) > len(fb.inputs) + 1:
            ctx.err(
                f"term {var.name}.{t.name}: linear has {len(t.params)} coefficients for "
                f"{len(fb.inputs)} inputs",
                db.span,
                "linear-arity",
            )
            return None
    return _ts_plan(ctx, out)


def _ts_plan(ctx: LowerContext, out: _Defuzzified) -> OutputPlan:
    """The plan of a weighted (Takagi-Sugeno or Tsukamoto) output."""
    accu = out.accu if out.accu is not None else ctx.options.ts_default_accu
    return out.plan("ts", methods.ts_method(out.method), accu)


def _mamdani_output(ctx: LowerContext, out: _Defuzzified) -> OutputPlan | None:
    """A Mamdani output: its method, universe, and the grid of a constant piecewise-linear one."""
    var, db, tps, accu = out.var, out.db, out.tps, out.accu
    meth = out.method or "COG"
    if meth in methods.WEIGHTED:
        ctx.err(
            f"DEFUZZIFY {var.name}: {meth} needs singleton or Takagi-Sugeno terms", db.span, "method-terms"
        )
        return None
    bounds = _universe(ctx, var, db, tps)
    if bounds is None:
        return None
    low, high = bounds
    if low == high:
        # the terms span one point (jFuzzyLogic's DeMorgan tests: TERM v := (0, 1) (0, 1)):
        # every sample of the set is there, so the output is that point whenever a rule fires
        point = tuple(
            TermPlan(
                t.name,
                "singletons",
                (low, shapes.membership(t.kind, _consts(t.params), _const(t.height), low)),
            )
            for t in tps
        )
        return out.plan("singleton", "COGS", accu or "MAX", point)
    acc = accu or "MAX"
    acts = {c.act for c in out.contributions}
    exact = out.kinds <= shapes.PWL_KINDS and acts <= {"MIN", "PROD"} and acc in ops.EXACT_ACCU
    grid = None
    if exact and all(t.constant for t in tps):
        used = {c.term for c in out.contributions if c.term is not None}
        grid = build_grid([t.pwl for t in tps if t.pwl is not None], low, high, used)
        if not _finite_grid(grid):
            # closed forms whose coefficients overflow (a term rising 2e-308 over 2e-308, points
            # at 1e300): the integrals are taken numerically, as for curved terms
            grid, exact = None, False
    if methods.METHODS[meth].on_pieces and not exact:
        ctx.err(
            f"DEFUZZIFY {var.name}: {meth} applies to piecewise-linear fuzzy sets only "
            "(points or triangle/trapezoid-like terms, MIN or PROD activation)",
            db.span,
            "method-terms",
        )
        return None
    return out.plan("mamdani", meth, acc, low=low, high=high, exact=exact, grid=grid)


def _finite_grid(grid: GridPlan) -> bool:
    """Whether every number of ``grid``'s closed forms is finite (each becomes a literal of
    the generated evaluator, which has no infinite literals)."""
    numbers = [*grid.xs, *(c for bands in grid.min_bands for _lo, _hi, ac, mc in bands for c in (*ac, *mc))]
    numbers += [c for area_moment in grid.full for c in area_moment]
    numbers += [v for rows in (grid.left, grid.right, grid.point) for row in rows for v in row]
    return all(math.isfinite(v) for v in numbers)


def _universe(
    ctx: LowerContext, var: m.Variable, db: m.DefuzzifyBlock, tps: tuple[TermPlan, ...]
) -> tuple[float, float] | None:
    """The interval an area-based method integrates over: the RANGE if given, else the hull
    of the terms' supports; when a term does not fall to 0 outside a finite interval, the
    span of the terms as jFuzzyLogic computes it (:mod:`~fuzzyctl.engine.semantics.universe`), with a
    warning naming the term and the universe (an error under ``strict``).  The jFuzzyLogic
    profile always takes the span (its sample points depend on it) and ignores a RANGE on
    the declaration line."""
    opts = ctx.options
    rng = db.range if opts.ignore_declared_range else (db.range or var.range)
    if rng is not None:
        low, high = float(rng.low), float(rng.high)
        if not (math.isfinite(low) and math.isfinite(high) and low < high):
            ctx.err(f"DEFUZZIFY {var.name}: RANGE must be finite with min < max", rng.span, "range-invalid")
            return None
        return low, high
    for t in tps:
        if not t.constant:
            ctx.err(
                f"DEFUZZIFY {var.name}: term {t.name} has variable parameters; give a RANGE",
                db.span,
                "range-needed",
            )
            return None
    params = [[float(p) for p in t.params if not isinstance(p, Slot)] for t in tps]
    heights = [float(t.height) if not isinstance(t.height, Slot) else 1.0 for t in tps]
    supports = [shapes.support(t.kind, p, h) for t, p, h in zip(tps, params, heights, strict=True)]
    unbounded = next((t for t, s in zip(tps, supports, strict=True) if not all(map(math.isfinite, s))), None)
    if unbounded is None and not opts.span_universe:
        low, high = min(s[0] for s in supports), max(s[1] for s in supports)
    else:
        spans = [universe.span(t.kind, p) for t, p in zip(tps, params, strict=True)]
        low, high = min(s[0] for s in spans), max(s[1] for s in spans)
        if unbounded is not None:
            term = next((mt for mt in db.terms if mt.name == unbounded.name), None)
            where = term.span if term is not None and term.span is not None else db.span
            rule = universe.span_rule(unbounded.kind)
            message = (
                f"DEFUZZIFY {var.name}: term {unbounded.name} ({unbounded.kind}) is not 0 outside a "
                f"finite interval and there is no RANGE"
            )
            if opts.strict or not (math.isfinite(low) and math.isfinite(high)):
                ctx.err(
                    message + ("; give a RANGE" if opts.strict else "; its span is infinite: give a RANGE"),
                    where,
                    "range-needed",
                    hint=f"add RANGE := ({low:g} .. {high:g}); to DEFUZZIFY {var.name}"
                    if math.isfinite(low) and math.isfinite(high) and low < high
                    else None,
                )
                return None
            ctx.warn(
                message + f": the universe is [{low:g}, {high:g}], the span of its terms as "
                f"jFuzzyLogic computes it ({unbounded.name}: {rule})",
                where,
                "universe-from-terms",
            )
    if low == high and not opts.strict and math.isfinite(low):
        ctx.warn(
            f"DEFUZZIFY {var.name}: no RANGE and its terms span the single point {low:g} "
            f"(jFuzzyLogic's universe): the output is {low:g} whenever a rule fires",
            db.span,
            "universe-from-terms",
        )
        return low, high
    if not low < high:
        ctx.err(f"DEFUZZIFY {var.name}: the terms have no extent; give a RANGE", db.span, "range-needed")
        return None
    return low, high


def _consts(params: tuple[PParam, ...]) -> list[float]:
    return [float(p) for p in params if not isinstance(p, Slot)]


def _const(p: PParam) -> float:
    return float(p) if not isinstance(p, Slot) else 1.0


#: jFuzzyLogic's discrete terms (a HashMap of points), taken by its weighted methods
_JFL_DISCRETE = {"singleton", "singletons", "function"}


def _jfl_terms_fit(
    ctx: LowerContext, var: m.Variable, db: m.DefuzzifyBlock, method: str | None, kinds: set[str]
) -> bool:
    """jFuzzyLogic accumulates singleton and FUNCTION terms only into COGS/COGF (discrete)
    and every other term only into COG/COA/LM/RM/MM (sampled); METHOD defaults to COG.  It
    throws as soon as a rule concludes a term of the other sort, so its profile refuses."""
    if "singletons" in kinds:
        ctx.err(
            f"DEFUZZIFY {var.name}: jFuzzyLogic 3.3 cannot load SINGLETONS terms (its parser fails on "
            "them: 'Unknown (or unimplemented) option : VALUE_REAL')",
            db.span,
            "jfl-singletons",
        )
        return False
    meth = (db.method or "COG").upper()
    code = methods.jfl_spelled().get(meth)
    discrete = code is not None and methods.METHODS[code].weighted is not None
    wrong = sorted(kinds - _JFL_DISCRETE) if discrete else sorted(kinds & (_JFL_DISCRETE | {"function_of_x"}))
    if code is None:
        ctx.err(f"DEFUZZIFY {var.name}: jFuzzyLogic has no METHOD {db.method}", db.span, "jfl-method")
        return False
    if wrong:
        ctx.err(
            f"DEFUZZIFY {var.name}: jFuzzyLogic cannot accumulate {', '.join(wrong)} terms with METHOD "
            f"{meth}{'' if db.method else ' (its default)'}: "
            + ("COGS and COGF take singletons and FUNCTION terms" if discrete else "use COGS for singletons"),
            db.span,
            "jfl-method",
        )
        return False
    return True
