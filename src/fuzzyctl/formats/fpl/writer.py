"""Writing FPL for Siemens S7 Fuzzy Control (manual 1.3): the writer, what the subset
cannot express, and the adapting ``fuzzyctl convert --lossy`` uses."""

from __future__ import annotations

import itertools
from dataclasses import replace

from fuzzyctl.diagnostics import Diagnostic, DiagnosticError, error, warning
from fuzzyctl.formats.common.adapt import rename
from fuzzyctl.formats.common.basics import identifier
from fuzzyctl.formats.fpl.names import (
    ADDING_ACCU,
    MAX_NAME,
    SIEMENS_ACCU,
    is_fpl_name,
    leaves,
    shared_conclusions,
)
from fuzzyctl.kinds import methods as method_kinds
from fuzzyctl.kinds import norms
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.model import (
    And,
    Condition,
    Default,
    DefuzzifyBlock,
    Document,
    FunctionBlock,
    Is,
    MembershipFunction,
    PointsMF,
    Range,
    Rule,
    ShapeMF,
    SingletonMF,
    Span,
    Variable,
    VarKind,
    implied_operators,
    is_constant,
)

__all__ = ["adapt_fpl", "check_fpl", "write_fpl"]


def _num(x: float) -> str:
    return repr(float(x))


def _as_points(mf: MembershipFunction) -> list[tuple[float, float]] | None:
    """Points of a piecewise-linear term, or None when FPL cannot hold it (also a triangle,
    trapezoid or rectangle whose vertices are out of order: the FPL reader refuses points
    that are not in increasing x order)."""
    points = _points_of(mf)
    if points is None or any(b[0] < a[0] for a, b in itertools.pairwise(points)):
        return None
    return points


def _points_of(mf: MembershipFunction) -> list[tuple[float, float]] | None:
    if isinstance(mf, PointsMF):
        if not all(is_constant(p.x) and is_constant(p.y) for p in mf.points):
            return None
        return [(float(p.x), float(p.y)) for p in mf.points]  # type: ignore[arg-type]
    if isinstance(mf, ShapeMF) and all(is_constant(v) for v in mf.params) and mf.height == 1.0:
        v = [float(x) for x in mf.params]  # type: ignore[arg-type]
        shape = registry.SHAPES.get(mf.kind)
        if shape is not None and not isinstance(shape.spellings.fpl, registry.NA):
            return shape.spellings.fpl(v)  # the points FPL writes for the shape
    return None


def _fpl_points(points: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """IEC points -> the Siemens form: a vertical edge is written by its upper point only."""
    pts = list(points)
    if len(pts) >= 2 and pts[0][1] == 0.0 and pts[1][1] > 0 and pts[0][0] == pts[1][0]:
        pts.pop(0)
    if len(pts) >= 2 and pts[-1][1] == 0.0 and pts[-2][1] > 0 and pts[-1][0] == pts[-2][0]:
        pts.pop()
    return pts


def check_fpl(block: FunctionBlock) -> list[Diagnostic]:
    """What of ``block`` the FPL subset cannot say (errors) or drops (warnings).

    The limits of the Siemens product (8 inputs, 7 terms, ...) are not checked here; the
    ``siemens`` profile of :mod:`fuzzyctl.blocks.siemens` does that."""
    diags: list[Diagnostic] = []

    def err(msg: str, span: Span | None, code: str, hint: str | None = None) -> None:
        diags.append(error(msg, span, code=code, hint=hint))

    if len(block.rule_blocks) > 1:
        err(
            "FPL for Fuzzy Control holds one set of rules; this program has "
            f"{len(block.rule_blocks)} rule blocks",
            block.rule_blocks[1].span,
            "fpl-expr-ruleblocks",
        )
    if block.locals:
        err("FPL for Fuzzy Control has no intermediate variables", block.locals[0].span, "fpl-expr-local")
    for rb in block.rule_blocks:
        and_op = implied_operators(rb.and_op, rb.or_op)[0]  # OR : ASUM alone means AND : PROD
        if not norms.is_min(and_op):
            err(
                f"AND : {and_op}{'' if rb.and_op else f' (the pair of OR : {rb.or_op})'} cannot be "
                "written in FPL (Fuzzy Control uses MIN)",
                rb.span,
                "fpl-expr-op",
            )
        accu_problem = _accu_problem(block, rb.accu)
        if accu_problem is not None:
            hint = "write ACCU : NSUM to say what Fuzzy Control computes"
            err(accu_problem, rb.item_span("accu"), "fpl-expr-op", hint=hint)
        # PROD on singletons is MIN: a singleton's degree is 1
        if rb.act is not None and not (
            norms.is_min(rb.act) or (norms.is_prod(rb.act) and _all_singletons(block))
        ):
            err(f"ACT : {rb.act} cannot be written in FPL (Fuzzy Control uses MIN)", rb.span, "fpl-expr-op")
        if not rb.enabled or rb.rule_activation is not None:
            err(
                f"rule block {rb.name}: FPL has no disabled rule blocks or rule activation methods",
                rb.span,
                "fpl-expr-ruleblocks",
            )
        for rule in rb.rules:
            _check_condition(rule.condition, rule, diags)
            if rule.weight is not None and rule.weight != 1.0:
                err(f"rule {rule.label}: rule weights cannot be written in FPL", rule.span, "fpl-expr-weight")
            for c in rule.conclusions:
                if c.hedges:
                    err(f"rule {rule.label}: hedges cannot be written in FPL", c.span, "fpl-expr-rule")
                if c.term is None:
                    err(f"rule {rule.label}: a conclusion needs a term", c.span, "fpl-expr-rule")
                if c.weight is not None and c.weight != 1.0:
                    err(
                        f"rule {rule.label}: WITH weights cannot be written in FPL",
                        c.span,
                        "fpl-expr-weight",
                        hint="remove the WITH or scale the rule another way",
                    )
    for fz in block.fuzzify:
        for t in fz.terms:
            if _as_points(t.mf) is None:
                err(
                    f"{fz.variable}.{t.name}: only piecewise-linear terms with constant points can be "
                    "written in FPL",
                    t.span,
                    "fpl-expr-term",
                    hint="equations are not permissible (1.3)",
                )
    for dz in block.defuzzify:
        if dz.method is not None and dz.method not in method_kinds.written("fpl"):
            err(
                f"METHOD : {dz.method} cannot be written in FPL (Fuzzy Control computes the centre of "
                "gravity)",
                dz.span,
                "fpl-expr-method",
            )
        if dz.default is not None and not dz.default.no_change:
            diags.append(
                warning(
                    f"{dz.variable}: DEFAULT := {dz.default.value} is not written: Fuzzy "
                    "Control keeps the last value when no rule fires",
                    dz.span,
                    code="fpl-expr-default",
                )
            )
        for t in dz.terms:
            if isinstance(t.mf, SingletonMF):
                if not is_constant(t.mf.value):
                    err(
                        f"{dz.variable}.{t.name}: a singleton given by a variable cannot be written in FPL",
                        t.span,
                        "fpl-expr-term",
                    )
            elif _as_points(t.mf) is None:
                err(
                    f"{dz.variable}.{t.name}: only singletons and piecewise-linear terms can be "
                    "written in FPL",
                    t.span,
                    "fpl-expr-term",
                )
    for v in block.variables:
        fzb, dzb = block.fuzzify_block(v.name), block.defuzzify_block(v.name)
        rng = v.range or (fzb.range if fzb else None) or (dzb.range if dzb else None)
        if rng is not None and not rng.low < rng.high and v.kind is not VarKind.LOCAL:
            err(
                f"{v.name}: RANGE ({rng.low:g} .. {rng.high:g}) cannot be written: FPL needs MIN below MAX",
                rng.span or v.span,
                "fpl-expr-range",
            )
        if v.kind is VarKind.OUTPUT and block.defuzzify_block(v.name) is None:
            err(f"output {v.name} has no DEFUZZIFY block", v.span, "fpl-expr-output")
    return diags


def _accu_problem(block: FunctionBlock, accu: str | None) -> str | None:
    """Why ``accu`` would compute something else than Fuzzy Control, which adds the degrees
    of the rules concluding one output term (1.4); None when it computes the same."""
    for dz in block.defuzzify:
        if dz.accu is not None and dz.accu not in ADDING_ACCU:
            accu = dz.accu
    if accu in ADDING_ACCU:
        return None
    name = accu or "MAX (the default)"
    if not _all_singletons(block):
        return (
            f"ACCU : {name} cannot be written in FPL: Fuzzy Control adds overlapping output "
            "areas (1.4, summation)"
        )
    shared = shared_conclusions(block)
    if not shared:
        return None  # one rule per term: every accumulation gives the same degrees
    output, term, rules = shared[0]
    labels = ", ".join(r.label for r in rules)
    return (
        f"ACCU : {name} cannot be written in FPL: Fuzzy Control adds the degrees of the rules "
        f"concluding the same term (1.4), and {output} IS {term} is concluded by rules {labels}"
    )


def _all_singletons(block: FunctionBlock) -> bool:
    return all(isinstance(t.mf, SingletonMF) for d in block.defuzzify for t in d.terms)


def _check_condition(cond: Condition | None, rule: Rule, diags: list[Diagnostic]) -> None:
    if cond is None:
        return
    if isinstance(cond, And):
        for c in cond.operands:
            _check_condition(c, rule, diags)
    elif isinstance(cond, Is) and not cond.negated and not cond.hedges:
        return
    else:
        diags.append(
            error(
                f"rule {rule.label}: only 'variable IS term' joined by AND can be written in FPL "
                "(no OR, NOT or hedges)",
                getattr(cond, "span", None) or rule.span,
                code="fpl-expr-rule",
            )
        )


def _singleton_width(dz: DefuzzifyBlock, variable: Variable | None) -> float:
    rng = dz.range or (variable.range if variable else None)
    if rng is not None and rng.high > rng.low:
        return (rng.high - rng.low) / 200.0  # the manual's narrow rectangle: 1/200 of the range
    values = [float(t.mf.value) for t in dz.terms if isinstance(t.mf, SingletonMF)]  # type: ignore[arg-type]
    spread = max(values) - min(values) if values else 0.0
    return spread / 200.0 if spread > 0 else 0.01


def _fpl_word(name: str, taken: set[str]) -> str:
    """``name`` when FPL reads it back as one name, else the nearest identifier: a name from
    another format may hold a space (MATLAB's), a newline or ``/*`` (JSON), which would end
    the statement or open a comment; one longer than the reader takes is cut."""
    if is_fpl_name(name) and len(name) <= MAX_NAME and name not in taken:
        return name
    word = identifier(name[: MAX_NAME - 12], taken)
    return word if is_fpl_name(word) else identifier(f"{word}_fpl", taken)


def write_fpl(block: FunctionBlock | Document) -> str:
    """FPL text for a function block (the first one of a document).

    Raises :class:`~fuzzyctl.diagnostics.DiagnosticError` listing what FPL cannot express
    (see :func:`check_fpl`)."""
    fb = block.main if isinstance(block, Document) else block
    problems = [d for d in check_fpl(fb) if d.is_error]
    if problems:
        raise DiagnosticError(problems)
    project = _fpl_word(fb.name or "fuzzy", set())
    out: list[str] = ["/*FPL file written by fuzzyctl*/", f"PROJECT {project}"]
    for var in fb.variables:
        if var.kind is VarKind.LOCAL:
            continue
        out.append(f"VAR {var.name}")
        out.append("TYPE float")
        fz = fb.fuzzify_block(var.name)
        dz = fb.defuzzify_block(var.name)
        rng = var.range or (fz.range if fz else None) or (dz.range if dz else None)
        members: list[tuple[str, list[tuple[float, float]]]] = []
        for t in fz.terms if fz else ():
            members.append((t.name, _fpl_points(_as_points(t.mf) or [])))
        for t in dz.terms if dz else ():
            if isinstance(t.mf, SingletonMF):
                x, half = float(t.mf.value), _singleton_width(dz, var) / 2.0  # type: ignore[arg-type]
                members.append((t.name, [(x - half, 1.0), (x + half, 1.0)]))
            else:
                members.append((t.name, _fpl_points(_as_points(t.mf) or [])))
        if rng is None:
            xs = [x for _, pts in members for x, _ in pts]
            rng = Range(min(xs), max(xs)) if xs else None
        if rng is not None and rng.low < rng.high:  # check_fpl says a degenerate one is dropped
            out += [f"MIN {_num(rng.low)}", f"MAX {_num(rng.high)}"]
        for name, pts in members:
            out += [f"MEMBER {name}", "POINTS " + " ".join(f"{_num(x)},{_num(y)}" for x, y in pts), "END"]
        out.append("END")
    base = fb.rule_blocks[0] if fb.rule_blocks else None
    base_name = _fpl_word(base.name if base and base.name else "rules", set())
    labels = {r.label for r in base.rules} if base else set()
    out.append(f"FUZZY {base_name}")
    for rb_rule in base.rules if base else ():
        label = rb_rule.label
        # a label FPL reads back: a number or a word of at most MAX_NAME characters
        if not ((label.isascii() and label.isdigit()) or is_fpl_name(label)) or len(label) > MAX_NAME:
            label = _fpl_word(label, labels)  # not one of the other labels
        out.append(f"RULE {label}")
        subconditions = list(leaves(rb_rule.condition))
        if subconditions:
            out.append("IF " + " AND ".join(f"({c.variable} is {c.term})" for c in subconditions))
        if rb_rule.conclusions:
            out.append("THEN " + " AND ".join(f"{c.variable} = {c.term}" for c in rb_rule.conclusions))
        out.append("END")
    out.append("END")
    for var in fb.inputs:
        out += ["CONNECT", f"FROM {var.name}", f"TO {base_name}", "END"]
    for var in fb.outputs:
        out += ["CONNECT", f"FROM {base_name}", f"TO {var.name}", "END"]
    out.append("END")
    return "\n".join(out) + "\n"


def _loss(d: Diagnostic) -> tuple[str, str]:
    where = f"line {d.span.line}" if d.span is not None else "program"
    return where, d.message


def _fpl_condition(cond: Condition | None) -> bool:
    if cond is None:
        return True
    if isinstance(cond, Is):
        return not cond.negated and not cond.hedges
    return isinstance(cond, And) and all(_fpl_condition(c) for c in cond.operands)


def adapt_fpl(document: Document) -> tuple[Document, list[tuple[str, str]]]:
    """``document`` reduced to what FPL can say, and what was dropped as ``(element,
    reason)`` pairs: further function blocks, rule blocks and intermediate variables,
    weights, DEFAULT values (Fuzzy Control keeps the last value), other operators, rules
    with OR/NOT/hedges and terms FPL cannot hold (with the rules that use them)."""
    fb = document.main
    losses = [(f"function block {b.name}", "an FPL file holds one project") for b in document.blocks[1:]]
    diags = check_fpl(fb)
    losses += [_loss(d) for d in diags if d.is_error or d.code == "fpl-expr-default"]
    local_names = {v.name for v in fb.locals}
    keep_terms: set[tuple[str, str]] = set()
    fuzzify = []
    for fz in fb.fuzzify:
        if fz.variable in local_names:
            continue
        terms = tuple(t for t in fz.terms if _as_points(t.mf) is not None)
        keep_terms.update((fz.variable, t.name) for t in terms)
        fuzzify.append(replace(fz, terms=terms))
    defuzzify = []
    for dz in fb.defuzzify:
        if dz.variable in local_names:
            continue
        terms = tuple(
            t
            for t in dz.terms
            if (isinstance(t.mf, SingletonMF) and is_constant(t.mf.value)) or _as_points(t.mf) is not None
        )
        keep_terms.update((dz.variable, t.name) for t in terms)
        singletons = all(isinstance(t.mf, SingletonMF) for t in terms)
        defuzzify.append(
            replace(
                dz,
                terms=terms,
                method="COGS" if singletons else "COG",
                default=Default(no_change=True),
                accu=None,
            )
        )
    rule_blocks = []
    for rb in fb.rule_blocks[:1]:
        rules = []
        for rule in rb.rules:
            used = [(c.variable, c.term) for c in leaves(rule.condition)]
            used += [(c.variable, c.term or "") for c in rule.conclusions]
            plain = _fpl_condition(rule.condition) and not any(c.hedges for c in rule.conclusions)
            if plain and all(u in keep_terms for u in used):
                conclusions = tuple(replace(c, weight=None) for c in rule.conclusions)
                rules.append(replace(rule, conclusions=conclusions, weight=None))
        rule_blocks.append(
            replace(
                rb,
                rules=tuple(rules) if rb.enabled else (),
                and_op="MIN",
                or_op=None,
                accu=SIEMENS_ACCU,
                act=None if rb.act is None or norms.is_min(rb.act) else "MIN",
                enabled=True,
                rule_activation=None,
            )
        )
    adapted = replace(
        fb,
        variables=tuple(v for v in fb.variables if v.name not in local_names),
        fuzzify=tuple(fuzzify),
        defuzzify=tuple(defuzzify),
        rule_blocks=tuple(rule_blocks),
    )
    # names FPL cannot read back (MATLAB's "dV*", "Rear Left", a variable "If") are renamed
    adapted, _renames = rename(adapted, is_fpl_name, is_fpl_name)
    return Document((adapted,), path=document.path, comments=document.comments), losses
