"""FPL, the Togai InfraLogic Fuzzy Programming Language, in the subset that Siemens
S7 Fuzzy Control reads and writes (Siemens manual, section 1.3).

The subset: one ``PROJECT``; ``VAR`` objects with ``TYPE``, ``MIN``, ``MAX`` and ``MEMBER``
objects holding a ``POINTS`` list; one ``FUZZY`` rule base of ``RULE`` objects
``IF (v is t) AND ... THEN v = t``; ``CONNECT FROM x TO y`` objects telling inputs from
outputs; ``END`` closing every object; ``/* */`` comments.  The elements the manual lists as
tolerated are skipped: ``MAP``, ``INITIALLY`` and ``DEFAULT`` with the manual's warning,
``OPTIONS``, ``SOURCE``, ``FRAGMENT`` and ``#CODE .. #END_CODE`` with a note.

Meaning of the points lists (Siemens 1.3): an input term is a rectangle, triangle or
trapezoid; "with vertical lines specifying the upper point is sufficient", so a list that
starts or ends on degree 1 strictly inside ``[MIN, MAX]`` has a vertical edge there (we add
the foot point).  At ``MIN``/``MAX`` the edge is kept as an IEC shoulder: the FB clamps its
inputs to the limits, so both readings agree inside the range and the shoulder also agrees
with an FCL program outside it.  An output term whose points all have degree 1 (the
"narrow rectangle" of the manual) is the singleton at its centre.

The rule base reads as IEC AND MIN, ACT MIN, ACCU NSUM, METHOD COGS (COG when an output has
area terms) and ``DEFAULT := NC``: Fuzzy Control keeps the last output when no rule fires.
ACCU NSUM because Fuzzy Control *adds* the contributions of several rules to one output
term (1.4, ``x_S' = (mu_A x_A + mu_B x_B + ...) / (mu_A + mu_B + ...)`` with one mu per
rule; glossary, "Singleton Function": "the influences ... resulting from various rules are
added together"); NSUM is the Table 5 sum, and its normalisation cancels in the centre of
gravity, so with singletons it computes exactly the manual's formula.
MIN/MAX of an input become the range of its FUZZIFY block, of an output the range of its
DEFUZZIFY block.  The block limits its inputs to [MIN, MAX] (1.5); that changes nothing when
every point of the input's terms lies in [MIN, MAX] (points lists are constant beyond their
ends), else the FUZZIFY block gets ``clamp``.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, replace

from fuzzyctl.diagnostics import Diagnostic, DiagnosticError, error, warning
from fuzzyctl.formats import Loaded
from fuzzyctl.formats.fpl.names import SIEMENS_ACCU, leaves
from fuzzyctl.formats.fpl.parse import FplVar, Parser, parse_project
from fuzzyctl.model import (
    Condition,
    Default,
    DefuzzifyBlock,
    Document,
    FunctionBlock,
    FuzzifyBlock,
    MembershipFunction,
    Point,
    PointsMF,
    Range,
    Rule,
    RuleBlock,
    SingletonMF,
    Span,
    Term,
    Variable,
    VarKind,
)

__all__ = ["FplResult", "parse_fpl", "read", "read_fpl"]

# --------------------------------------------------------------------------- model building


@dataclass(frozen=True)
class FplResult:
    """What :func:`parse_fpl` found: the document (None when there are errors) and every
    diagnostic, warnings for the tolerated elements included."""

    document: Document | None
    diagnostics: tuple[Diagnostic, ...]


def _input_points(points: Sequence[tuple[float, float]], low: float, high: float) -> tuple[Point, ...]:
    """Siemens points list -> IEC points (vertical edges inside the range get their foot)."""
    pts = list(points)
    if len(pts) == 1:
        x, y = pts[0]
        # a point of degree 0 is 0 everywhere: two points, as 5.2.2 asks
        pts = [(x, 0.0), (x, y), (x, 0.0)] if y > 0 else [(x, y), (x, y)]
    else:
        if pts[0][1] > 0 and pts[0][0] > low:
            pts.insert(0, (pts[0][0], 0.0))
        if pts[-1][1] > 0 and pts[-1][0] < high:
            pts.append((pts[-1][0], 0.0))
    return tuple(Point(x, y) for x, y in pts)


def _output_mf(points: Sequence[tuple[float, float]], low: float, high: float) -> MembershipFunction:
    if all(y == 1.0 for _, y in points):
        # The narrow rectangle that TILShell needs for a singleton (Siemens 1.3 and 1.4).
        return SingletonMF((points[0][0] + points[-1][0]) / 2.0)
    return PointsMF(_input_points(points, low, high))


def _build(p: Parser, file: str | None, comments: list[str]) -> FunctionBlock:
    diags = p.diags
    by_name: dict[str, FplVar] = {}
    for var in p.vars:
        if var.name in by_name:
            diags.append(error(f"VAR {var.name} is defined twice", var.span, code="fpl-duplicate", file=file))
        by_name[var.name] = var
        seen: set[str] = set()
        for m in var.members:
            if m.name in seen:
                diags.append(
                    error(
                        f"MEMBER {m.name} is defined twice in VAR {var.name}",
                        m.span,
                        code="fpl-duplicate",
                        file=file,
                    )
                )
            seen.add(m.name)
    base = p.rulebases[0] if p.rulebases else None
    base_name = base.name if base else None

    kinds: dict[str, VarKind] = {}
    for src, src_span, dst, dst_span in p.connects:
        if src == base_name and dst in by_name:
            kinds[dst] = VarKind.OUTPUT
        elif dst == base_name and src in by_name:
            kinds[src] = VarKind.INPUT
        else:
            bad, span = (src, src_span) if src not in by_name and src != base_name else (dst, dst_span)
            diags.append(
                error(
                    f"CONNECT FROM {src} TO {dst}: {bad} is not a VAR or the rule base",
                    span,
                    code="fpl-connect",
                    file=file,
                )
            )
    # Without CONNECT objects the rules tell inputs from outputs.
    for rule in base.rules if base else []:
        for c in rule.conclusions:
            kinds.setdefault(c.variable, VarKind.OUTPUT)
        for v in _condition_vars(rule.condition):
            kinds.setdefault(v, VarKind.INPUT)

    variables: list[Variable] = []
    fuzzify: list[FuzzifyBlock] = []
    defuzzify: list[DefuzzifyBlock] = []
    all_singletons = True
    outputs = [v for v in p.vars if kinds.get(v.name) is VarKind.OUTPUT]
    for var in p.vars:
        kind = kinds.get(var.name, VarKind.INPUT)  # a VAR in no rule is a monitoring input (1.5)
        rng = Range(var.low, var.high) if var.low is not None and var.high is not None else None
        low = var.low if var.low is not None else -math.inf
        high = var.high if var.high is not None else math.inf
        # MIN/MAX go where FCL puts a range: on the DEFUZZIFY block of an output, on the
        # FUZZIFY block of an input - with clamp, as the block limits its inputs (1.5) -
        # and on the declaration of a monitoring input, which has no terms.
        monitoring = kind is VarKind.INPUT and not var.members
        variables.append(Variable(var.name, kind, "REAL", range=rng if monitoring else None, span=var.span))
        if kind is VarKind.OUTPUT:
            terms = tuple(Term(m.name, _output_mf(m.points, low, high), span=m.span) for m in var.members)
            all_singletons &= all(isinstance(t.mf, SingletonMF) for t in terms)
            defuzzify.append(
                DefuzzifyBlock(var.name, terms, range=rng, default=Default(no_change=True), span=var.span)
            )
        elif var.members:
            terms = tuple(
                Term(m.name, PointsMF(_input_points(m.points, low, high)), span=m.span) for m in var.members
            )
            # Clamping only changes something when a term has points outside [MIN, MAX]:
            # IEC points lists are constant beyond their ends.
            outside = any(not low <= x <= high for m in var.members for x, _ in m.points)
            fuzzify.append(FuzzifyBlock(var.name, terms, range=rng, span=var.span, clamp=outside))
    method = "COGS" if all_singletons else "COG"
    defuzzify = [replace(d, method=method) for d in defuzzify]

    # The names of each VAR's MEMBERs, made once: a rule base may refer to them very often.
    members = {name: {m.name for m in var.members} for name, var in by_name.items()}
    for rule in base.rules if base else []:
        for cond in leaves(rule.condition):
            _check_ref(members, kinds, cond.variable, cond.term, VarKind.INPUT, cond.span, file, diags)
        for c in rule.conclusions:
            _check_ref(members, kinds, c.variable, c.term, VarKind.OUTPUT, c.span, file, diags)
    if not outputs and base and base.rules:
        diags.append(
            warning(
                "no output variable: nothing is CONNECTed FROM the rule base",
                base.span,
                code="fpl-no-output",
                file=file,
            )
        )
    rule_blocks: tuple[RuleBlock, ...] = ()
    if base is not None:
        rules = tuple(Rule(r.label, r.condition, tuple(r.conclusions), span=r.span) for r in base.rules)
        rule_blocks = (
            RuleBlock(base.name, rules, and_op="MIN", act="MIN", accu=SIEMENS_ACCU, span=base.span),
        )
    return FunctionBlock(
        p.project, tuple(variables), tuple(fuzzify), tuple(defuzzify), rule_blocks, comments=tuple(comments)
    )


def _condition_vars(cond: Condition | None) -> Iterator[str]:
    for leaf in leaves(cond):
        yield leaf.variable


def _check_ref(
    members: dict[str, set[str]],
    kinds: dict[str, VarKind],
    var: str,
    term: str | None,
    want: VarKind,
    span: Span | None,
    file: str | None,
    diags: list[Diagnostic],
) -> None:
    role = "output" if want is VarKind.OUTPUT else "input"
    if var not in members:
        diags.append(error(f"{var} is not a VAR of this project", span, code="fpl-undeclared", file=file))
    elif kinds.get(var) is not want:
        diags.append(
            error(
                f"{var} is used as an {role} but CONNECTed the other way",
                span,
                code="fpl-direction",
                file=file,
            )
        )
    elif term is not None and term not in members[var]:
        diags.append(error(f"{var} has no MEMBER {term}", span, code="fpl-undeclared-term", file=file))


def parse_fpl(text: str, *, path: str | None = None) -> FplResult:
    """Read FPL source text; never raises for bad input (see :class:`FplResult`)."""
    diags: list[Diagnostic] = []
    comments: list[str] = []
    parser = parse_project(text, path, diags, comments)
    block = _build(parser, path, comments) if parser is not None else None
    ok = block is not None and not any(d.is_error for d in diags)
    # the comments are the block's (written before it): on the document too, FCL had them twice
    doc = Document((block,), path=path) if ok and block else None
    return FplResult(doc, tuple(diags))


def read_fpl(text: str, *, path: str | None = None) -> Document:
    """Read FPL source text into a :class:`~fuzzyctl.model.Document`.

    Raises :class:`~fuzzyctl.diagnostics.DiagnosticError` (every diagnostic, file:line:col)
    when the text has errors; use :func:`parse_fpl` to see the warnings of a good file."""
    result = parse_fpl(text, path=path)
    if result.document is None:
        raise DiagnosticError(result.diagnostics, text)
    return result.document


# --------------------------------------------------------------------------- registry


def read(text: str, path: str | None = None) -> Loaded:
    """The registry's reader: the model and the warnings met on the way."""
    result = parse_fpl(text, path=path)
    if result.document is None:
        raise DiagnosticError(result.diagnostics, text)
    return Loaded(result.document, result.diagnostics)
