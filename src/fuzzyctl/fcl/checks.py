"""Semantic checks of a parsed FCL document.

Checks are *providers*: functions ``(document, context) -> diagnostics``.  The built-in
ones below cover IEC 61131-7 clause 5; other packages add theirs with
:func:`register_provider` (the inference engine reports the features it does not evaluate
that way) and :func:`run_checks` runs them all.  A provider never raises for bad input: it
reports."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field

from fuzzyctl import model as m
from fuzzyctl.diagnostics import Diagnostic, Severity, error, warning
from fuzzyctl.fcl.jfl import check_jfuzzylogic
from fuzzyctl.fcl.reserved import check_reserved_words
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.kinds.methods import METHODS
from fuzzyctl.validation import at_spans, validate


@dataclass
class CheckContext:
    """What a provider may need besides the document: the file name for diagnostics."""

    file: str | None = None
    options: dict[str, object] = field(default_factory=dict)


Provider = Callable[[m.Document, CheckContext], Iterable[Diagnostic]]

_PROVIDERS: dict[str, Provider] = {}


def register_provider(name: str, provider: Provider) -> None:
    """Add (or replace) a named check provider; ``run_checks`` calls it for every file."""
    _PROVIDERS[name] = provider


def providers() -> dict[str, Provider]:
    return dict(_PROVIDERS)


def run_checks(doc: m.Document, context: CheckContext | None = None) -> list[Diagnostic]:
    """Every provider's diagnostics, sorted by position."""
    ctx = context or CheckContext(doc.path)
    out: list[Diagnostic] = []
    for provider in _PROVIDERS.values():
        out.extend(provider(doc, ctx))
    return sorted(out, key=lambda d: (d.span.line if d.span else 0, d.span.column if d.span else 0))


# --------------------------------------------------------------------------- helpers


def term_blocks(fb: m.FunctionBlock) -> list[m.FuzzifyBlock | m.DefuzzifyBlock]:
    """The FUZZIFY then DEFUZZIFY blocks of ``fb``."""
    return [*fb.fuzzify, *fb.defuzzify]


class _Reporter:
    def __init__(self, ctx: CheckContext) -> None:
        self.ctx = ctx
        self.found: list[Diagnostic] = []

    def error(self, message: str, span: m.Span | None, code: str, hint: str | None = None) -> None:
        self.found.append(error(message, span, code=code, file=self.ctx.file, hint=hint))

    def warning(self, message: str, span: m.Span | None, code: str, hint: str | None = None) -> None:
        self.found.append(warning(message, span, code=code, file=self.ctx.file, hint=hint))

    def note(self, message: str, span: m.Span | None, code: str) -> None:
        self.found.append(Diagnostic(Severity.NOTE, message, span, self.ctx.file, code))


def uses_operator(c: m.Condition | None, kind: type) -> bool:
    if c is None or isinstance(c, m.Is | m.Degree):
        return False
    if isinstance(c, kind):
        return True
    if isinstance(c, m.Not):
        return uses_operator(c.operand, kind)
    return any(uses_operator(o, kind) for o in c.operands)


def mf_params(mf: object) -> list[m.Param]:
    if isinstance(mf, m.PointsMF | m.SingletonsMF):
        return [v for p in mf.points for v in (p.x, p.y)]
    if isinstance(mf, m.SingletonMF):
        return [mf.value]
    if isinstance(mf, m.ShapeMF):
        return [*mf.params, mf.height]
    return []


def is_singleton(mf: object) -> bool:
    return isinstance(mf, m.SingletonMF | m.SingletonsMF) or (
        isinstance(mf, m.ShapeMF) and registry.flag(mf.kind, "ts_constant")
    )


# --------------------------------------------------------------------------- built-in checks


def check_declarations(doc: m.Document, ctx: CheckContext) -> Iterator[Diagnostic]:
    r = _Reporter(ctx)
    names: dict[str | None, m.Span | None] = {}
    for fb in doc.blocks:
        if fb.name in names and len(doc.blocks) > 1:
            r.error(f"function block {fb.name!r} defined twice", fb.span, "duplicate-block")
        names[fb.name] = fb.span
        seen: dict[str, m.Span | None] = {}
        for v in fb.variables:
            if v.name in seen:
                r.error(
                    f"variable {v.name} declared twice (first on line {_line(seen[v.name])})",
                    v.span,
                    "duplicate-variable",
                )
            else:
                seen[v.name] = v.span
        _check_blocks(fb, r)
    yield from r.found


def _line(span: m.Span | None) -> str:
    return str(span.line) if span else "?"


def _check_block(
    fb: m.FunctionBlock,
    block: m.FuzzifyBlock | m.DefuzzifyBlock,
    seen: dict[str, m.Span | None],
    r: _Reporter,
) -> None:
    """What FUZZIFY and DEFUZZIFY blocks share: a declared variable of the kind the block
    takes (5.2.2, 5.2.3), one block per variable, no term defined twice."""
    word, takes, section, code = (
        ("FUZZIFY", m.VarKind.INPUT, "5.2.2", "fuzzify-non-input")
        if isinstance(block, m.FuzzifyBlock)
        else ("DEFUZZIFY", m.VarKind.OUTPUT, "5.2.3", "defuzzify-non-output")
    )
    name = block.variable
    var = fb.variable(name)
    if var is None:
        r.error(f"{word} {name}: no variable {name} is declared", block.span, "undeclared-variable")
    elif var.kind is not takes and var.kind is not m.VarKind.LOCAL:
        r.error(
            f"{word} {name}: {name} is a {var.kind.value}; {word} takes a {takes.value} ({section})",
            block.span,
            code,
        )
    if name in seen:
        r.error(f"second {word} block for {name}", block.span, "duplicate-block")
    seen[name] = block.span
    _check_terms(block.terms, name, r)


def _check_blocks(fb: m.FunctionBlock, r: _Reporter) -> None:
    fuzzified: dict[str, m.Span | None] = {}
    for f in fb.fuzzify:
        var = fb.variable(f.variable)
        if var is not None and var.kind is m.VarKind.LOCAL:
            r.warning(
                f"FUZZIFY {f.variable}: {f.variable} is a local VAR; the standard fuzzifies VAR_INPUT "
                "variables (5.2.2)",
                f.span,
                "fuzzify-local",
            )
        _check_block(fb, f, fuzzified, r)
    defuzzified: dict[str, m.Span | None] = {}
    for d in fb.defuzzify:
        _check_block(fb, d, defuzzified, r)
        _check_defuzzify(fb, d, r)
    for v in fb.variables:
        if v.kind is m.VarKind.OUTPUT and v.name not in defuzzified and not _assigned_bare(fb, v.name):
            r.warning(f"output {v.name} has no DEFUZZIFY block", v.span, "output-without-defuzzify")
    for term, p in _refs_in_terms(fb):
        var = fb.variable(p.name)
        if var is None:
            r.error(
                f"TERM {term.name}: no variable {p.name} is declared",
                p.span or term.span,
                "undeclared-variable",
            )
        elif var.kind is m.VarKind.OUTPUT:
            r.warning(
                f"TERM {term.name}: parameter {p.name} is an output; variable points are VAR_INPUTs (5.2.2)",
                p.span or term.span,
                "parameter-not-input",
            )


def _assigned_bare(fb: m.FunctionBlock, name: str) -> bool:
    return any(c.variable == name and c.term is None for _, rule in fb.rules() for c in rule.conclusions)


def _refs_in_terms(fb: m.FunctionBlock) -> Iterator[tuple[m.Term, m.Ref]]:
    for block in term_blocks(fb):
        for t in block.terms:
            for p in mf_params(t.mf):
                if isinstance(p, m.Ref):
                    yield t, p


def _check_terms(terms: tuple[m.Term, ...], variable: str, r: _Reporter) -> None:
    seen: dict[str, m.Span | None] = {}
    for t in terms:
        if t.name in seen:
            r.warning(
                f"term {t.name} of {variable} defined twice (first on line {_line(seen[t.name])}); "
                "the first definition is used",
                t.span,
                "duplicate-term",
            )
        else:
            seen[t.name] = t.span
    # the points of each term: fuzzyctl.validation (one validation for every reader)


def _check_defuzzify(fb: m.FunctionBlock, d: m.DefuzzifyBlock, r: _Reporter) -> None:
    method_span = d.item_span("method")
    if d.method is not None and METHODS[d.method].bisects and any(is_singleton(t.mf) for t in d.terms):
        r.error(
            f"DEFUZZIFY {d.variable}: CoA cannot be used with singleton terms (Table 1, note 3)",
            method_span,
            "coa-singletons",
            hint="use CoGS for singletons",
        )
    if d.method is None:
        r.warning(
            f"DEFUZZIFY {d.variable} has no METHOD: CoG is used (for singletons it equals CoGS)",
            d.span,
            "missing-method",
        )
    if d.default is None:
        r.warning(
            f"DEFUZZIFY {d.variable} has no DEFAULT: NC is used, the output keeps its last value, "
            "0 before the first firing",
            d.span,
            "missing-default",
        )
    if (
        d.method in METHODS
        and METHODS[d.method].for_function_terms
        and not any(isinstance(t.mf, m.FunctionMF) for t in d.terms)
    ):
        r.warning(
            f"DEFUZZIFY {d.variable}: COGF is meant for FUNCTION terms", method_span, "cogf-without-function"
        )


def check_rules(doc: m.Document, ctx: CheckContext) -> Iterator[Diagnostic]:
    r = _Reporter(ctx)
    for fb in doc.blocks:
        names: dict[str | None, m.Span | None] = {}
        for rb in fb.rule_blocks:
            if rb.name is not None and rb.name in names:
                r.error(f"rule block {rb.name} defined twice", rb.span, "duplicate-block")
            names[rb.name] = rb.span
            _check_rule_block(fb, rb, r)
        _check_cycles(fb, r)
    yield from r.found


def _terms_of(fb: m.FunctionBlock, name: str) -> frozenset[str] | None:
    """The terms of ``name`` in its FUZZIFY and DEFUZZIFY blocks (``None``: no such block)."""
    return fb.term_names(name)


def _check_rule_block(fb: m.FunctionBlock, rb: m.RuleBlock, r: _Reporter) -> None:
    if rb.and_op and rb.or_op and m.OPERATOR_PAIRS.get(rb.and_op) != rb.or_op:
        r.warning(
            f"AND : {rb.and_op} and OR : {rb.or_op} are not a pair of Table 3 "
            f"(AND {rb.and_op} goes with OR {m.OPERATOR_PAIRS.get(rb.and_op, '?')})",
            rb.item_span("or_op"),
            "operator-pair",
        )
    outputs = {c.variable for rule in rb.rules for c in rule.conclusions}
    if rb.accu is None:
        without = sorted(v for v in outputs if (d := fb.defuzzify_block(v)) is None or d.accu is None)
        if without:
            r.warning(
                f"RULEBLOCK {rb.name or ''} has no ACCU: using MAX, the Basic-level accumulation".replace(
                    "  ", " "
                ),
                rb.span,
                "missing-accu",
            )
    if rb.act is None and any(
        (d := fb.defuzzify_block(v)) is not None and any(not is_singleton(t.mf) for t in d.terms)
        for v in outputs
    ):
        r.note(
            f"RULEBLOCK {rb.name or ''} has no ACT: MIN activation is used".replace("  ", " "),
            rb.span,
            "missing-act",
        )
    labels: dict[str, m.Span | None] = {}
    for rule in rb.rules:
        if rule.label in labels:
            r.warning(
                f"RULE {rule.label} appears twice in this rule block "
                f"(first on line {_line(labels[rule.label])})",
                rule.span,
                "duplicate-rule",
            )
        labels[rule.label] = rule.span
        for sub in m.walk_condition(rule.condition):
            if _declared(fb, rule, sub.variable, sub.span, r) is None:
                continue
            if isinstance(sub, m.Is):
                terms = _terms_of(fb, sub.variable)
                if terms is None:
                    r.error(
                        f"RULE {rule.label}: {sub.variable} has no FUZZIFY or DEFUZZIFY block defining "
                        f"term {sub.term}",
                        sub.span or rule.span,
                        "undeclared-term",
                    )
                elif sub.term not in terms and sub.term.lower() == "any" and not sub.hedges:
                    r.note(
                        f"RULE {rule.label}: {sub.variable} IS any is fuzzylite's hedge 'any' (always true)",
                        sub.span or rule.span,
                        "fuzzylite-any",
                    )
                elif sub.term not in terms:
                    _no_term(rule, sub.variable, sub.term, terms, sub.span, r)
        for c in rule.conclusions:
            var = _declared(fb, rule, c.variable, c.span, r)
            if var is None:
                continue
            if var.kind is m.VarKind.INPUT:
                r.error(
                    f"RULE {rule.label}: {c.variable} is a VAR_INPUT and cannot be a conclusion",
                    c.span or rule.span,
                    "conclusion-on-input",
                )
            if c.term is not None:
                d = fb.defuzzify_block(c.variable)
                terms = _terms_of(fb, c.variable)
                if d is None and terms is None:
                    r.error(
                        f"RULE {rule.label}: {c.variable} has no DEFUZZIFY block defining term {c.term}",
                        c.span or rule.span,
                        "undeclared-term",
                    )
                elif terms is not None and c.term not in terms:
                    _no_term(rule, c.variable, c.term, terms, c.span, r)
            w = c.weight
            if isinstance(w, m.Ref):
                wvar = fb.variable(w.name)
                if wvar is None:
                    r.error(
                        f"RULE {rule.label}: undeclared weight variable {w.name}",
                        w.span or c.span,
                        "undeclared-variable",
                    )
                elif wvar.kind is not m.VarKind.INPUT:
                    r.warning(
                        f"RULE {rule.label}: weight {w.name} is not a VAR_INPUT (5.2.4)",
                        w.span or c.span,
                        "weight-not-input",
                    )
                elif isinstance(wvar.initial, float) and not 0.0 <= wvar.initial <= 1.0:
                    r.error(
                        f"RULE {rule.label}: weight {w.name} starts at {wvar.initial:g}, outside [0, 1]",
                        wvar.span,
                        "weight-out-of-range",
                    )
            # a numeric weight: fuzzyctl.validation (one validation for every reader)


def _declared(
    fb: m.FunctionBlock, rule: m.Rule, name: str, span: m.Span | None, r: _Reporter
) -> m.Variable | None:
    """The variable ``name`` a rule uses, or None after reporting it undeclared."""
    var = fb.variable(name)
    if var is None:
        r.error(f"RULE {rule.label}: undeclared variable {name}", span or rule.span, "undeclared-variable")
    return var


def _no_term(
    rule: m.Rule, variable: str, term: str, terms: Iterable[str], span: m.Span | None, r: _Reporter
) -> None:
    r.error(
        f"RULE {rule.label}: {variable} has no term {term}",
        span or rule.span,
        "undeclared-term",
        hint="its terms: " + ", ".join(sorted(terms)),
    )


def _check_cycles(fb: m.FunctionBlock, r: _Reporter) -> None:
    """Rule blocks feed each other through local variables; a cycle has no evaluation order."""
    locals_ = {v.name for v in fb.locals}
    if not locals_ or len(fb.rule_blocks) < 2:
        return
    writes: dict[int, set[str]] = {}
    reads: dict[int, set[str]] = {}
    for i, rb in enumerate(fb.rule_blocks):
        writes[i] = {c.variable for rule in rb.rules for c in rule.conclusions} & locals_
        reads[i] = {s.variable for rule in rb.rules for s in m.walk_condition(rule.condition)} & locals_
    edges = {i: {j for j in writes if j != i and writes[i] & reads[j]} for i in writes}
    state: dict[int, int] = {}

    def visit(i: int, path: list[int]) -> list[int] | None:
        state[i] = 1
        for j in sorted(edges[i]):
            if state.get(j) == 1:
                return [*path[path.index(j) :], j] if j in path else [i, j]
            if state.get(j) is None:
                found = visit(j, [*path, j])
                if found:
                    return found
        state[i] = 2
        return None

    for i in edges:
        if state.get(i) is None:
            cycle = visit(i, [i])
            if cycle:
                names = " -> ".join(fb.rule_blocks[k].name or f"#{k + 1}" for k in cycle)
                via = sorted(set().union(*(writes[k] for k in cycle)))
                r.error(
                    f"rule blocks depend on each other in a cycle ({names}) through local "
                    f"variable(s) {', '.join(via)}",
                    fb.rule_blocks[cycle[0]].span,
                    "rule-block-cycle",
                )
                return


def check_functions(doc: m.Document, ctx: CheckContext) -> Iterator[Diagnostic]:
    """FUNCTION terms may only name declared variables."""
    r = _Reporter(ctx)
    for fb in doc.blocks:
        for block in term_blocks(fb):
            for t in block.terms:
                if isinstance(t.mf, m.FunctionMF):
                    for name in sorted({n.name for n in m.walk_expr(t.mf.expr) if isinstance(n, m.Name)}):
                        if fb.variable(name) is None and name not in ("x", "pi", "e"):
                            r.error(
                                f"TERM {t.name}: FUNCTION uses undeclared variable {name}",
                                t.span,
                                "undeclared-variable",
                            )
    yield from r.found


def check_reserved(doc: m.Document, ctx: CheckContext) -> list[Diagnostic]:
    """Identifiers that are IEC 61131-7 Table 7 keywords (:mod:`fuzzyctl.fcl.reserved`)."""
    return check_reserved_words(doc, ctx.file, bool(ctx.options.get("strict")))


def check_model(doc: m.Document, ctx: CheckContext) -> list[Diagnostic]:
    """The rules every reader applies (:mod:`fuzzyctl.validation`: points, degrees, weights),
    at FCL's own positions; ``strict``: a weight above 1 is an error."""
    compat = str(ctx.options.get("compat") or "iec")
    return at_spans(validate(doc, strict=bool(ctx.options.get("strict")), compat=compat), ctx.file)


register_provider("declarations", check_declarations)
register_provider("rules", check_rules)
register_provider("functions", check_functions)
register_provider("model", check_model)


def check_jfl(doc: m.Document, ctx: CheckContext) -> list[Diagnostic]:
    """Under ``compat="jfuzzylogic"``: what jFuzzyLogic 3.3 would reject or read differently
    (:mod:`fuzzyctl.fcl.jfl`)."""
    if ctx.options.get("compat") != "jfuzzylogic":
        return []
    return check_jfuzzylogic(doc, ctx.file, ctx.options.get("parsed"))


register_provider("reserved", check_reserved)
register_provider("jfuzzylogic", check_jfl)
