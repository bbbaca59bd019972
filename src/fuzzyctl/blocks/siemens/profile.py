"""The ``siemens`` profile: what a controller must respect to run in the S7 FUZZY block
(Siemens manual 1.3, 3.1 and 3.4).

Errors (the block cannot hold or compute it): more than 8 inputs, 7 terms per input, 4
outputs, 9 terms per output or 200 rules; more than one rule block; intermediate
variables; rules other than ``IF v IS t AND ... THEN out IS t`` (no OR, NOT, hedges,
weights, conclusions on inputs, conditions on outputs); input terms other than rectangle,
triangle or trapezoid; output terms other than constant singletons; operators other than
the block's own (AND MIN, singleton centre of gravity); names whose significant
characters (10 for variables, 7 for terms) collide.

Warnings (the block runs it, but differently from what the program says, or the
configuration tool would not take it as written): a DEFAULT value (the block keeps the last
value instead); inputs or outputs without limits (the block needs MIN and MAX); an
accumulation other than a sum when two rules conclude the same output term (the block adds
their degrees, 1.4); a variable wired to a bipolar FUZZY_AI / FUZZY_AO whose MIN and MAX
are not symmetric (3.2, 3.3 notes); names longer than the tool's dialogs take (project 8
characters, 6.2; inputs and outputs 10, 6.4; terms 7, 6.4 - only that many are significant
in FPL, 1.3) or with characters other than letters, digits and ``_``, or starting with a
digit (6.4).  The manual's own FPLTEST has an 8-character term "drainage": a warning, not
an error.
"""

from __future__ import annotations

import itertools
import re
from collections.abc import Iterable

from fuzzyctl.diagnostics import Diagnostic, Severity, error, warning
from fuzzyctl.formats.fpl.names import ADDING_ACCU, shared_conclusions
from fuzzyctl.kinds import methods as method_kinds
from fuzzyctl.kinds import norms
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.model import (
    And,
    Condition,
    DefuzzifyBlock,
    Document,
    FunctionBlock,
    FuzzifyBlock,
    Is,
    MembershipFunction,
    PointsMF,
    Rule,
    ShapeMF,
    SingletonMF,
    Span,
    Variable,
    VarKind,
    is_constant,
)

__all__ = ["LIMITS", "check_siemens", "input_shape", "name_problem", "variable_limits"]

LIMITS = {
    "inputs": 8,
    "input_terms": 7,
    "outputs": 4,
    "output_terms": 9,
    "rules": 200,
    "project_name": 8,
    "variable_name": 10,
    "term_name": 7,
}
"""The block's and the configuration tool's limits (1.3, 6.2, 6.4); the studio's dialogs
use the same numbers (``/api/info``)."""

_NAME_CHARS = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def input_shape(mf: MembershipFunction) -> str | None:
    """``"rectangle"``, ``"triangle"`` or ``"trapezoid"`` when the block can hold ``mf``
    as an input term, else None.  IEC shoulders (a list starting or ending on degree 1)
    are trapezoids whose outer points sit at the limits of the input."""
    if isinstance(mf, ShapeMF):
        if (
            registry.SHAPES.get(mf.kind) is not None
            and not isinstance(registry.SHAPES[mf.kind].spellings.fpl, registry.NA)
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


def _term_xs(mf: MembershipFunction) -> list[float]:
    if isinstance(mf, PointsMF):
        return [float(p.x) for p in mf.points if is_constant(p.x)]  # type: ignore[arg-type]
    if isinstance(mf, SingletonMF) and is_constant(mf.value):
        return [float(mf.value)]  # type: ignore[arg-type]
    if isinstance(mf, ShapeMF):
        return [float(p) for p in mf.params if is_constant(p)]  # type: ignore[arg-type]
    return []


def variable_limits(fb: FunctionBlock, name: str) -> tuple[float, float] | None:
    """MIN/MAX of a variable as the block holds them: its RANGE, else the span of its
    terms; None when it has neither."""
    var = fb.variable(name)
    fz, dz = fb.fuzzify_block(name), fb.defuzzify_block(name)
    rng = (var.range if var else None) or (fz.range if fz else None) or (dz.range if dz else None)
    if rng is not None:
        return (rng.low, rng.high)
    xs = [x for block in (fz, dz) if block for t in block.terms for x in _term_xs(t.mf)]
    return (min(xs), max(xs)) if xs else None


def name_problem(name: str, limit: int) -> str | None:
    """What the configuration tool's dialogs would refuse in ``name`` (6.2, 6.4): more
    than ``limit`` characters, a first character that is a digit, characters other than
    letters, digits and ``_``.  None when the tool takes it."""
    problems = []
    if len(name) > limit:
        problems.append(f"{len(name)} characters, the configuration tool takes {limit}")
    if name[:1].isdigit():
        problems.append("the first character may not be a number")
    elif not _NAME_CHARS.fullmatch(name) or not name.isascii():
        problems.append("special characters and accents are not permitted, only '_'")
    return "; ".join(problems) or None


class _Report:
    """Collects the profile's diagnostics (codes ``siemens-...``)."""

    def __init__(self) -> None:
        self.diags: list[Diagnostic] = []

    def err(self, msg: str, span: Span | None, code: str, hint: str | None = None) -> None:
        self.diags.append(error(msg, span, code=f"siemens-{code}", hint=hint))

    def warn(self, msg: str, span: Span | None, code: str, hint: str | None = None) -> None:
        self.diags.append(warning(msg, span, code=f"siemens-{code}", hint=hint))

    def note(self, msg: str, span: Span | None, code: str) -> None:
        self.diags.append(Diagnostic(Severity.NOTE, msg, span, code=f"siemens-{code}"))


def check_siemens(model: FunctionBlock | Document, *, bipolar: Iterable[str] = ()) -> list[Diagnostic]:
    """Every way ``model`` exceeds the S7 FUZZY block, most precise location first.

    ``bipolar`` names the inputs and outputs wired to a bipolar FUZZY_AI / FUZZY_AO (or
    ``INPUTn`` / ``OUTPUTn``): their MIN and MAX must be symmetric (3.2, 3.3)."""
    fb = model.main if isinstance(model, Document) else model
    r = _Report()
    _check_variables(fb, r)
    _check_terms(fb, r)
    _check_rules(fb, r)
    _check_accumulation(fb, r)
    _check_bipolar(fb, tuple(bipolar), r)
    return r.diags


def _check_variables(fb: FunctionBlock, r: _Report) -> None:
    inputs, outputs = fb.inputs, fb.outputs
    for what, items, limit in (("inputs", inputs, LIMITS["inputs"]), ("outputs", outputs, LIMITS["outputs"])):
        if len(items) > limit:
            r.err(
                f"{len(items)} {what}; the FUZZY block has {limit} (INPUT1..8, OUTPUT1..4): "
                f"{', '.join(v.name for v in items[limit:])} cannot be connected",
                items[limit].span,
                f"too-many-{what}",
            )
    for v in fb.locals:
        r.err(f"intermediate variable {v.name}: the FUZZY block has no chained rules", v.span, "intermediate")
    if fb.name is not None:
        problem = name_problem(fb.name, LIMITS["project_name"])
        if problem is not None:
            r.warn(f"project name {fb.name}: {problem} (6.2, Define Project)", fb.span, "name")
    seen: dict[str, str] = {}
    n = LIMITS["variable_name"]
    for v in (*inputs, *outputs):
        key = v.name[:n]
        if key in seen:
            r.err(
                f"{v.name} and {seen[key]} are the same name for the block: only {n} characters are "
                "significant (1.3)",
                v.span,
                "name-collision",
            )
        else:
            problem = name_problem(v.name, n)
            if problem is not None:
                significant = f"; only the first {n} ({key}) are significant (1.3)" if len(v.name) > n else ""
                r.warn(f"{v.name}: {problem} (6.4){significant}", v.span, "name")
        seen.setdefault(key, v.name)
        if v.range is None:
            block = fb.fuzzify_block(v.name) if v.kind is VarKind.INPUT else fb.defuzzify_block(v.name)
            if block is None or block.range is None:
                r.warn(
                    f"{v.name} has no RANGE: the block needs MIN and MAX (taken from the terms)",
                    v.span,
                    "no-range",
                )


def _check_term_list(block: FuzzifyBlock | DefuzzifyBlock, side: str, r: _Report) -> None:
    """How many terms the block takes on this ``side`` (input, output) and their names."""
    limit = LIMITS[f"{side}_terms"]
    if len(block.terms) > limit:
        r.err(
            f"{side} {block.variable} has {len(block.terms)} terms; the block allows {limit}",
            block.terms[limit].span or block.span,
            "too-many-terms",
        )
    _check_term_names(block.variable, [t.name for t in block.terms], [t.span for t in block.terms], r)


def _check_terms(fb: FunctionBlock, r: _Report) -> None:
    for fz in fb.fuzzify:
        var = fb.variable(fz.variable)
        if var is not None and var.kind is not VarKind.INPUT:
            r.err(
                f"{fz.variable}: only inputs are fuzzified in the FUZZY block", fz.span, "fuzzify-non-input"
            )
        _check_term_list(fz, "input", r)
        for t in fz.terms:
            if input_shape(t.mf) is None:
                r.err(
                    f"{fz.variable}.{t.name}: input terms are rectangles, triangles or trapezoids (degrees 0 "
                    "and 1, at most 4 points)",
                    t.span or fz.span,
                    "input-shape",
                )
    for dz in fb.defuzzify:
        _check_term_list(dz, "output", r)
        for t in dz.terms:
            if not isinstance(t.mf, SingletonMF) or not is_constant(t.mf.value):
                r.err(
                    f"{dz.variable}.{t.name}: output terms are singletons with a constant position",
                    t.span or dz.span,
                    "output-shape",
                    hint="in FPL a singleton is a narrow rectangle (1/200 of the range)",
                )
        if dz.method is not None and dz.method not in method_kinds.written("fpl"):
            r.err(
                f"{dz.variable}: METHOD : {dz.method}; the block computes the centre of gravity of "
                "singletons",
                dz.span,
                "method",
            )
        if dz.default is not None and not dz.default.no_change:
            r.warn(
                f"{dz.variable}: DEFAULT := {dz.default.value:g} is not used: when no rule fires the block "
                "keeps the last value (0 before the first)",
                dz.default.span or dz.span,
                "default",
            )


def _check_rules(fb: FunctionBlock, r: _Report) -> None:
    if len(fb.rule_blocks) > 1:
        r.err(
            f"{len(fb.rule_blocks)} rule blocks; the FUZZY block has one set of rules",
            fb.rule_blocks[1].span,
            "rule-blocks",
        )
    n_rules = sum(len(rb.rules) for rb in fb.rule_blocks)
    if n_rules > LIMITS["rules"]:
        r.err(
            f"{n_rules} rules; the FUZZY block holds {LIMITS['rules']} (with 2 inputs and 1 output)",
            fb.rule_blocks[0].span,
            "too-many-rules",
        )
    input_names = {v.name for v in fb.inputs}
    output_names = {v.name for v in fb.outputs}
    for rb in fb.rule_blocks:
        if rb.and_op is not None and not norms.is_min(rb.and_op):
            r.err(f"AND : {rb.and_op}; the block uses MIN", rb.span, "operator")
        if not rb.enabled or rb.rule_activation is not None:
            r.err(
                f"rule block {rb.name}: the FUZZY block always fires every rule", rb.span, "rule-activation"
            )
        if rb.act is not None and not (norms.is_min(rb.act) or norms.is_prod(rb.act)):
            r.err(f"ACT : {rb.act}; the block uses MIN", rb.span, "operator")
        for rule in rb.rules:
            _check_rule(rule, rb.span, input_names, output_names, r)


def _check_rule(rule: Rule, block_span: Span | None, inputs: set[str], outputs: set[str], r: _Report) -> None:
    where = rule.span or block_span
    for c in _conditions(rule.condition):
        if not isinstance(c, Is):
            r.err(
                f"rule {rule.label}: only AND joins conditions in the FUZZY block "
                "(no OR, NOT or bare degrees)",
                getattr(c, "span", None) or where,
                "rule-operator",
            )
        elif c.negated or c.hedges:
            r.err(
                f"rule {rule.label}: {c.variable} IS {'NOT ' if c.negated else ''}"
                f"{' '.join(c.hedges)} {c.term}: no NOT or hedges in the FUZZY block",
                c.span or where,
                "rule-operator",
            )
        elif c.variable not in inputs:
            r.err(
                f"rule {rule.label}: condition on {c.variable}, which is not an input",
                c.span or where,
                "rule-variable",
            )
    for k in rule.conclusions:
        if k.variable not in outputs:
            r.err(
                f"rule {rule.label}: conclusion on {k.variable}, which is not an output",
                k.span or where,
                "rule-variable",
            )
        if k.term is None:
            r.err(
                f"rule {rule.label}: conclusion {k.variable} needs a term", k.span or where, "rule-variable"
            )
        if k.weight is not None and k.weight != 1.0:
            r.err(
                f"rule {rule.label}: WITH {k.weight}: the FUZZY block has no rule weights",
                k.span or where,
                "weight",
            )
        if k.hedges:
            r.err(f"rule {rule.label}: no hedges in the FUZZY block", k.span or where, "rule-operator")
    if rule.weight is not None and rule.weight != 1.0:
        r.err(
            f"rule {rule.label}: weight {rule.weight}: the FUZZY block has no rule weights", where, "weight"
        )


def _check_accumulation(fb: FunctionBlock, r: _Report) -> None:
    """The block adds the degrees of the rules concluding one output term (1.4); any other
    accumulation computes the same only when no term is concluded twice."""
    shared = shared_conclusions(fb)
    if not shared:
        return
    output, term, rules = shared[0]
    labels = ", ".join(rule.label for rule in rules)
    for dz in fb.defuzzify:
        if dz.accu is not None and dz.accu not in ADDING_ACCU:
            r.warn(
                f"{dz.variable}: ACCU : {dz.accu}; the FUZZY block adds the degrees of rules concluding "
                f"the same term (1.4): {output} IS {term} (rules {labels})",
                dz.item_span("accu"),
                "accumulation",
            )
    for rb in fb.rule_blocks:
        if rb.accu not in ADDING_ACCU:
            r.warn(
                f"ACCU : {rb.accu or 'MAX (the default)'}; the FUZZY block adds the degrees of rules "
                f"concluding the same term (1.4): {output} IS {term} is concluded by rules {labels}, so "
                "the block computes another value",
                rb.item_span("accu"),
                "accumulation",
                hint="write ACCU : NSUM, the IEC sum (its normalisation cancels in the centre of gravity)",
            )


def _check_bipolar(fb: FunctionBlock, names: tuple[str, ...], r: _Report) -> None:
    """3.2 and 3.3 notes: with a bipolar signal (+-10 V, +-20 mA) the MIN and MAX of the
    input or output must be symmetric (e.g. -100.0 and +100.0), else FUZZY_AI / FUZZY_AO
    compute wrong values."""
    for name in names:
        var = _by_manual_name(fb, name)
        if var is None:
            known = ", ".join(v.name for v in (*fb.inputs, *fb.outputs))
            r.err(f"bipolar {name}: no such input or output ({known}, INPUTn, OUTPUTn)", fb.span, "bipolar")
            continue
        limits = variable_limits(fb, var.name)
        if limits is None:
            continue  # reported as no-range already
        low, high = limits
        if low != -high:
            fc = "FUZZY_AI" if var.kind is VarKind.INPUT else "FUZZY_AO"
            r.warn(
                f"{var.name}: MIN {low:g} and MAX {high:g} are not symmetric; with a bipolar signal "
                f"{fc} may compute wrong values (3.2, 3.3: give e.g. -{max(abs(low), abs(high)):g} and "
                f"+{max(abs(low), abs(high)):g})",
                var.span,
                "bipolar-asymmetric",
            )


def _by_manual_name(fb: FunctionBlock, name: str) -> Variable | None:
    var = fb.variable(name)
    if var is not None and var.kind in (VarKind.INPUT, VarKind.OUTPUT):
        return var
    m = re.fullmatch(r"(INPUT|OUTPUT)([1-8])", name.upper())
    if m is None:
        return None
    items = fb.inputs if m.group(1) == "INPUT" else fb.outputs
    k = int(m.group(2))
    return items[k - 1] if k <= len(items) and (m.group(1) == "INPUT" or k <= 4) else None


def _check_term_names(variable: str, names: list[str], spans: list[Span | None], r: _Report) -> None:
    n = LIMITS["term_name"]
    seen: dict[str, str] = {}
    for name, span in zip(names, spans, strict=True):
        key = name[:n]
        if key in seen:
            r.err(
                f"{variable}: terms {name} and {seen[key]} are the same for the block: "
                f"only {n} characters are significant (1.3)",
                span,
                "name-collision",
            )
        else:
            problem = name_problem(name, n)
            if problem is not None:
                significant = f"; only the first {n} ({key}) are significant (1.3)" if len(name) > n else ""
                r.warn(f"{variable}.{name}: {problem} (6.4){significant}", span, "name")
        seen.setdefault(key, name)
