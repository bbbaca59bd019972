"""The ``siemens`` profile: what a controller must respect to run in the S7 FUZZY block
(Siemens manual 1.3, 3.1 and 3.4).

Errors (the block cannot hold or compute it): more than 8 inputs, 7 terms per input, 4
outputs, 9 terms per output or 200 rules; more than one rule block; intermediate
variables; rules other than ``IF v IS t AND ... THEN out IS t`` (no OR, NOT, hedges,
weights, conclusions on inputs, conditions on outputs); input terms other than rectangle,
triangle or trapezoid; output terms other than constant singletons; operators other than
the block's own (AND MIN, ACCU MAX, singleton centre of gravity); names whose significant
characters (10 for variables, 7 for terms) collide.

Warnings (the block runs it, but differently from what the program says): a DEFAULT value
(the block keeps the last value instead), inputs or outputs without limits (the block needs
MIN and MAX).  Notes: longer names, of which only the significant characters are kept (the
manual's own FPLTEST has an 8-character "drainage").
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterable

from fuzzyctl.diagnostics import Diagnostic, Severity, error, warning
from fuzzyctl.model import (
    And,
    Condition,
    Document,
    FunctionBlock,
    Is,
    MembershipFunction,
    PointsMF,
    ShapeMF,
    SingletonMF,
    Span,
    VarKind,
    is_constant,
)

__all__ = ["LIMITS", "check_siemens", "input_shape"]

Report = Callable[[str, "Span | None", str], None]

LIMITS = {
    "inputs": 8,
    "input_terms": 7,
    "outputs": 4,
    "output_terms": 9,
    "rules": 200,
    "variable_name": 10,
    "term_name": 7,
}


def input_shape(mf: MembershipFunction) -> str | None:
    """``"rectangle"``, ``"triangle"`` or ``"trapezoid"`` when the block can hold ``mf``
    as an input term, else None.  IEC shoulders (a list starting or ending on degree 1)
    are trapezoids whose outer points sit at the limits of the input."""
    if isinstance(mf, ShapeMF):
        if (
            mf.kind in ("rectangle", "triangle", "trapezoid")
            and mf.height == 1.0
            and all(is_constant(p) for p in mf.params)
        ):
            return mf.kind
        return None
    if not isinstance(mf, PointsMF) or not mf.points:
        return None
    if not all(is_constant(p.x) and is_constant(p.y) for p in mf.points):
        return None
    pts = [(float(p.x), float(p.y)) for p in mf.points]  # type: ignore[arg-type]
    if any(y not in (0.0, 1.0) for _, y in pts) or any(b[0] < a[0] for a, b in itertools.pairwise(pts)):
        return None
    ys = [y for _, y in pts]
    # Collapse runs of equal degrees: the remaining pattern must be one plateau of 1.
    pattern = [ys[0]] + [y for prev, y in itertools.pairwise(ys) if y != prev]
    if pattern not in ([1.0], [0.0, 1.0], [1.0, 0.0], [0.0, 1.0, 0.0]):
        return None
    plateau = [x for x, y in pts if y == 1.0]
    rises = [(a, b) for a, b in itertools.pairwise(pts) if a[1] != b[1]]
    if len(pts) > 6:
        return None
    if all(a[0] == b[0] for a, b in rises):
        return "rectangle"
    return "triangle" if len(set(plateau)) == 1 else "trapezoid"


def _conditions(cond: Condition | None) -> Iterable[Condition]:
    if isinstance(cond, And):
        for c in cond.operands:
            yield from _conditions(c)
    elif cond is not None:
        yield cond


def check_siemens(model: FunctionBlock | Document) -> list[Diagnostic]:
    """Every way ``model`` exceeds the S7 FUZZY block, most precise location first."""
    fb = model.main if isinstance(model, Document) else model
    diags: list[Diagnostic] = []

    def err(msg: str, span: Span | None, code: str, hint: str | None = None) -> None:
        diags.append(error(msg, span, code=f"siemens-{code}", hint=hint))

    def warn(msg: str, span: Span | None, code: str) -> None:
        diags.append(warning(msg, span, code=f"siemens-{code}"))

    def note(msg: str, span: Span | None, code: str) -> None:
        diags.append(Diagnostic(Severity.NOTE, msg, span, code=f"siemens-{code}"))

    inputs, outputs = fb.inputs, fb.outputs
    for what, items, limit in (("inputs", inputs, LIMITS["inputs"]), ("outputs", outputs, LIMITS["outputs"])):
        if len(items) > limit:
            err(
                f"{len(items)} {what}; the FUZZY block has {limit} (INPUT1..8, OUTPUT1..4): "
                f"{', '.join(v.name for v in items[limit:])} cannot be connected",
                items[limit].span,
                f"too-many-{what}",
            )
    for v in fb.locals:
        err(f"intermediate variable {v.name}: the FUZZY block has no chained rules", v.span, "intermediate")

    seen: dict[str, str] = {}
    for v in (*inputs, *outputs):
        n = LIMITS["variable_name"]
        if len(v.name) > n:
            key = v.name[:n]
            if key in seen:
                err(
                    f"{v.name} and {seen[key]} are the same name for the block: only {n} characters are "
                    "significant",
                    v.span,
                    "name-collision",
                )
            else:
                note(f"{v.name}: only the first {n} characters ({key}) are significant", v.span, "long-name")
            seen.setdefault(key, v.name)
        if v.range is None:
            block = fb.fuzzify_block(v.name) if v.kind is VarKind.INPUT else fb.defuzzify_block(v.name)
            if block is None or block.range is None:
                warn(
                    f"{v.name} has no RANGE: the block needs MIN and MAX (taken from the terms)",
                    v.span,
                    "no-range",
                )

    for fz in fb.fuzzify:
        var = fb.variable(fz.variable)
        if var is not None and var.kind is not VarKind.INPUT:
            err(f"{fz.variable}: only inputs are fuzzified in the FUZZY block", fz.span, "fuzzify-non-input")
        if len(fz.terms) > LIMITS["input_terms"]:
            err(
                f"input {fz.variable} has {len(fz.terms)} terms; the block allows {LIMITS['input_terms']}",
                fz.terms[LIMITS["input_terms"]].span or fz.span,
                "too-many-terms",
            )
        _check_term_names(fz.variable, [t.name for t in fz.terms], [t.span for t in fz.terms], err, note)
        for t in fz.terms:
            if input_shape(t.mf) is None:
                err(
                    f"{fz.variable}.{t.name}: input terms are rectangles, triangles or trapezoids (degrees 0 "
                    "and 1, at most 4 points)",
                    t.span or fz.span,
                    "input-shape",
                )

    for dz in fb.defuzzify:
        if len(dz.terms) > LIMITS["output_terms"]:
            err(
                f"output {dz.variable} has {len(dz.terms)} terms; the block allows {LIMITS['output_terms']}",
                dz.terms[LIMITS["output_terms"]].span or dz.span,
                "too-many-terms",
            )
        _check_term_names(dz.variable, [t.name for t in dz.terms], [t.span for t in dz.terms], err, note)
        for t in dz.terms:
            if not isinstance(t.mf, SingletonMF) or not is_constant(t.mf.value):
                err(
                    f"{dz.variable}.{t.name}: output terms are singletons with a constant position",
                    t.span or dz.span,
                    "output-shape",
                    hint="in FPL a singleton is a narrow rectangle (1/200 of the range)",
                )
        if dz.method not in (None, "COGS", "COG"):
            err(
                f"{dz.variable}: METHOD : {dz.method}; the block computes the centre of gravity of "
                "singletons",
                dz.span,
                "method",
            )
        if dz.accu not in (None, "MAX"):
            err(f"{dz.variable}: ACCU : {dz.accu}; the block accumulates with MAX", dz.span, "operator")
        if dz.default is not None and not dz.default.no_change:
            warn(
                f"{dz.variable}: DEFAULT := {dz.default.value:g} is not used: when no rule fires the block "
                "keeps the last value (0 before the first)",
                dz.default.span or dz.span,
                "default",
            )

    if len(fb.rule_blocks) > 1:
        err(
            f"{len(fb.rule_blocks)} rule blocks; the FUZZY block has one set of rules",
            fb.rule_blocks[1].span,
            "rule-blocks",
        )
    n_rules = sum(len(rb.rules) for rb in fb.rule_blocks)
    if n_rules > LIMITS["rules"]:
        err(
            f"{n_rules} rules; the FUZZY block holds {LIMITS['rules']} (with 2 inputs and 1 output)",
            fb.rule_blocks[0].span,
            "too-many-rules",
        )
    input_names = {v.name for v in inputs}
    output_names = {v.name for v in outputs}
    for rb in fb.rule_blocks:
        if rb.and_op not in (None, "MIN"):
            err(f"AND : {rb.and_op}; the block uses MIN", rb.span, "operator")
        if rb.accu not in (None, "MAX"):
            err(f"ACCU : {rb.accu}; the block accumulates with MAX", rb.span, "operator")
        if not rb.enabled or rb.rule_activation is not None:
            err(f"rule block {rb.name}: the FUZZY block always fires every rule", rb.span, "rule-activation")
        if rb.act not in (None, "MIN", "PROD"):
            err(f"ACT : {rb.act}; the block uses MIN", rb.span, "operator")
        for rule in rb.rules:
            where = rule.span or rb.span
            for c in _conditions(rule.condition):
                if not isinstance(c, Is):
                    err(
                        f"rule {rule.label}: only AND joins conditions in the FUZZY block "
                        "(no OR, NOT or bare degrees)",
                        getattr(c, "span", None) or where,
                        "rule-operator",
                    )
                elif c.negated or c.hedges:
                    err(
                        f"rule {rule.label}: {c.variable} IS {'NOT ' if c.negated else ''}"
                        f"{' '.join(c.hedges)} {c.term}: no NOT or hedges in the FUZZY block",
                        c.span or where,
                        "rule-operator",
                    )
                elif c.variable not in input_names:
                    err(
                        f"rule {rule.label}: condition on {c.variable}, which is not an input",
                        c.span or where,
                        "rule-variable",
                    )
            for k in rule.conclusions:
                if k.variable not in output_names:
                    err(
                        f"rule {rule.label}: conclusion on {k.variable}, which is not an output",
                        k.span or where,
                        "rule-variable",
                    )
                if k.term is None:
                    err(
                        f"rule {rule.label}: conclusion {k.variable} needs a term",
                        k.span or where,
                        "rule-variable",
                    )
                if k.weight is not None and k.weight != 1.0:
                    err(
                        f"rule {rule.label}: WITH {k.weight}: the FUZZY block has no rule weights",
                        k.span or where,
                        "weight",
                    )
                if k.hedges:
                    err(f"rule {rule.label}: no hedges in the FUZZY block", k.span or where, "rule-operator")
            if rule.weight is not None and rule.weight != 1.0:
                err(
                    f"rule {rule.label}: weight {rule.weight}: the FUZZY block has no rule weights",
                    where,
                    "weight",
                )
    return diags


def _check_term_names(
    variable: str, names: list[str], spans: list[Span | None], err: Report, note: Report
) -> None:
    n = LIMITS["term_name"]
    seen: dict[str, str] = {}
    for name, span in zip(names, spans, strict=True):
        if len(name) <= n:
            seen.setdefault(name, name)
            continue
        key = name[:n]
        if key in seen:
            err(
                f"{variable}: terms {name} and {seen[key]} are the same for the block: "
                f"only {n} characters are significant",
                span,
                "name-collision",
            )
        else:
            note(
                f"{variable}.{name}: only the first {n} characters ({key}) are significant", span, "long-name"
            )
        seen.setdefault(key, name)
