"""FPL files of any size and shape (issue 14, point 4): the size limit measured against the
largest configuration S7 Fuzzy Control allows (Siemens manual 1.3), the cap on unexpected
characters, and the plain-rule reader agreeing with the general one (timings are in
benchmarks/large_inputs.py, never here)."""

from __future__ import annotations

import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from fuzzyctl.diagnostics import Diagnostic
from fuzzyctl.formats.fpl import parse as fpl_parse
from fuzzyctl.formats.fpl.names import leaves
from fuzzyctl.formats.fpl.parse import MAX_UNEXPECTED
from fuzzyctl.formats.fpl.reader import parse_fpl, read_fpl
from fuzzyctl.limits import max_input_bytes
from fuzzyctl.model import And, Document, Span

# the largest project the manual allows, as the benchmark of large inputs writes it
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from large_inputs import s7_largest


@pytest.mark.parametrize("per_input", [1, 7])
def test_the_largest_s7_project_reads_far_under_the_fpl_limit(per_input: int) -> None:
    text = s7_largest(per_input)
    fb = read_fpl(text).main
    assert (len(fb.inputs), len(fb.outputs), len(fb.rule_blocks[0].rules)) == (8, 4, 200)
    assert all(len(b.terms) == 7 for b in fb.fuzzify) and all(len(b.terms) == 9 for b in fb.defuzzify)
    assert len(list(leaves(fb.rule_blocks[0].rules[0].condition))) == 8 * per_input
    # 77 KB with a condition per input, 346 KB with the 56 of the manual: the limit is
    # three times the larger, and far below the 8 MiB of the other text formats.
    assert 3 * len(text.encode()) <= max_input_bytes("fpl") < max_input_bytes("fcl")


def test_unexpected_characters_are_reported_up_to_a_bound() -> None:
    # A binary file or another format would give an error per byte: the first
    # MAX_UNEXPECTED are reported at their places, then one error says where reading stopped.
    result = parse_fpl("PROJECT p\n" + "* " * 1500 + "\nEND\n", path="bin.fpl")
    assert result.document is None
    diags = result.diagnostics
    assert len(diags) == MAX_UNEXPECTED + 1 == 1001
    assert {d.message for d in diags[:-1]} == {"unexpected character '*'"}
    assert [_place(d) for d in diags[:2]] == [(2, 1), (2, 3)]
    assert _place(diags[MAX_UNEXPECTED - 1]) == (2, 2 * MAX_UNEXPECTED - 1)
    last = diags[-1]
    assert last.is_error and last.file == "bin.fpl" and last.code == "fpl-syntax"
    assert last.message.startswith(f"more than {MAX_UNEXPECTED} unexpected characters")
    assert _place(last) == (2, 2 * MAX_UNEXPECTED + 1)  # the first character not reported
    # Fewer than the bound: every one, and no closing error.
    few = parse_fpl("PROJECT p ** VAR x END ; END").diagnostics
    assert [(d.message, _place(d)) for d in few] == [
        ("unexpected character '*'", (1, 11)),
        ("unexpected character '*'", (1, 12)),
        ("unexpected character ';'", (1, 24)),
    ]


def test_a_comment_never_closed_is_reported_where_it_opens() -> None:
    # Every "/*" after the last "*/" is unclosed: each is two unexpected characters (the
    # lexer no longer looks for a "*/" after them, which took a scan to the end each time).
    src = "/* ok */ PROJECT p\nVAR x /* a comment\n over two lines */ END\n" + "/* " * 600 + "END\n"
    diags = parse_fpl(src).diagnostics
    assert [(d.message, _place(d)) for d in diags[:3]] == [
        ("unexpected character '/'", (4, 1)),
        ("unexpected character '*'", (4, 2)),
        ("unexpected character '/'", (4, 4)),
    ]
    assert len(diags) == MAX_UNEXPECTED + 1


RULES = [
    "RULE r1 IF (a is lo) THEN y = s END",
    "RULE r1 IF a is lo THEN y = s END",
    "rule r_2 if (a IS lo) and b Is hi And (b is lo) then y = s, z = t AND y = t end",
    "RULE r3\r\n\tIF ( a is lo )AND(b is hi)\r\n THEN y=s\r\nEND",
    "RULE r4 IF (a is lo) AND (b is hi)\rTHEN y = s END",
    # taken by the general reader only: keywords and non-ASCII names, comments, numbers,
    # nested parentheses, conclusions in parentheses or with IS, NOT, OR, no IF part
    "RULE AND IF (a is lo) THEN y = s END",
    "RULE r5 IF (a is lo) THEN y = map END",
    "RULE r6 IF (ä is lo) THEN y = s END",
    "RULE r7 IF (a is lo) /* c */ THEN y = s END",
    "RULE 8 IF (a is lo) THEN y = s END",
    "RULE r9 IF ((a is lo) AND (b is hi)) AND a is hi THEN (y = s) END",
    "RULE r10 IF a is lo THEN y IS s END",
    "RULE r11 THEN y = s END",
    "RULE r12 IF (a is lo) OR (b is hi) THEN y = s END",
    "RULE r13 IF a is NOT lo THEN y = s END",
    "RULE r14 IF (a is lo) AND THEN y = s END",
    "RULE r15 IF (a is lo) THEN y = END",
    "RULE r16 IF (a is lo)THEN y = s END",
    "RULE r17 IF (a is lo) THENy = s END",
]


def _project(rule: str) -> str:
    return (
        "PROJECT p\nVAR a MEMBER lo POINTS 0,1 1,0 END MEMBER hi POINTS 0,0 1,1 END END\n"
        "VAR b MEMBER lo POINTS 0,1 1,0 END MEMBER hi POINTS 0,0 1,1 END END\n"
        "VAR y MEMBER s POINTS 0,1 0.1,1 END MEMBER t POINTS 1,1 END END\n"
        "VAR z MEMBER t POINTS 1,1 END END\n"
        f"FUZZY rb\nRULE first IF (a is lo) THEN y = s END\n{rule}\nEND\nEND\n"
    )


@pytest.mark.parametrize("rule", RULES)
def test_the_plain_rule_reader_reads_as_the_general_one(rule: str, monkeypatch: pytest.MonkeyPatch) -> None:
    text = _project(rule)
    taken = []
    plain = fpl_parse.Parser.plain_rule

    def counted(self: fpl_parse.Parser, start: fpl_parse._Tok) -> fpl_parse.FplRule | None:
        taken.append(plain(self, start))
        return taken[-1]

    monkeypatch.setattr(fpl_parse.Parser, "plain_rule", counted)
    fast = parse_fpl(text, path="r.fpl")
    assert taken[0] is not None  # the first rule is plain: the path is in use
    monkeypatch.setattr(fpl_parse.Parser, "plain_rule", lambda self, start: None)
    general = parse_fpl(text, path="r.fpl")
    assert _located(fast.diagnostics) == _located(general.diagnostics)
    assert (fast.document is None) == (general.document is None)
    if fast.document is not None and general.document is not None:
        assert fast.document == general.document
        assert list(_spans(fast.document)) == list(_spans(general.document))  # == ignores spans


def _place(d: Diagnostic) -> tuple[int, int]:
    assert d.span is not None
    return d.span.line, d.span.column


def _located(diags: tuple[Diagnostic, ...]) -> list[tuple[str, str, Span | None]]:
    return [(d.severity.value, d.message, d.span) for d in diags]


def _spans(doc: Document) -> Iterator[tuple[str, Span | None]]:
    for _rb, rule in doc.main.rules():
        yield rule.label, rule.span
        if isinstance(rule.condition, And):
            yield "and", rule.condition.span
        for leaf in leaves(rule.condition):
            yield leaf.variable, leaf.span
        for c in rule.conclusions:
            yield c.variable, c.span
