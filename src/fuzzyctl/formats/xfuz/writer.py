"""Encoding a fuzzyctl model (an FCL program, ...) into XFUZ constants: slots, terms as
the four abscissae, rules as FA numbers, and what the tables cannot hold.

See :mod:`fuzzyctl.formats.xfuz.reader` for the mapping and the ``XFUZ`` OPTIONS lines."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace

from fuzzyctl.diagnostics import Diagnostic, DiagnosticError, Severity, error, warning
from fuzzyctl.formats.xfuz.tablefile import write_tables
from fuzzyctl.formats.xfuz.tables import (
    DISCR_MAX,
    MAX_RULES,
    OPEN_HIGH,
    OPEN_LOW,
    KnowledgeBase,
    SlotKind,
    XfuzConstants,
    XMembership,
    XRule,
    XVariable,
    check_kb,
    encode_kb,
    encode_name,
    slot_kind,
    slot_label,
)
from fuzzyctl.kinds import methods as method_kinds
from fuzzyctl.kinds import norms
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.model import (
    And,
    Condition,
    Document,
    FunctionBlock,
    FuzzifyBlock,
    Is,
    MembershipFunction,
    Not,
    Or,
    Param,
    Point,
    PointsMF,
    Range,
    Rule,
    RuleBlock,
    ShapeMF,
    SingletonMF,
    Span,
    Term,
    VarKind,
    implied_operators,
    is_constant,
)

__all__ = [
    "ALWAYS",
    "adapt_xfuz",
    "check_xfuz",
    "constants_from_model",
    "notes",
    "slot_labels",
    "with_always_predicate",
    "write_xfuz",
]


_SLOT_NAME = re.compile(r"^(INP|OUT|VAR)([1-8])$", re.IGNORECASE)
_OPTION = re.compile(r"^\s*XFUZ\s+(\S+)\s+(.*?)\s*;?\s*$", re.IGNORECASE)


@dataclass
class _Options:
    slots: dict[str, str]
    discr: dict[str, int]
    contask: bool = True
    t_ofb: int = 200


def _read_options(block: FunctionBlock, diags: list[Diagnostic]) -> _Options:
    opts = _Options({}, {})
    for ob in block.options:
        for line in ob.text.splitlines():
            m = _OPTION.match(line)
            if not m:
                continue
            key, args = m.group(1).upper(), m.group(2).split()
            try:
                if key == "SLOT" and len(args) == 2:
                    opts.slots[args[0]] = args[1].upper()
                elif key == "DISCR" and len(args) == 2:
                    opts.discr[args[0]] = int(args[1])
                elif key == "CONTASK$" and len(args) == 1:
                    opts.contask = bool(int(args[0]))
                elif key == "T_OFB$" and len(args) == 1:
                    opts.t_ofb = int(args[0])
                else:
                    diags.append(
                        warning(f"OPTIONS line not understood: {line.strip()}", ob.span, code="xfuz-options")
                    )
            except ValueError:
                diags.append(
                    error(f"OPTIONS line has a bad number: {line.strip()}", ob.span, code="xfuz-options")
                )
    return opts


def _int_point(value: Param, what: str, span: Span | None, diags: list[Diagnostic]) -> int:
    number = float(value) if isinstance(value, int | float) else math.nan
    if not (number == int(number) if math.isfinite(number) else False) or not OPEN_LOW <= number <= OPEN_HIGH:
        diags.append(
            error(
                f"{what}: {value} is not a 16-bit integer (XFUZ works on integer words)",
                span,
                code="xfuz-expr-value",
            )
        )
        return 0
    return int(number)


def _abcd(
    mf: MembershipFunction, what: str, span: Span | None, diags: list[Diagnostic]
) -> tuple[int, int, int, int] | None:
    """A term as the four XFUZ abscissae (None and an error when it has another shape, or
    abscissae out of order: a triangle 2 0 4 is no XFUZ term, and the XFUZ reader refuses
    it as every reader does points out of order)."""
    abcd = _abscissae(mf, what, span, diags)
    if abcd is not None and not abcd[0] <= abcd[1] <= abcd[2] <= abcd[3]:
        message = f"{what}: the abscissae {', '.join(map(str, abcd))} are not in ascending order"
        diags.append(error(message, span, code="xfuz-expr-term"))
        return None
    return abcd


def _xfuz_spelling(mf: MembershipFunction) -> tuple[int, int, int, int] | None:
    """Which parameters of a shape are XFUZ's trapezoid a, b, c, d (the registry's spelling)."""
    shape = registry.SHAPES.get(mf.kind) if isinstance(mf, ShapeMF) else None
    if shape is None or isinstance(shape.spellings.xfuz, registry.NA):
        return None
    return shape.spellings.xfuz


def _abscissae(
    mf: MembershipFunction, what: str, span: Span | None, diags: list[Diagnostic]
) -> tuple[int, int, int, int] | None:
    abcd = _xfuz_spelling(mf)
    if isinstance(mf, ShapeMF) and abcd is not None and mf.height == 1.0:
        p = [_int_point(x, what, span, diags) for x in mf.params]
        return (p[abcd[0]], p[abcd[1]], p[abcd[2]], p[abcd[3]])
    if isinstance(mf, PointsMF) and mf.points:
        pts = [(p.x, p.y) for p in mf.points]
        if not all(is_constant(y) and float(y) in (0.0, 1.0) for _, y in pts):  # type: ignore[arg-type]
            diags.append(error(f"{what}: XFUZ terms take degrees 0 and 1 only", span, code="xfuz-expr-term"))
            return None
        # Leading/trailing points that repeat the degree of their neighbour add nothing.
        while len(pts) > 1 and pts[0][1] == pts[1][1]:
            pts.pop(0)
        while len(pts) > 1 and pts[-1][1] == pts[-2][1]:
            pts.pop()
        ys = tuple(int(float(y)) for _, y in pts)  # type: ignore[arg-type]
        xs = [_int_point(x, what, span, diags) for x, _ in pts]
        shapes = {(1,): (OPEN_LOW, OPEN_LOW, OPEN_HIGH, OPEN_HIGH)}
        if ys == (1, 0):
            return (OPEN_LOW, OPEN_LOW, xs[0], xs[1])
        if ys == (0, 1):
            return (xs[0], xs[1], OPEN_HIGH, OPEN_HIGH)
        if ys == (0, 1, 0):
            return (xs[0], xs[1], xs[1], xs[2])
        if ys == (0, 1, 1, 0):
            return (xs[0], xs[1], xs[2], xs[3])
        if ys in shapes:
            return shapes[ys]
    diags.append(
        error(
            f"{what}: XFUZ terms are trapezoids, triangles or half trapezoids (and singletons "
            "with OUT_PT = 1)",
            span,
            code="xfuz-expr-term",
        )
    )
    return None


def _leaves(cond: Condition | None, rule: Rule, diags: list[Diagnostic]) -> list[tuple[Is, bool]]:
    if cond is None:
        return []
    if isinstance(cond, Is) and not cond.hedges:
        return [(cond, cond.negated)]
    if isinstance(cond, Not) and isinstance(cond.operand, Is) and not cond.operand.hedges:
        return [(cond.operand, not cond.operand.negated)]
    if isinstance(cond, And):
        return [leaf for c in cond.operands for leaf in _leaves(c, rule, diags)]
    diags.append(
        error(
            f"rule {rule.label}: XFUZ rules are ANDs of 'variable IS [NOT] term' (no OR, hedges "
            "or bare degrees)",
            getattr(cond, "span", None) or rule.span,
            code="xfuz-expr-rule",
            hint="split an OR into one rule per alternative",
        )
    )
    return []


def _assign_slots(fb: FunctionBlock, opts: _Options, diags: list[Diagnostic]) -> dict[str, int]:
    """Slots: an explicit ``XFUZ SLOT`` option, a name that is a slot label, else the next
    free slot of the variable's kind, in declaration order."""
    slots: dict[str, int] = {}
    taken: set[int] = set()
    pools = {VarKind.INPUT: range(0, 8), VarKind.OUTPUT: range(8, 14), VarKind.LOCAL: range(14, 18)}
    wanted: dict[str, int] = {}
    for v in fb.variables:
        label = opts.slots.get(v.name) or (v.name.upper() if _SLOT_NAME.match(v.name) else None)
        m = _SLOT_NAME.match(label or "")
        if m:
            first = {"INP": 0, "OUT": 8, "VAR": 14}[m.group(1).upper()]
            slot = first + int(m.group(2)) - 1
            if slot in pools[v.kind] and slot not in taken:
                wanted[v.name] = slot
                taken.add(slot)
    for v in fb.variables:
        if v.name in wanted:
            slots[v.name] = wanted[v.name]
            continue
        free = [s for s in pools[v.kind] if s not in taken]
        if not free:
            what = {
                VarKind.INPUT: "8 inputs",
                VarKind.OUTPUT: "6 outputs",
                VarKind.LOCAL: "4 intermediate variables",
            }
            diags.append(error(f"{v.name}: XFUZ has {what[v.kind]}", v.span, code="xfuz-expr-count"))
            continue
        slots[v.name] = free[0]
        taken.add(free[0])

    return slots


def slot_labels(block: FunctionBlock | Document) -> dict[str, str]:
    """Where each variable of ``block`` goes in the XFUZ block: name -> ``INP1``.. /
    ``OUT1``.. / ``VAR1``.."""
    fb = block.main if isinstance(block, Document) else block
    diags: list[Diagnostic] = []
    return {
        name: slot_label(slot) for name, slot in _assign_slots(fb, _read_options(fb, diags), diags).items()
    }


ALWAYS = "ALWAYS"
"""The term that carries a rule without an IF part in the tables (RG needs a predicate): a
function open on both sides (xA = xB = -32768, xC = xD = 32767), 1 for every input word."""


def with_always_predicate(fb: FunctionBlock) -> FunctionBlock:
    """``fb`` with each rule without an IF part (Siemens 1.5, degree 1) given the predicate
    ``INPi IS ALWAYS``, a term that is 1 on the whole 16-bit range, added to the first input
    (``fb`` itself when it has no such rule or no input)."""
    if not any(rule.condition is None for _rb, rule in fb.rules()) or not fb.inputs:
        return fb
    carrier = next((v for v in fb.inputs if fb.fuzzify_block(v.name) is not None), fb.inputs[0])
    block = fb.fuzzify_block(carrier.name) or FuzzifyBlock(carrier.name, ())
    taken = {t.name.upper() for t in block.terms}
    name, n = ALWAYS, 1
    while name.upper() in taken:
        n += 1
        name = f"{ALWAYS[: 8 - len(str(n))]}{n}"
    term = Term(name, PointsMF((Point(0.0, 1.0),)))  # one point: constant 1 (IEC 5.2.2)
    grown = replace(block, terms=(*block.terms, term))
    fuzzify = [grown if f.variable == carrier.name else f for f in fb.fuzzify]
    if fb.fuzzify_block(carrier.name) is None:
        fuzzify.append(grown)
    predicate = Is(carrier.name, name)
    rule_blocks = tuple(
        replace(
            rb, rules=tuple(replace(r, condition=predicate) if r.condition is None else r for r in rb.rules)
        )
        for rb in fb.rule_blocks
    )
    return replace(fb, fuzzify=tuple(fuzzify), rule_blocks=rule_blocks)


def constants_from_model(block: FunctionBlock | Document) -> tuple[XfuzConstants, list[Diagnostic]]:
    """Encode a function block into XFUZ constants.  Returns the constants and the
    diagnostics; when there are errors the constants are not meaningful.  A rule without an
    IF part gets the predicate ``INPi IS ALWAYS`` (:func:`with_always_predicate`)."""
    fb = block.main if isinstance(block, Document) else block
    fb = with_always_predicate(fb)
    diags: list[Diagnostic] = []
    opts = _read_options(fb, diags)

    def err(msg: str, span: Span | None, code: str, hint: str | None = None) -> None:
        diags.append(error(msg, span, code=code, hint=hint))

    slots = _assign_slots(fb, opts, diags)

    if fb.rule_blocks and (not fb.rule_blocks[0].enabled or fb.rule_blocks[0].rule_activation is not None):
        err(
            "XFUZ has no disabled rule blocks or rule activation methods",
            fb.rule_blocks[0].span,
            "xfuz-expr-ruleblocks",
        )
    if len(fb.rule_blocks) > 1:
        err(
            "XFUZ has a single rule base; use one XFUZ instance per rule block",
            fb.rule_blocks[1].span,
            "xfuz-expr-ruleblocks",
        )
    rb = fb.rule_blocks[0] if fb.rule_blocks else RuleBlock("xfuz", ())
    and_op = implied_operators(rb.and_op, rb.or_op)[0] if rb.or_op else rb.and_op  # OR : ASUM alone: PROD
    if norms.xfuz_code(and_op) is None:
        err(f"AND : {and_op}: XFUZ offers MIN or PROD", rb.span, "xfuz-expr-op")
    if norms.xfuz_code(rb.act) is None:
        err(f"ACT : {rb.act}: XFUZ offers MIN or PROD", rb.span, "xfuz-expr-op")
    if rb.accu is not None and not norms.is_max(rb.accu):
        err(f"ACCU : {rb.accu}: XFUZ aggregates with MAX", rb.span, "xfuz-expr-op")
    local_names = {v.name for v in fb.locals}
    methods = {d.method or "COG" for d in fb.defuzzify if d.terms and d.variable not in local_names}
    if len(methods) > 1:
        err(
            f"XFUZ has one defuzzification method for all outputs; found {', '.join(sorted(methods))}",
            None,
            "xfuz-expr-method",
        )
    method = methods.pop() if len(methods) == 1 else "COG"
    if method not in _XFUZ_METHODS:
        err(
            f"METHOD : {method}: XFUZ offers COG, MOM (mean of maxima) or singletons (COGS)",
            None,
            "xfuz-expr-method",
        )
    out_pt = _weighted(method)

    variables: list[XVariable] = []
    mf_list: list[tuple[int, Term, str]] = []  # (slot, term, variable name)
    o_def = [0] * 6
    for v in fb.variables:
        if v.name not in slots:
            continue
        slot = slots[v.name]
        fz, dz = fb.fuzzify_block(v.name), fb.defuzzify_block(v.name)
        rng = v.range or (dz.range if dz else None) or (fz.range if fz else None)
        low = _int_point(rng.low, f"{v.name} RANGE", v.span, diags) if rng else 0
        high = _int_point(rng.high, f"{v.name} RANGE", v.span, diags) if rng else 0
        kind = slot_kind(slot)
        if kind is SlotKind.INPUT:
            variables.append(XVariable(slot, low, high))
            mf_terms = fz.terms if fz else ()
        else:
            if rng is None and (dz or fz):
                err(
                    f"{v.name}: XFUZ outputs and intermediate variables need a RANGE (BorneInf..BorneSup)",
                    v.span,
                    "xfuz-expr-range",
                )
            discr = opts.discr.get(v.name, max(3, min(DISCR_MAX, (high - low) // 2 + 1)))
            label = slot_label(slot)
            vname = v.name if kind is SlotKind.INTERMEDIATE and v.name.upper() != label else ""
            try:
                encode_name(vname)
            except ValueError as exc:
                diags.append(
                    warning(f"{v.name}: {exc}; the name is not stored", v.span, code="xfuz-expr-name")
                )
                vname = ""
            variables.append(XVariable(slot, low, high, discr, vname))
            mf_terms = dz.terms if dz else (fz.terms if fz else ())
            if dz and fz and [t.name for t in dz.terms] != [t.name for t in fz.terms]:
                err(
                    f"{v.name}: FUZZIFY and DEFUZZIFY must have the same terms (XFUZ keeps one set per "
                    "variable)",
                    fz.span,
                    "xfuz-expr-terms",
                )
            if kind is SlotKind.OUTPUT and dz is not None and dz.default is not None:
                if dz.default.no_change or dz.default.value is None:
                    diags.append(
                        warning(
                            f"{v.name}: DEFAULT := NC has no XFUZ equivalent; O{slot - 7}_DEF$ is 0",
                            dz.default.span,
                            code="xfuz-expr-default",
                        )
                    )
                else:
                    o_def[slot - 8] = _int_point(dz.default.value, f"{v.name} DEFAULT", dz.span, diags)
        for t in mf_terms:
            mf_list.append((slot, t, v.name))
    # Inputs first (3.2-3), then outputs and intermediate variables, in declaration order.
    mf_list.sort(key=lambda item: slot_kind(item[0]) is not SlotKind.INPUT)
    memberships: list[XMembership] = []
    numbers: dict[tuple[str, str], int] = {}
    for _n, (slot, t, vname) in enumerate(mf_list):
        what = f"{vname}.{t.name}"
        if isinstance(t.mf, SingletonMF):
            if not out_pt or slot_kind(slot) is not SlotKind.OUTPUT:
                err(
                    f"{what}: a singleton needs singleton mode (METHOD : COGS on every output, OUT_PT = 1)",
                    t.span,
                    "xfuz-expr-term",
                )
                continue
            p = _int_point(t.mf.value, what, t.span, diags)
            abcd: tuple[int, int, int, int] | None = (p, p, p, p)
        elif out_pt and slot_kind(slot) is SlotKind.OUTPUT:
            err(f"{what}: with METHOD : COGS every output term must be a singleton", t.span, "xfuz-expr-term")
            continue
        else:
            abcd = _abcd(t.mf, what, t.span, diags)
        if abcd is None:
            continue
        tname = t.name if not re.fullmatch(r"FA\d+", t.name) else ""
        try:
            encode_name(tname)
        except ValueError as exc:
            diags.append(warning(f"{what}: {exc}; it is cut to 8 characters", t.span, code="xfuz-expr-name"))
            tname = tname.encode("cp850", "replace")[:8].decode("cp850")
        numbers[(vname, t.name)] = len(memberships)
        memberships.append(XMembership(len(memberships), tname, slot, *abcd))

    rules: list[XRule] = []
    for rule in rb.rules:
        preds: list[tuple[int, bool]] = []
        for leaf, negated in _leaves(rule.condition, rule, diags):
            key = (leaf.variable, leaf.term)
            if key not in numbers:
                err(
                    f"rule {rule.label}: {leaf.variable} IS {leaf.term} is no XFUZ membership function",
                    leaf.span or rule.span,
                    "xfuz-expr-rule",
                )
                continue
            preds.append((numbers[key], negated))
        if rule.condition is None:
            err(f"rule {rule.label}: XFUZ rules need at least one predicate", rule.span, "xfuz-expr-rule")
        concl: list[int] = []
        if rule.weight is not None and rule.weight != 1.0:
            err(f"rule {rule.label}: XFUZ rules have no weight", rule.span, "xfuz-expr-weight")
        for c in rule.conclusions:
            if c.hedges:
                err(
                    f"rule {rule.label}: XFUZ conclusions have no hedges",
                    c.span or rule.span,
                    "xfuz-expr-rule",
                )
            if c.weight is not None and c.weight != 1.0:
                err(
                    f"rule {rule.label}: XFUZ rules have no WITH weight",
                    c.span or rule.span,
                    "xfuz-expr-weight",
                )
            key = (c.variable, c.term or "")
            if key not in numbers:
                err(
                    f"rule {rule.label}: {c.variable} IS {c.term} is no XFUZ membership function",
                    c.span or rule.span,
                    "xfuz-expr-rule",
                )
                continue
            concl.append(numbers[key])
        if len(preds) > 4 or len(concl) > 2:
            err(
                f"rule {rule.label}: XFUZ rules have at most 4 predicates and 2 conclusions "
                f"(this one has {len(preds)} and {len(concl)})",
                rule.span,
                "xfuz-expr-rule",
            )
            continue
        rules.append(XRule(len(rules), tuple(preds), tuple(concl)))
    for what, count, limit in (("membership functions", len(memberships), 64), ("rules", len(rules), 64)):
        if count > limit:
            err(f"{count} {what}; XFUZ holds {limit}", None, "xfuz-expr-count")
    if any(d.is_error for d in diags):
        return XfuzConstants(), diags
    kb = KnowledgeBase(tuple(variables), tuple(memberships), tuple(rules))
    op_defuz = 1 if _mean_of_maximum(method) else 0
    for issue in check_kb(kb, out_pt=out_pt, op_defuz=op_defuz):
        diags.append(
            warning(
                f"the block would set STATUS bit {issue.bit}: {issue.message}",
                code=f"xfuz-status-{issue.bit}",
            )
        )
    esv, fa, rg = encode_kb(kb)
    constants = XfuzConstants(
        op_et=norms.xfuz_code(and_op) or 0,
        op_impl=norms.xfuz_code(rb.act) or 0,
        op_defuz=op_defuz,
        out_pt=out_pt,
        contask=opts.contask,
        t_ofb=opts.t_ofb,
        o_def=tuple(o_def),
        esv=esv,
        fa=fa,
        rg=rg,
    )
    return constants, diags


def check_xfuz(block: FunctionBlock) -> list[Diagnostic]:
    """What of ``block`` the XFUZ tables cannot hold (errors) or what the block would flag
    (warnings naming the STATUS bit)."""
    return constants_from_model(block)[1]


def write_xfuz(block: FunctionBlock | Document, *, layout: str = "json") -> str:
    """Table file text for a function block; raises DiagnosticError when it does not fit."""
    constants, diags = constants_from_model(block)
    if any(d.is_error for d in diags):
        raise DiagnosticError([d for d in diags if d.severity is not Severity.NOTE])
    return write_tables(constants, layout=layout)


def notes(document: Document) -> list[tuple[str, str]]:
    """A rule without an IF part (Siemens 1.5) has a predicate in RG: ``INPi IS ALWAYS``."""
    fb = document.main
    labels = [rule.label for _rb, rule in fb.rules() if rule.condition is None]
    if not labels or not fb.inputs:
        return []
    return [
        (
            f"rule(s) {', '.join(repr(x) for x in labels)}",
            "no IF part (degree 1): written with the predicate 'INPi IS ALWAYS', a function open on "
            "both sides (1 for every input word) on the first input, one of the 64 of FA",
        )
    ]


# --------------------------------------------------------------------------- adapting

Conjunct = list[tuple[Is, bool]]


def _dnf(cond: Condition | None, or_is_max: bool) -> list[Conjunct] | None:
    """``cond`` as an OR of ANDs of ``v IS [NOT] t``; None when that changes its value.

    Splitting an OR into rules is exact when OR is MAX (rules aggregate by MAX), and AND
    (MIN or product) distributes over MAX."""
    if isinstance(cond, Is):
        return None if cond.hedges else [[(cond, cond.negated)]]
    if isinstance(cond, Not) and isinstance(cond.operand, Is) and not cond.operand.hedges:
        return [[(cond.operand, not cond.operand.negated)]]
    if isinstance(cond, And):
        out: list[Conjunct] = [[]]
        for operand in cond.operands:
            part = _dnf(operand, or_is_max)
            if part is None:
                return None
            out = [a + b for a in out for b in part]
            if len(out) > MAX_RULES:  # more than the tables hold (and exponential to build)
                raise _TooMany
        return out
    if isinstance(cond, Or) and or_is_max:
        alternatives: list[Conjunct] = []
        for operand in cond.operands:
            part = _dnf(operand, or_is_max)
            if part is None:
                return None
            alternatives += part
            if len(alternatives) > MAX_RULES:
                raise _TooMany
        return alternatives
    return None


class _TooMany(Exception):
    """A condition whose OR-of-ANDs form has more rules than the RG table holds."""


def _extent(terms: tuple[Term, ...]) -> Range | None:
    xs = [float(x) for t in terms for x in _term_xs(t.mf)]
    xs = [x for x in xs if math.isfinite(x)]
    return Range(math.floor(min(xs)), math.ceil(max(xs))) if xs else None


def _term_xs(mf: MembershipFunction) -> list[float]:
    if isinstance(mf, PointsMF):
        return [float(p.x) for p in mf.points if isinstance(p.x, int | float)]
    if isinstance(mf, SingletonMF) and isinstance(mf.value, int | float):
        return [float(mf.value)]
    if isinstance(mf, ShapeMF):
        return [float(p) for p in mf.params if isinstance(p, int | float)]
    return []


def _rounded(mf: MembershipFunction) -> MembershipFunction:
    def r(v: object) -> bool:  # a finite literal (a MATLAB shoulder at +-inf stays as it is)
        return isinstance(v, int | float) and math.isfinite(v)

    if isinstance(mf, PointsMF):
        return PointsMF(tuple(replace(p, x=float(round(p.x))) if r(p.x) else p for p in mf.points))  # type: ignore[arg-type]
    if isinstance(mf, SingletonMF) and r(mf.value):
        return SingletonMF(float(round(mf.value)))  # type: ignore[arg-type]
    if isinstance(mf, ShapeMF):
        return replace(mf, params=tuple(float(round(p)) if r(p) else p for p in mf.params))  # type: ignore[arg-type]
    return mf


def adapt_xfuz(document: Document) -> tuple[Document, list[tuple[str, str]]]:
    """``document`` reduced to what the XFUZ tables hold, and what changes on the way as
    ``(element, reason)`` pairs.  Exact rewrites are not losses: OR split into rules (OR is
    MAX), more than 2 conclusions split into rules.  Losses: what is dropped (further rule
    blocks, weights, rules with hedges, terms of other shapes and their rules, variables
    and rules beyond the block's limits), what is rounded (non-integer points), operators
    replaced, and the XFUZ semantics themselves when the program does not already state
    them: defuzzification on Discr points (no ``XFUZ DISCR`` option) and 16-bit integer
    inputs and outputs (REAL variables)."""
    fb = with_always_predicate(document.main)
    losses: list[tuple[str, str]] = [
        (f"function block {b.name}", "XFUZ holds one rule base") for b in document.blocks[1:]
    ]
    opts = _read_options(fb, [])
    rb = fb.rule_blocks[0] if fb.rule_blocks else RuleBlock("xfuz", ())
    losses += [(f"rule block {b.name}", "XFUZ holds one rule base") for b in fb.rule_blocks[1:]]
    implied_and = implied_operators(rb.and_op, rb.or_op)[0] if rb.or_op else rb.and_op  # Table 3
    and_op = implied_and if norms.xfuz_code(implied_and) is not None else "MIN"
    act = rb.act if norms.xfuz_code(rb.act) is not None else "MIN"
    if and_op != implied_and or act != rb.act or (rb.accu is not None and not norms.is_max(rb.accu)):
        losses.append((f"rule block {rb.name}", "XFUZ offers AND MIN/PROD, ACT MIN/PROD and ACCU MAX only"))
    or_is_max = norms.is_max(rb.or_op) or (rb.or_op is None and (and_op is None or norms.is_min(and_op)))
    local_names = {v.name for v in fb.locals}
    methods = {d.method or "COG" for d in fb.defuzzify if d.terms and d.variable not in local_names}
    method = methods.pop() if len(methods) == 1 else "COG"
    if method not in _XFUZ_METHODS or methods:
        losses.append(
            (
                "defuzzification",
                f"XFUZ has one method for all outputs, COG, MOM or singletons; "
                f"{method if method in _XFUZ_METHODS else 'COG'} is used",
            )
        )
        method = method if method in _XFUZ_METHODS else "COG"
    singletons = _weighted(method)

    keep: set[tuple[str, str]] = set()

    def fit(owner: str, terms: tuple[Term, ...], output: bool) -> tuple[Term, ...]:
        kept = []
        for t in terms:
            mf = t.mf
            if isinstance(mf, SingletonMF) != (output and singletons):
                losses.append(
                    (
                        f"term {t.name!r} of {owner!r}",
                        "XFUZ output terms are all singletons (METHOD CoGS, OUT_PT = 1) or all trapezoids",
                    )
                )
                continue
            probe: list[Diagnostic] = []
            rounded = _rounded(mf)
            if not isinstance(mf, SingletonMF) and _abcd(rounded, t.name, None, probe) is None:
                losses.append(
                    (
                        f"term {t.name!r} of {owner!r}",
                        "XFUZ terms are trapezoids, triangles or half trapezoids with degrees 0 and 1",
                    )
                )
                continue
            if rounded != mf:
                losses.append((f"term {t.name!r} of {owner!r}", "abscissae rounded to integers"))
            kept.append(replace(t, mf=rounded))
            keep.add((owner, t.name))
        return tuple(kept)

    fuzzify = tuple(replace(fz, terms=fit(fz.variable, fz.terms, False)) for fz in fb.fuzzify)
    defuzzify = []
    for dz in fb.defuzzify:
        output = dz.variable not in local_names
        terms = fit(dz.variable, dz.terms, output)
        declared = fb.variable(dz.variable)
        rng = dz.range or (declared.range if declared is not None else None) or _extent(terms)
        default = dz.default
        if output and default is not None and (default.no_change or default.value is None):
            losses.append((f"output {dz.variable!r}", "DEFAULT := NC: XFUZ outputs a default value (0)"))
            default = None
        if output and dz.variable not in opts.discr and not singletons:
            losses.append((f"output {dz.variable!r}", "computed on Discr points (XFUZ 2.2-5), not exactly"))
        defuzzify.append(
            replace(
                dz, terms=terms, range=rng, method=None if not output else method, default=default, accu=None
            )
        )
    for v in fb.variables:
        if v.kind is not VarKind.LOCAL and v.data_type.upper() not in ("INT", "WORD", "SINT", "DINT"):
            losses.append((f"variable {v.name!r}", "XFUZ reads and writes 16-bit integers"))
        if v.kind is VarKind.LOCAL and v.name not in opts.slots and v.name not in opts.discr:
            losses.append(
                (f"variable {v.name!r}", "chained as a fuzzy set (XFUZ 2.2-1), not as a crisp value")
            )
    rules: list[Rule] = []
    for rule in rb.rules:
        label = f"rule {rule.label!r}"
        try:
            conjuncts = _dnf(rule.condition, or_is_max)
        except _TooMany:
            losses.append((label, f"as ANDs of 'v IS [NOT] t' it needs more than {MAX_RULES} rules"))
            continue
        if conjuncts is None:
            losses.append(
                (label, "XFUZ rules are ANDs of 'v IS [NOT] t' (OR only as MAX, no hedges or degrees)")
            )
            continue
        conclusions = [
            replace(c, weight=None) for c in rule.conclusions if (c.variable, c.term or "") in keep
        ]
        if any(c.hedges for c in rule.conclusions):
            losses.append((label, "XFUZ conclusions have no hedges"))
            continue
        if (rule.weight is not None and rule.weight != 1.0) or any(
            c.weight is not None and c.weight != 1.0 for c in rule.conclusions
        ):
            losses.append((label, "XFUZ rules have no weight"))
        if len(conclusions) < len(rule.conclusions) or any(
            (leaf.variable, leaf.term) not in keep for conj in conjuncts for leaf, _ in conj
        ):
            losses.append((label, "uses a term XFUZ cannot hold"))
            continue
        if any(len(conj) > 4 for conj in conjuncts):
            losses.append((label, "more than 4 predicates"))
            continue
        for k, conj in enumerate(conjuncts):
            preds = [replace(leaf, negated=negated) for leaf, negated in conj]
            cond: Condition = preds[0] if len(preds) == 1 else And(tuple(preds))
            exact = len(conjuncts) == 1 and len(conclusions) <= 2
            for j in range(0, max(len(conclusions), 1), 2):
                name = rule.label if exact else f"{rule.label}_{k + 1}_{j // 2 + 1}"
                rules.append(Rule(name, cond, tuple(conclusions[j : j + 2])))
    if len(rules) > 64:
        losses.append((f"rules {rules[64].label}..", "XFUZ holds 64 rules"))
        rules = rules[:64]
    if not rb.enabled or rb.rule_activation is not None:
        losses.append(
            (f"rule block {rb.name}", "XFUZ has no disabled rule blocks or rule activation methods")
        )
        rules = rules if rb.enabled else []
    adapted_rb = replace(
        rb,
        rules=tuple(rules),
        and_op=and_op,
        act=act,
        or_op=None,
        accu="MAX",
        enabled=True,
        rule_activation=None,
    )
    adapted = replace(fb, fuzzify=fuzzify, defuzzify=tuple(defuzzify), rule_blocks=(adapted_rb,))
    _, diags = constants_from_model(adapted)
    losses += [(f"line {d.span.line}" if d.span else "program", d.message) for d in diags if d.is_error]
    return Document((adapted,), path=document.path), losses


#: The methods XFUZ expresses (kinds/methods.py: COG, MOM, and singletons as COGS).
_XFUZ_METHODS = frozenset(method_kinds.written("xfuz"))


def _weighted(method: str) -> bool:
    """Singleton mode (OUT_PT = 1): the method weights points."""
    entry = method_kinds.METHODS.get(method)
    return entry is not None and entry.weighted is not None


def _mean_of_maximum(method: str) -> bool:
    """OP_DEFUZ = 1: the mean of maxima."""
    entry = method_kinds.METHODS.get(method)
    return entry is not None and entry.maximum == "mean"
