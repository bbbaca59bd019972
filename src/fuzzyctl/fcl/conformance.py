"""IEC 61131-7 clause 6: the conformance level a program needs and its data check list.

:func:`features` lists what a document uses, each feature tagged with the level that
introduces it (Table 8 Basic, Table 9 Extension, Table 10-style Open); :func:`level` is
the highest of them.  :func:`checklist` fills in Table 11 for a function block."""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum
from typing import Any

from fuzzyctl.fcl.checks import is_singleton, uses_operator
from fuzzyctl.kinds import norms
from fuzzyctl.kinds.methods import METHODS
from fuzzyctl.model import (
    And,
    Condition,
    Degree,
    Document,
    FunctionBlock,
    FunctionMF,
    Is,
    Not,
    Or,
    PointsMF,
    Ref,
    ShapeMF,
    SingletonMF,
    SingletonsMF,
    Term,
    walk_condition,
)


class Level(IntEnum):
    BASIC = 1
    EXTENSION = 2
    OPEN = 3

    def __str__(self) -> str:
        return self.name.capitalize()


@dataclass(frozen=True)
class Feature:
    level: Level
    table: str  # "Table 9", "Table 10"
    element: str
    detail: str


def _points(t: Term) -> int:
    mf = t.mf
    if isinstance(mf, PointsMF | SingletonsMF):
        return len(mf.points)
    if isinstance(mf, SingletonMF):
        return 1
    if isinstance(mf, ShapeMF):
        return len(mf.params)
    return 0


def _degrees(t: Term) -> list[float | Ref]:
    mf = t.mf
    if isinstance(mf, PointsMF | SingletonsMF):
        return [p.y for p in mf.points]
    return []


def _variable_points(t: Term) -> bool:
    """Abscissae given by variables (Table 9: "constant or variable points")."""
    mf = t.mf
    if isinstance(mf, PointsMF | SingletonsMF):
        return any(isinstance(p.x, Ref) for p in mf.points)
    if isinstance(mf, SingletonMF):
        return isinstance(mf.value, Ref)
    return False


def _variable_degrees(t: Term) -> bool:
    """Degrees given by variables: Table 9 keeps the degree co-ordinate at 0 or 1, Table 10
    lists "variable membership values" as Open level."""
    mf = t.mf
    return isinstance(mf, PointsMF | SingletonsMF) and any(isinstance(p.y, Ref) for p in mf.points)


def depth(c: Condition | None) -> int:
    """Parentheses the condition needs when written canonically (Table 11 "nesting depth")."""
    if c is None or isinstance(c, Degree) or not isinstance(c, And | Or | Not):
        return 0
    if isinstance(c, Not):
        inner = c.operand
        return depth(inner) + (1 if isinstance(inner, And | Or | Not) else 0)
    own = 2 if isinstance(c, And) else 1
    best = 0
    for o in c.operands:
        extra = 1 if isinstance(o, And | Or) and (2 if isinstance(o, And) else 1) <= own else 0
        best = max(best, depth(o) + extra)
    return best


def _flat(c: Condition | None) -> tuple[Is, ...] | None:
    """The tests of a condition that is one test or one AND / OR of tests, else None."""
    if isinstance(c, Is):
        return (c,)
    if isinstance(c, And | Or) and all(type(o) is Is for o in c.operands):
        return c.operands  # type: ignore[return-value]
    return None


def _flat_features(c: Condition | None, leaves: tuple[Is, ...], outputs: set[str], add: Any) -> None:
    ext, open_ = Level.EXTENSION, Level.OPEN
    if isinstance(c, Or):
        add(ext, "conditional aggregation", "operator OR in a condition")
    for s in leaves:
        if s.negated:
            add(ext, "conditional aggregation", "operator NOT")
        if s.hedges:
            add(open_, "condition", "hedges (fuzzylite)")
        if s.variable in outputs:
            add(open_, "condition", "output variable in a condition (chained rules)")


def _nested_features(c: Condition | None, outputs: set[str], add: Any) -> None:
    ext, open_ = Level.EXTENSION, Level.OPEN
    if uses_operator(c, Or):
        add(ext, "conditional aggregation", "operator OR in a condition")
    if uses_operator(c, Not) or any(s.negated for s in walk_condition(c) if not isinstance(s, Degree)):
        add(ext, "conditional aggregation", "operator NOT")
    if depth(c) > 0:
        add(ext, "parentheses", "( ) in conditions")
    for s in walk_condition(c):
        if isinstance(s, Degree):
            add(ext, "condition", "input variables as subconditions")
        elif s.hedges:
            add(open_, "condition", "hedges (fuzzylite)")
        if s.variable in outputs:
            add(open_, "condition", "output variable in a condition (chained rules)")


def features(doc: Document, spellings: frozenset[str] = frozenset()) -> list[Feature]:
    """Every non-Basic feature the document uses, without repeats, in table order."""
    found: dict[tuple[str, str], Feature] = {}

    def add(level: Level, element: str, detail: str) -> None:
        table = "Table 9" if level is Level.EXTENSION else "Table 10"
        found.setdefault((element, detail), Feature(level, table, element, detail))

    ext, open_ = Level.EXTENSION, Level.OPEN
    if len(doc.blocks) > 1:
        add(open_, "function blocks", f"{len(doc.blocks)} function blocks in one file")
    for fb in doc.blocks:
        if fb.locals:
            add(ext, "function block declaration", "VAR: local variables")
        if any(v.range is not None for v in fb.variables):
            add(open_, "declarations", "RANGE on a declaration line (jFuzzyLogic)")
        outputs = {v.name for v in fb.outputs}
        for blocks, side in ((fb.fuzzify, "input"), (fb.defuzzify, "output")):
            for b in blocks:
                if side == "input" and b.range is not None:
                    add(open_, "range", "RANGE in FUZZIFY (input universe)")
                for t in b.terms:
                    _term_features(t, side, add)
        for d in fb.defuzzify:
            if d.type_reduction is not None:
                add(open_, "type reduction", f"TYPE_REDUCTION: {d.type_reduction} (interval type-2)")
            if d.range is not None:
                add(ext, "range", "RANGE(min..max) for an output")
            level = "basic" if d.method is None else getattr(METHODS.get(d.method), "conformance", "open")
            if level == "extension":
                add(ext, "defuzzification method", f"METHOD: {d.method}")
            elif level == "open":
                add(open_, "defuzzification method", f"METHOD: {d.method}")
            if d.accu is not None:
                add(open_, "accumulation", "ACCU inside DEFUZZIFY (fuzzylite)")
            if d.default is not None and d.default.value is not None and d.default.no_change:
                add(open_, "default value", "DEFAULT := value | NC (fuzzylite)")
            elif d.default is not None and d.default.value is not None and d.default.value != d.default.value:
                add(open_, "default value", "DEFAULT := nan (fuzzylite)")
        if len(fb.rule_blocks) > 1:
            add(ext, "ruleblock", f"{len(fb.rule_blocks)} rule blocks")
        for rb in fb.rule_blocks:
            operators: tuple[tuple[norms.Role, str, str | None], ...] = (
                ("AND", "conditional aggregation", rb.and_op),
                ("OR", "conditional aggregation", rb.or_op),
                ("ACT", "activation", rb.act),
                ("ACCU", "accumulation", rb.accu),
            )
            for role, feature, name in operators:
                op_level = norms.conformance(role, name)
                if op_level != "basic":
                    add(ext if op_level == "extension" else open_, feature, f"{role}: {name}")
            for rule in rb.rules:
                c = rule.condition
                if c is None:  # written IF ALWAYS THEN (fcl/no_if.py): a degree input
                    add(ext, "condition", "rule without IF part: IF ALWAYS (an input variable)")
                leaves = _flat(c)
                if leaves is not None:  # the common rule: one walk over its tests
                    _flat_features(c, leaves, outputs, add)
                else:
                    _nested_features(c, outputs, add)
                if len(rule.conclusions) > 1:
                    add(ext, "conclusion", "n subconclusions")
                for concl in rule.conclusions:
                    if concl.term is None:
                        add(ext, "conclusion", "output variables as subconclusions")
                    if concl.hedges:
                        add(open_, "conclusion", "hedges in conclusions (fuzzylite)")
                    if concl.weight is not None:
                        detail = "variable" if isinstance(concl.weight, Ref) else "constant"
                        add(ext, "weighting factor", f"WITH {detail}")
        if fb.options:
            add(open_, "options", "OPTIONS ... END_OPTIONS")
    for spelling in sorted(spellings):
        add(open_, "membership function spelling", spelling)
    return sorted(found.values(), key=lambda f: (f.level, f.element, f.detail))


def _term_features(t: Term, side: str, add: object) -> None:
    assert callable(add)
    ext, open_ = Level.EXTENSION, Level.OPEN
    if t.lower is not None:  # docs/fcl.md, interval type-2 terms
        form = "SCALE/LAG" if t.lower.mf is None else "membership function"
        add(open_, "membership function", f"{side}: interval type-2 term (LOWER {form})")
    mf = t.mf
    n = _points(t)
    if isinstance(mf, ShapeMF):
        add(open_, "membership function", f"{side} shape {mf.kind}")
        return
    if isinstance(mf, FunctionMF):
        add(open_, "membership function", f"{side} FUNCTION term")
        return
    if isinstance(mf, SingletonsMF):
        add(open_, "membership function", f"{side} SINGLETONS (discrete set)")
        return
    if _variable_points(t):
        add(ext, "membership function", f"{side}: variable points")
    if _variable_degrees(t):
        add(open_, "membership function", f"{side}: variable membership degrees")
    degrees = [d for d in _degrees(t) if not isinstance(d, Ref)]
    if any(d not in (0.0, 1.0) for d in degrees):
        add(open_, "membership function", f"{side}: degrees between 0 and 1")
    if isinstance(mf, SingletonMF):
        if side == "input":
            add(open_, "membership function", "input singleton")
        return
    if side == "output":
        add(ext, "membership function", "output terms given by points")
    if n > 4:
        add(open_, "membership function", f"{side}: more than four points")
    elif n == 4 and side == "input":
        add(ext, "membership function", "input: four points")


def level(feats: list[Feature]) -> Level:
    return max((f.level for f in feats), default=Level.BASIC)


@dataclass(frozen=True)
class ChecklistRow:
    item: str
    value: str


def checklist(fb: FunctionBlock, comments_used: bool) -> list[ChecklistRow]:
    """Table 11 filled in for one function block."""
    inputs = [f for f in fb.fuzzify]
    outputs = [d for d in fb.defuzzify]
    in_terms = [t for f in inputs for t in f.terms]
    out_terms = [t for d in outputs for t in d.terms]
    rules = [r for rb in fb.rule_blocks for r in rb.rules]
    names = [v.name for v in fb.variables] + [t.name for t in in_terms + out_terms]
    names += [rb.name for rb in fb.rule_blocks if rb.name] + ([fb.name] if fb.name else [])
    types = sorted({v.data_type for v in (*fb.inputs, *fb.outputs)})
    shapes = any(isinstance(t.mf, ShapeMF) for t in in_terms + out_terms)

    def mx(values: list[int]) -> str:
        return str(max(values, default=0))

    rows = [
        ("data types of function block inputs and outputs", ", ".join(types) or "-"),
        ("line comments in the FCL program", "YES" if comments_used else "NO"),
        ("execution time (ms)", "not a property of the file"),
        ("memory requirements (kb)", "not a property of the file"),
        ("mapping of weighting factors and degrees onto integers", "not used (floating point)"),
        ("length of identifiers (longest)", mx([len(n) for n in names])),
        ("number of input variables for fuzzification", str(len(inputs))),
        ("membership function terms per input variable (max)", mx([len(f.terms) for f in inputs])),
        ("membership function terms for all input variables", str(len(in_terms))),
        ("points per input term (max)" + (" *" if shapes else ""), mx([_points(t) for t in in_terms])),
        ("points for all input terms", str(sum(_points(t) for t in in_terms))),
        ("number of output variables for defuzzification", str(len(outputs))),
        ("membership function terms per output variable (max)", mx([len(d.terms) for d in outputs])),
        ("membership function terms for all output variables", str(len(out_terms))),
        ("points per output term (max)" + (" *" if shapes else ""), mx([_points(t) for t in out_terms])),
        ("points for all output terms", str(sum(_points(t) for t in out_terms))),
        ("number of rule blocks", str(len(fb.rule_blocks))),
        ("rules per block (max)", mx([len(rb.rules) for rb in fb.rule_blocks])),
        ("subconditions per rule (max)", mx([len(list(walk_condition(r.condition))) for r in rules])),
        ("number of all rules", str(len(rules))),
        ("subconclusions per rule (max)", mx([len(r.conclusions) for r in rules])),
        ("nesting depth of ( )", mx([depth(r.condition) for r in rules])),
    ]
    return [ChecklistRow(a, b) for a, b in rows]


def singleton_outputs(fb: FunctionBlock) -> bool:
    return all(is_singleton(t.mf) for d in fb.defuzzify for t in d.terms)
