"""Model to canonical IEC 61131-7 FCL text.

Canonical means: upper-case keywords in the standard's spelling (``METHOD : CoG;``,
``RANGE(0..30);``), four-space indentation, one statement per line, the block order of
5.4.1 (declarations, FUZZIFY, DEFUZZIFY, RULEBLOCK, OPTIONS), points as ``(x, y)``, and
shapes in the spelling of :func:`fuzzyctl.fcl.shapes.spelling_for`.  Reading the output
gives a model equal to the input (tested on every corpus file and on random models)."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import replace

from fuzzyctl.diagnostics import Diagnostic, DiagnosticError, error
from fuzzyctl.escape import fcl_comment, fcl_options
from fuzzyctl.fcl import shapes
from fuzzyctl.fcl.identifiers import fcl_block_name, fcl_name, fcl_term
from fuzzyctl.fcl.no_if import with_if_parts
from fuzzyctl.fcl.parser import number_text
from fuzzyctl.fcl.words import unwritable_words
from fuzzyctl.model import (
    And,
    Binary,
    Call,
    Conclusion,
    Condition,
    Default,
    DefuzzifyBlock,
    Degree,
    Document,
    Expr,
    FunctionBlock,
    FunctionMF,
    FuzzifyBlock,
    Is,
    MembershipFunction,
    Name,
    Not,
    Num,
    OptionsBlock,
    Or,
    Param,
    PointsMF,
    Range,
    Ref,
    Rule,
    RuleBlock,
    ShapeMF,
    SingletonMF,
    SingletonsMF,
    Span,
    Term,
    Unary,
    Variable,
)

INDENT = "    "

# The standard's spellings of the methods (Table 1); everything else upper-case.
METHOD_SPELLING = {"COG": "CoG", "COGS": "CoGS", "COA": "CoA"}


def param_text(p: Param) -> str:
    return p.name if isinstance(p, Ref) else number_text(p)


def _comment_lines(comments: Iterable[str], indent: str) -> list[str]:
    # Every comment passes fcl_comment (a model's comments are untrusted text: one from JSON,
    # FPL or FLL could otherwise end the comment and add rules or blocks).
    out: list[str] = []
    for text in comments:
        first, *rest = fcl_comment(text).splitlines()
        out.append(indent + first)
        out.extend(rest)
    return out


# --------------------------------------------------------------------------- expressions

_PRECEDENCE = {"+": 1, "-": 1, "*": 2, "/": 2, "%": 2, "^": 4}


def expr_text(e: Expr, parent: int = 0, right: bool = False) -> str:
    """An expression with the parentheses its structure needs (and no more)."""
    if isinstance(e, Num):
        text = number_text(e.value)
        return f"({text})" if e.value < 0 and parent else text
    if isinstance(e, Name):
        return e.name
    if isinstance(e, Call):
        return f"{e.function}({', '.join(expr_text(a) for a in e.args)})"
    if isinstance(e, Unary):
        inner = expr_text(e.operand, 3)
        if isinstance(e.operand, Num):
            # "-1" would read back as the number -1, not as minus applied to 1.
            inner = f"({number_text(e.operand.value)})"
        text = f"{e.op}{inner}"
        return f"({text})" if parent >= 3 else text
    assert isinstance(e, Binary)
    prec = _PRECEDENCE[e.op]
    # '^' is right-associative; the others are left-associative.
    left = expr_text(e.left, prec + (1 if e.op == "^" else 0))
    right_text = expr_text(e.right, prec + (0 if e.op == "^" else 1), True)
    text = f"{left} {e.op} {right_text}"
    return f"({text})" if prec < parent else text


# --------------------------------------------------------------------------- terms


def mf_text(mf: MembershipFunction) -> str:
    if isinstance(mf, PointsMF):
        return " ".join(f"({param_text(p.x)}, {param_text(p.y)})" for p in mf.points)
    if isinstance(mf, SingletonMF):
        return param_text(mf.value)
    if isinstance(mf, SingletonsMF):
        return "SINGLETONS " + " ".join(f"({param_text(p.x)}, {param_text(p.y)})" for p in mf.points)
    if isinstance(mf, FunctionMF):
        return "FUNCTION " + expr_text(mf.expr)
    assert isinstance(mf, ShapeMF)
    spelling = shapes.spelling_for(mf)
    return " ".join([spelling.written, *(param_text(p) for p in shapes.written_args(spelling, mf))])


def _term(t: Term, indent: str) -> list[str]:
    return [*_comment_lines(t.comments, indent), f"{indent}TERM {t.name} := {mf_text(t.mf)};"]


def _range(r: Range) -> str:
    return f"RANGE({number_text(r.low)}..{number_text(r.high)});"


def _default(d: Default) -> str:
    if d.value is None:
        return "DEFAULT := NC;"
    if d.no_change:
        return f"DEFAULT := {number_text(d.value)} | NC;"
    return f"DEFAULT := {number_text(d.value)};"


# --------------------------------------------------------------------------- conditions

# Binding strength: OR 1, AND 2, NOT 3, subcondition 4 (Table 6).


def condition_text(c: Condition, parent: int = 0) -> str:
    """A condition with parentheses where the model nests (so reading it back gives the
    same tree): an AND or OR operand that is itself AND/OR of the same or weaker
    binding is parenthesised."""
    if isinstance(c, Is):
        words = [c.variable, "IS"]
        if c.negated:
            words.append("NOT")
        words.extend(c.hedges)
        words.append(c.term)
        return " ".join(words)
    if isinstance(c, Degree):
        return c.variable
    if isinstance(c, Not):
        inner = c.operand
        text = condition_text(inner, 3)
        if isinstance(inner, And | Or | Not):
            text = f"({condition_text(inner)})"
        return f"NOT {text}"
    own = 2 if isinstance(c, And) else 1
    keyword = " AND " if isinstance(c, And) else " OR "
    parts = []
    for operand in c.operands:
        text = condition_text(operand, own)
        if isinstance(operand, And | Or):
            other = 2 if isinstance(operand, And) else 1
            if other <= own:
                text = f"({text})"
        parts.append(text)
    return keyword.join(parts)


def conclusion_text(c: Conclusion) -> str:
    text = c.variable
    if c.term is not None:
        text += " IS " + " ".join([*c.hedges, c.term])
    if c.weight is not None:
        text += f" WITH {param_text(c.weight)}"
    return text


def rule_text(r: Rule) -> str:
    condition = condition_text(r.condition) if r.condition is not None else ""
    conclusions = ", ".join(conclusion_text(c) for c in r.conclusions)
    return f"RULE {r.label} : IF {condition} THEN {conclusions};"


# --------------------------------------------------------------------------- blocks


def _variables(fb: FunctionBlock) -> list[str]:
    # One section per run of same-kind declarations, so the declaration order (which the
    # model keeps and Linear terms depend on) survives a round trip.
    out: list[str] = []
    runs: list[list[Variable]] = []
    for v in fb.variables:
        if runs and runs[-1][0].kind is v.kind:
            runs[-1].append(v)
        else:
            runs.append([v])
    for group in runs:
        out.append(f"{INDENT}{group[0].kind.value}")
        out.extend(line for v in group for line in _variable(v))
        out.append(f"{INDENT}END_VAR")
        out.append("")
    return out


def _variable(v: Variable) -> list[str]:
    pad = INDENT * 2
    text = f"{pad}{v.name} : {v.data_type}"
    if v.initial is not None:
        if isinstance(v.initial, bool):
            text += f" := {'TRUE' if v.initial else 'FALSE'}"
        elif isinstance(v.initial, float | int):
            text += f" := {number_text(float(v.initial))}"
        else:
            text += f" := {v.initial}"
    text += ";"
    if v.range is not None:
        # RANGE on the declaration line is jFuzzyLogic's; kept there so that it reads back.
        text += " " + _range(v.range)
    return [*_comment_lines(v.comments, pad), text]


def _fuzzify(b: FuzzifyBlock) -> list[str]:
    inner = INDENT * 2
    out = [*_comment_lines(b.comments, INDENT), f"{INDENT}FUZZIFY {b.variable}"]
    if b.range is not None:
        out.append(inner + _range(b.range))
    for t in b.terms:
        out.extend(_term(t, inner))
    out.extend([f"{INDENT}END_FUZZIFY", ""])
    return out


def _defuzzify(b: DefuzzifyBlock) -> list[str]:
    inner = INDENT * 2
    out = [*_comment_lines(b.comments, INDENT), f"{INDENT}DEFUZZIFY {b.variable}"]
    if b.range is not None:
        out.append(inner + _range(b.range))
    for t in b.terms:
        out.extend(_term(t, inner))
    if b.method is not None:
        out.append(f"{inner}METHOD : {METHOD_SPELLING.get(b.method, b.method)};")
    if b.accu is not None:
        out.append(f"{inner}ACCU : {b.accu};")
    if b.default is not None:
        out.append(inner + _default(b.default))
    out.extend([f"{INDENT}END_DEFUZZIFY", ""])
    return out


def _rule_block(b: RuleBlock) -> list[str]:
    inner = INDENT * 2
    header = f"{INDENT}RULEBLOCK" + (f" {b.name}" if b.name is not None else "")
    out = [*_comment_lines(b.comments, INDENT), header]
    for keyword, value in (("AND", b.and_op), ("OR", b.or_op), ("ACT", b.act), ("ACCU", b.accu)):
        if value is not None:
            out.append(f"{inner}{keyword} : {value};")
    for r in b.rules:
        out.extend(_comment_lines(r.comments, inner))
        out.append(inner + rule_text(r))
    out.extend([f"{INDENT}END_RULEBLOCK", ""])
    return out


def _options(o: OptionsBlock) -> list[str]:
    end = "END_OPTION" if o.keyword == "OPTION" else "END_OPTIONS"
    body = [INDENT * 2 + line if line else "" for line in o.text.splitlines()]
    return [f"{INDENT}{o.keyword}", *body, f"{INDENT}{end}", ""]


def unwritable_names(fb: FunctionBlock) -> list[Diagnostic]:
    """Names FCL could not read back (a keyword such as ``if``, a space in a variable name,
    ``a/b``): written as they are, they would give a file the parser rejects."""
    found: list[Diagnostic] = []

    def bad(what: str, name: str, span: Span | None) -> None:
        found.append(
            error(
                f"{what} {name!r} cannot be written in FCL: it is not an identifier or it is an FCL keyword",
                span,
                code="fcl-write-name",
                hint="rename it (`fuzzyctl convert` renames such names itself)",
            )
        )

    if fb.name is not None and not fcl_block_name(fb.name):
        bad("function block", fb.name, fb.span)
    for v in fb.variables:
        if not fcl_term(v.name):  # the parser reads several-word names (ridderware's fly.fcl)
            bad("variable", v.name, v.span)
    blocks: list[FuzzifyBlock | DefuzzifyBlock] = [*fb.fuzzify, *fb.defuzzify]
    for blk in blocks:
        for t in blk.terms:
            if not fcl_term(t.name):
                bad(f"term of {blk.variable}", t.name, t.span)
    for rb in fb.rule_blocks:
        if rb.name and not fcl_name(rb.name):
            bad("rule block", rb.name, rb.span)
        for r in rb.rules:
            if r.label and not (r.label.isdigit() or fcl_name(r.label)):
                bad(f"rule of {rb.name or 'the rule block'}", r.label, r.span)
    return found


def write_block(fb: FunctionBlock) -> str:
    """FCL text of one function block; a name FCL could not read back is an error (all such
    names are listed) rather than a file that does not load."""
    fb = with_if_parts(fb)  # rules without an IF part: IF ALWAYS THEN (fcl/no_if.py)
    # OPTIONS text is free text: no END_OPTIONS inside, no control characters (escape.py)
    fb = replace(fb, options=tuple(replace(o, text=fcl_options(o.text)) for o in fb.options))
    problems = unwritable_names(fb) + unwritable_words(fb)
    if problems:
        raise DiagnosticError(problems)
    out = [*_comment_lines(fb.comments, ""), "FUNCTION_BLOCK" + (f" {fb.name}" if fb.name else ""), ""]
    out.extend(_variables(fb))
    for f in fb.fuzzify:
        out.extend(_fuzzify(f))
    for d in fb.defuzzify:
        out.extend(_defuzzify(d))
    for r in fb.rule_blocks:
        out.extend(_rule_block(r))
    for o in fb.options:
        out.extend(_options(o))
    out.append("END_FUNCTION_BLOCK")
    return "\n".join(out) + "\n"


def write(doc: Document | FunctionBlock) -> str:
    """Canonical FCL text for a document (all its function blocks) or one block."""
    if isinstance(doc, FunctionBlock):
        return write_block(doc)
    parts = [write_block(fb) for fb in doc.blocks]
    trailer = _comment_lines(doc.comments, "")
    text = "\n".join(parts)
    if trailer:
        text += "\n" + "\n".join(trailer) + "\n"
    return text
