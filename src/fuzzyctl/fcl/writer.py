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
from fuzzyctl.fcl.numbers import number_text
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
    comments_at,
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


def _trail(line: str, comments: Iterable[str], indent: str) -> list[str]:
    """``line`` with ``comments`` after it on the same line (a multi-line comment goes on
    from there; after a ``//`` comment, which runs to the end of the line, the next one
    starts a line of its own)."""
    out = [line]
    open_line = True
    for text in comments:
        lines = _comment_lines([text], "")
        if open_line:
            out[-1] += " " + lines[0]
        else:
            out.append(indent + lines[0])
        out.extend(lines[1:])
        # a line comment runs to the end of the line: what follows starts a new one
        open_line = len(lines) > 1 or "\n" in lines[0] or not lines[0].lstrip().startswith("//")
    return out


def _statement(element: object, text: str, indent: str, place: str = "") -> list[str]:
    """A statement line with the comments written before it and after it on its line;
    ``place``: the prefix of an item's places in its block (``"method."``)."""
    return [
        *_comment_lines(comments_at(element, place + "before"), indent),
        *_trail(indent + text, comments_at(element, place + "after"), indent),
    ]


def _block_lines(block: object, header: str, body: list[str], end: str) -> list[str]:
    """A block: comments before it, its header (with those after it), its body, the
    comments before its END_ keyword and those after it."""
    return [
        *_comment_lines(comments_at(block, "before"), INDENT),
        *_trail(INDENT + header, comments_at(block, "head"), INDENT),
        *body,
        *_comment_lines(comments_at(block, "end"), INDENT * 2),
        *_trail(INDENT + end, comments_at(block, "tail"), INDENT),
        "",
    ]


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
    return _statement(t, f"TERM {t.name} := {mf_text(t.mf)};", indent)


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
        first, last = group[0], group[-1]
        # the comments around the VAR_... keywords of the source; where the writer joins two
        # sections of the same kind they go between the declarations
        out.extend(_comment_lines(comments_at(first, "section.before"), INDENT))
        out.extend(_trail(f"{INDENT}{first.kind.value}", comments_at(first, "section.head"), INDENT))
        for v in group:
            if v is not first:
                out.extend(_comment_lines(comments_at(v, "section.before"), INDENT * 2))
                out.extend(_comment_lines(comments_at(v, "section.head"), INDENT * 2))
            out.extend(_variable(v))
            if v is not last:
                out.extend(_comment_lines(comments_at(v, "section.end"), INDENT * 2))
                out.extend(_comment_lines(comments_at(v, "section.tail"), INDENT * 2))
        out.extend(_comment_lines(comments_at(last, "section.end"), INDENT * 2))
        out.extend(_trail(f"{INDENT}END_VAR", comments_at(last, "section.tail"), INDENT))
        out.append("")
    return out


def _variable(v: Variable) -> list[str]:
    pad = INDENT * 2
    text = f"{v.name} : {v.data_type}"
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
    return _statement(v, text, pad)


def _fuzzify(b: FuzzifyBlock) -> list[str]:
    inner = INDENT * 2
    out = _item(b, "range", _range(b.range) if b.range is not None else None, inner)
    for t in b.terms:
        out.extend(_term(t, inner))
    return _block_lines(b, f"FUZZIFY {b.variable}", out, "END_FUZZIFY")


def _defuzzify(b: DefuzzifyBlock) -> list[str]:
    inner = INDENT * 2
    out = _item(b, "range", _range(b.range) if b.range is not None else None, inner)
    for t in b.terms:
        out.extend(_term(t, inner))
    method = f"METHOD : {METHOD_SPELLING.get(b.method, b.method)};" if b.method is not None else None
    out.extend(_item(b, "method", method, inner))
    out.extend(_item(b, "accu", f"ACCU : {b.accu};" if b.accu is not None else None, inner))
    out.extend(_item(b, "default", _default(b.default) if b.default is not None else None, inner))
    out.extend(_other_items(b, ("range", "method", "accu", "default"), inner))
    return _block_lines(b, f"DEFUZZIFY {b.variable}", out, "END_DEFUZZIFY")


def _item(
    b: DefuzzifyBlock | FuzzifyBlock | RuleBlock, item: str, text: str | None, indent: str
) -> list[str]:
    """A single-valued item of a block with its comments; where the model has no value for
    it (``ACCU : NONE;``), its comments alone, where it stood among the items."""
    if text is not None:
        return _statement(b, text, indent, item + ".")
    return _comment_lines((*comments_at(b, item + ".before"), *comments_at(b, item + ".after")), indent)


def _other_items(b: DefuzzifyBlock | RuleBlock, items: tuple[str, ...], indent: str) -> list[str]:
    """The comments of items this writer does not know (none today), so that none is lost."""
    places = dict.fromkeys(p for p, _ in b.placed_comments if "." in p and p.split(".")[0] not in items)
    return [line for p in places for line in _comment_lines(comments_at(b, p), indent)]


def _rule_block(b: RuleBlock) -> list[str]:
    inner = INDENT * 2
    header = "RULEBLOCK" + (f" {b.name}" if b.name is not None else "")
    out: list[str] = []
    for keyword, value, item in (
        ("AND", b.and_op, "and_op"),
        ("OR", b.or_op, "or_op"),
        ("ACT", b.act, "act"),
        ("ACCU", b.accu, "accu"),
    ):
        out.extend(_item(b, item, f"{keyword} : {value};" if value is not None else None, inner))
    for r in b.rules:
        out.extend(_statement(r, rule_text(r), inner))
    out.extend(_other_items(b, ("and_op", "or_op", "act", "accu"), inner))
    return _block_lines(b, header, out, "END_RULEBLOCK")


def _options(o: OptionsBlock) -> list[str]:
    end = "END_OPTION" if o.keyword == "OPTION" else "END_OPTIONS"
    body = [INDENT * 2 + line if line else "" for line in o.text.splitlines()]
    return [
        *_comment_lines(comments_at(o, "before"), INDENT),
        f"{INDENT}{o.keyword}",
        *body,
        *_trail(f"{INDENT}{end}", comments_at(o, "after"), INDENT),
        "",
    ]


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
    header = "FUNCTION_BLOCK" + (f" {fb.name}" if fb.name else "")
    out = [*_comment_lines(fb.comments, ""), *_trail(header, comments_at(fb, "head"), ""), ""]
    out.extend(_variables(fb))
    for f in fb.fuzzify:
        out.extend(_fuzzify(f))
    for d in fb.defuzzify:
        out.extend(_defuzzify(d))
    for r in fb.rule_blocks:
        out.extend(_rule_block(r))
    for o in fb.options:
        out.extend(_options(o))
    out.extend(_comment_lines(comments_at(fb, "end"), INDENT))
    out.extend(_trail("END_FUNCTION_BLOCK", comments_at(fb, "tail"), ""))
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
