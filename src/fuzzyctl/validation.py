"""One validation for models from every reader (IEC 61131-7 5.2.2 and 5.2.4).

Whatever format a model comes from (FCL, JSON, FIS, FLL, FPL, XFUZ tables), the same rules
hold, so that a model one reader accepts is never a file another refuses (``convert``
never writes an FCL that ``check`` refuses):

* a points term (``PointsMF``) has at least two points (5.2.2: "The minimum number of points
  is two"); a singleton is not a points term (``TERM closed := 0;``, 5.2.3, and
  jFuzzyLogic's ``SINGLETONS (x, y)`` keep one value);
* the points of a points or singletons term are in ascending order of the variable value
  (5.2.2) and their membership degrees are in [0, 1];
* a RANGE has its minimum at or below its maximum;
* a WITH weight (and a FIS/fuzzylite rule weight) is a number >= 0; above 1 it is a warning
  (jFuzzyLogic multiplies by any weight, files written for it use them) and an error under
  ``strict`` (5.2.4 allows 0.0 to 1.0).

Parameters given by variables are checked where they are used (their values are not known
here).  :func:`validate` returns :class:`Finding` objects that name the element by its
place in the model (:attr:`Finding.path`, a JSON path of fuzzyctl's JSON form) and carry the
span the reader gave it; each reader turns them into diagnostics at its own position with
:func:`at_spans` (readers that keep spans) or :func:`at_json_paths` (the JSON reader).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass

from fuzzyctl.diagnostics import Diagnostic, Severity
from fuzzyctl.model import (
    DefuzzifyBlock,
    Document,
    FunctionBlock,
    FuzzifyBlock,
    Point,
    PointsMF,
    Range,
    Ref,
    SingletonsMF,
    Span,
    Term,
)

PathItem = str | int


@dataclass(frozen=True)
class Finding:
    """A rule the model breaks: where in the model (``path``), where in the source when the
    reader kept it (``span``), what (``code``, ``message``) and how bad (``severity``)."""

    severity: Severity
    code: str
    message: str
    path: tuple[PathItem, ...]
    span: Span | None = None
    hint: str | None = None

    @property
    def json_path(self) -> str:
        """``path`` as a JSON path of fuzzyctl's JSON form (``$.blocks[0].fuzzify[1]...``)."""
        return "$" + "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in self.path)


def _num(x: float) -> str:
    return f"{x:g}"


#: Tools whose profile (``compat=``) reads a term of one point, as a constant degree: under
#: them that term is a warning, not an error (jFuzzyLogic 3.3 runs such files).
ONE_POINT_TOOLS = frozenset({"jfuzzylogic"})


def _point_findings(
    term: Term, mf: PointsMF | SingletonsMF, where: tuple[PathItem, ...], compat: str = "iec"
) -> Iterator[Finding]:
    points: tuple[Point, ...] = mf.points
    if isinstance(mf, PointsMF) and len(points) < 2:
        if not points:
            yield Finding(Severity.ERROR, "empty-term", f"TERM {term.name} has no points", where, term.span)
        else:
            yield Finding(
                Severity.WARNING if compat in ONE_POINT_TOOLS else Severity.ERROR,
                "too-few-points",
                f"TERM {term.name} has one point; a membership function needs at least two (5.2.2)",
                (*where, "points", 0),
                points[0].span or term.span,
                hint="a singleton is written as its value alone (TERM t := 5;); "
                "a constant degree as two points",
            )
    for i in range(1, len(points)):
        a, b = points[i - 1].x, points[i].x
        if not isinstance(a, Ref) and not isinstance(b, Ref) and not b >= a:
            yield Finding(
                Severity.ERROR,
                "points-not-ascending",
                f"TERM {term.name}: points not in ascending order ({_num(a)} then {_num(b)})",
                (*where, "points", i, "x"),
                points[i].span or term.span,
                hint="5.2.2: the points shall be given in ascending order of the variable value",
            )
            break
    for i, p in enumerate(points):
        if not isinstance(p.y, Ref) and not 0.0 <= p.y <= 1.0:
            yield Finding(
                Severity.ERROR,
                "degree-out-of-range",
                f"TERM {term.name}: membership degree {_num(p.y)} is outside [0, 1]",
                (*where, "points", i, "y"),
                p.span or term.span,
            )


def _weight_finding(
    weight: float, label: str, what: str, where: tuple[PathItem, ...], span: Span | None, strict: bool
) -> Finding | None:
    if math.isnan(weight):
        return Finding(
            Severity.ERROR, "weight-out-of-range", f"RULE {label}: {what} is not a number", where, span
        )
    if weight < 0.0:
        return Finding(
            Severity.ERROR,
            "weight-out-of-range",
            f"RULE {label}: {what} {_num(weight)} is negative; 5.2.4 allows 0.0 to 1.0",
            where,
            span,
        )
    if weight > 1.0:
        if strict:
            return Finding(
                Severity.ERROR,
                "weight-out-of-range",
                f"RULE {label}: {what} {_num(weight)} is above 1; 5.2.4 allows 0.0 to 1.0",
                where,
                span,
            )
        # jFuzzyLogic multiplies by any weight; files written for it use weights > 1.
        return Finding(
            Severity.WARNING,
            "weight-out-of-range",
            f"RULE {label}: {what} {_num(weight)} is above 1; 5.2.4 allows 0.0 to 1.0 "
            "(used as written, as jFuzzyLogic does)",
            where,
            span,
            hint="--strict refuses it",
        )
    return None


def _range_finding(rng: Range | None, owner: str, where: tuple[PathItem, ...]) -> Iterator[Finding]:
    if rng is not None and rng.low > rng.high:
        message = f"{owner}: RANGE({_num(rng.low)}..{_num(rng.high)}): the minimum is above the maximum"
        yield Finding(Severity.ERROR, "bad-range", message, (*where, "range"), rng.span)


def _block_findings(
    fb: FunctionBlock, where: tuple[PathItem, ...], strict: bool, compat: str = "iec"
) -> Iterator[Finding]:
    for vi, v in enumerate(fb.variables):
        yield from _range_finding(v.range, f"variable {v.name}", (*where, "variables", vi))
    groups: tuple[tuple[str, tuple[FuzzifyBlock | DefuzzifyBlock, ...]], ...] = (
        ("fuzzify", fb.fuzzify),
        ("defuzzify", fb.defuzzify),
    )
    for kind, blocks in groups:
        for bi, block in enumerate(blocks):
            yield from _range_finding(block.range, f"{kind.upper()} {block.variable}", (*where, kind, bi))
            for ti, term in enumerate(block.terms):
                if isinstance(term.mf, PointsMF | SingletonsMF):
                    yield from _point_findings(term, term.mf, (*where, kind, bi, "terms", ti, "mf"), compat)
    for ri, rb in enumerate(fb.rule_blocks):
        for ui, rule in enumerate(rb.rules):
            at: tuple[PathItem, ...] = (*where, "rule_blocks", ri, "rules", ui)
            if isinstance(rule.weight, float | int):
                found = _weight_finding(
                    float(rule.weight), rule.label, "rule weight", (*at, "weight"), rule.span, strict
                )
                if found:
                    yield found
            for ci, c in enumerate(rule.conclusions):
                if isinstance(c.weight, float | int):
                    found = _weight_finding(
                        float(c.weight),
                        rule.label,
                        "weight",
                        (*at, "conclusions", ci, "weight"),
                        c.span or rule.span,
                        strict,
                    )
                    if found:
                        yield found


def validate(document: Document, *, strict: bool = False, compat: str = "iec") -> list[Finding]:
    """Every rule of this module that ``document`` breaks (errors and warnings), in model
    order; ``strict``: a weight above 1 is an error; ``compat``: a tool's profile
    (:data:`ONE_POINT_TOOLS` read a term of one point)."""
    out: list[Finding] = []
    for i, fb in enumerate(document.blocks):
        out.extend(_block_findings(fb, ("blocks", i), strict, compat))
    return out


def at_spans(findings: Sequence[Finding], file: str | None = None) -> list[Diagnostic]:
    """The findings as diagnostics at the spans the reader kept (file:line:column)."""
    return [Diagnostic(f.severity, f.message, f.span, file, f.code, f.hint) for f in findings]


def at_json_paths(findings: Sequence[Finding], file: str | None = None) -> list[Diagnostic]:
    """The findings as diagnostics naming their JSON path (the spans a JSON model holds are
    those of the file it was made from, not positions in the JSON)."""
    return [
        Diagnostic(f.severity, f"{f.json_path}: {f.message}", None, file, f.code, f.hint) for f in findings
    ]


Placer = Callable[[Sequence[Finding], "str | None"], list[Diagnostic]]
"""How a reader turns findings into diagnostics at its own positions."""

__all__ = ["ONE_POINT_TOOLS", "Finding", "Placer", "at_json_paths", "at_spans", "validate"]
