"""Static analysis of a rule base: gaps, conflicts, redundancy, monotonicity and surface
facts (docs/analyze.md).  ``fuzzyctl.analyze(model)`` returns an :class:`Analysis`."""

from __future__ import annotations

from typing import TYPE_CHECKING

from fuzzyctl.analysis.report import Analysis

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path
    from typing import Any

    from fuzzyctl.analysis.usage import Coverage
    from fuzzyctl.model import Document, FunctionBlock

__all__ = ["Analysis", "analyze", "coverage"]


def analyze(
    model: Document | FunctionBlock,
    *,
    block: str | None = None,
    epsilon: float = 0.0,
    delta: float | None = None,
    monotone: list[str] | tuple[str, ...] = (),
    surface: bool = True,
) -> Analysis:
    """Analyse a function block (the first of a document unless ``block`` names one).

    ``epsilon``: a rule "fires" when its degree is >= epsilon (0, the default: > 0, where the
    output would fall to DEFAULT).  ``delta``: conflicts are pairs firing together above it
    (default 0.5).  ``monotone``: declarations ``"valve:-temp,+pressure"``.  ``surface``:
    sample the output surface (min, max, slope, jumps, monotonicity counterexamples).

    ```python
    >>> import fuzzyctl
    >>> found = fuzzyctl.analyze(fuzzyctl.load("examples/tank.fcl"))
    >>> found.gaps, found.conflicts, found.dead_rules      # the 25 rules cover every input
    ([], [], [])

    ```
    """
    from fuzzyctl.analysis import cells, conflicts, gaps, monotonicity, redundancy, table
    from fuzzyctl.analysis import surface as surf
    from fuzzyctl.analysis.context import build_context
    from fuzzyctl.diagnostics import FuzzyctlError

    if not 0.0 <= epsilon <= 1.0:
        raise FuzzyctlError(f"epsilon must be in [0, 1], got {epsilon}")
    delta = conflicts.DEFAULT_DELTA if delta is None else delta
    if not 0.0 <= delta < 1.0:
        raise FuzzyctlError(f"delta must be in [0, 1), got {delta}")
    ctx = build_context(model, block)
    plan = ctx.plan
    axes, coarse = cells.build_axes(ctx, epsilon)
    grid = cells.evaluate(ctx, axes, epsilon)
    outs = [(o, op.name) for o, op in enumerate(plan.outputs) if op.is_output]
    gap_list, fraction, coverage = gaps.find_gaps(grid, outs, epsilon)
    dead = {ri for ri in range(len(plan.rules)) if grid.rule_max[ri] <= 0.0}
    rows = [r for r in (table.as_row(ctx, ri) for ri in range(len(plan.rules))) if r is not None]
    tabs = table.axis_leaves(ctx, axes, rows)
    found = conflicts.find_conflicts(ctx, axes, [r for r in rows if r.rule not in dead], tabs, delta)
    redundant = redundancy.find_redundant(ctx, rows, tabs, dead)
    unused = redundancy.find_unused(ctx, dead)
    decls = monotonicity.parse_declarations(list(monotone), ctx.inputs, [n for _o, n in outs])
    sampled = surf.sample(ctx) if (surface or decls) and ctx.inputs else None
    mono = []
    for d in decls:
        bad, used = monotonicity.rule_table(ctx, rows, d)
        m = monotonicity.Monotonicity(d.output, d.input, d.sign, "violated" if bad else "holds", bad)
        m.proven = not bad and monotonicity.proven(ctx, used, d)
        if sampled is not None:
            m.counterexamples = surf.counterexamples(ctx, sampled, d.output, d.input, d.sign)
            m.resolution = sampled.resolution
        mono.append(m)
    facts = surf.facts(ctx, sampled, gap_list, epsilon) if surface and sampled is not None else []
    notes = list(grid.notes)
    if any(sum(c.output == n for c in found) >= conflicts.MAX_CONFLICTS for _o, n in outs):
        notes.append(
            f"conflicts: the first {conflicts.MAX_CONFLICTS} of an output are listed, there are more"
        )
    if coarse:
        notes.append(
            "smooth terms' peaks left out of the cells (too many): the gaps are still exact, the "
            "coverage index is a coarse upper bound"
        )
    if len(rows) < len(plan.rules):
        notes.append(
            f"{len(plan.rules) - len(rows)} rule(s) are not plain conjunctions: "
            "left out of conflicts and redundancy"
        )
    return Analysis(
        block=plan.name,
        inputs=dict(zip(ctx.inputs, ctx.ranges, strict=True)),
        epsilon=epsilon,
        delta=delta,
        gaps=gap_list,
        coverage_index=coverage,
        gap_fraction=fraction,
        conflicts=found,
        dead_rules=[ctx.rule_names[ri] for ri in sorted(dead)],
        redundant=redundant,
        unused_terms=unused,
        monotonicity=mono,
        surface=facts,
        exact=grid.exact,
        cells=int(grid.best[outs[0][0]].size) if outs else 0,
        notes=notes,
        rule_where=dict(zip(ctx.rule_names, ctx.rule_where, strict=True)),
    )


def coverage(
    model: Document | FunctionBlock,
    data: str | Path | list[str | Path],
    *,
    block: str | None = None,
    epsilon: float = 0.0,
    dask: bool = False,
    scheduler: Any = None,
    progress: Callable[[int, int], None] | None = None,
) -> Coverage:
    """How the rules were used over the rows of a log (CSV/Parquet file, directory or glob):
    per rule how often it fired (degree >= epsilon; 0: > 0) and dominated (the highest degree
    for an output it concludes), its mean and max degree; rows in a gap or outside a RANGE
    (docs/analyze.md, "Coverage from data").  ``dask=True``: the files as a dask dataframe,
    partitions counted in parallel on ``scheduler`` (a ``distributed.Client`` or a Dask
    scheduler name; None: Dask's default), the same numbers; ``progress(done, total)``."""
    from fuzzyctl.analysis import usage

    return usage.coverage(
        model, data, block=block, epsilon=epsilon, dask=dask, scheduler=scheduler, progress=progress
    )
