"""The fast reader of RULE and TERM runs (fuzzyctl.fcl.fast) against lark, the grammar of
record: the same model - every field, spans and comments included - the same diagnostics
(place, wording, order) and the same shape spellings, on every FCL file we have and on
generated rule and term blocks (valid ones, and ones with a mistake somewhere)."""

from __future__ import annotations

import dataclasses
import random
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fuzzyctl.fcl import fast
from fuzzyctl.fcl.fast_blocks import read_blocks
from fuzzyctl.fcl.parser import parse_source
from fuzzyctl.fcl.source import Source, read_source
from tests.extras import extra_files

ROOT = Path(__file__).resolve().parents[2]
LOCAL = sorted({*ROOT.joinpath("examples").rglob("*.fcl"), *ROOT.joinpath("tests", "data").rglob("*.fcl")})


def deep(obj: Any) -> Any:
    """Everything a model object holds, compared fields included (spans, comments)."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return (type(obj).__name__, *(deep(getattr(obj, f.name)) for f in dataclasses.fields(obj)))
    if isinstance(obj, list | tuple):
        return tuple(deep(x) for x in obj)
    if isinstance(obj, float) and obj != obj:
        return "nan"
    return obj


def both(text: str, path: str | None = "t.fcl") -> tuple[Any, Any]:
    source = Source(text, path)
    fast_result = parse_source(source)
    lark_result = parse_source(source, fast=False)
    return (
        (deep(fast_result.document), deep(fast_result.diagnostics), fast_result.spellings),
        (deep(lark_result.document), deep(lark_result.diagnostics), lark_result.spellings),
    )


def assert_same(text: str, path: str | None = "t.fcl") -> None:
    got, want = both(text, path)
    assert got[1] == want[1]  # diagnostics first: the clearer message
    assert got[0] == want[0]
    assert got[2] == want[2]


def _read(path: Path) -> str | None:
    try:
        return read_source(path).text
    except Exception:  # undecodable files are refused before parsing, by both paths
        return None


@pytest.mark.parametrize("path", LOCAL, ids=lambda p: str(p.relative_to(ROOT)))
def test_same_model_on_local_files(path: Path) -> None:
    text = _read(path)
    if text is not None:
        assert_same(text, str(path))


CORPUS = extra_files("corpus", "corpus", pattern="*.fcl", recursive=True)


@pytest.mark.extra("corpus")
def test_same_model_on_the_corpus() -> None:
    assert CORPUS, "no FCL file in the corpus"
    taken = 0
    for path in CORPUS:
        text = _read(path)
        if text is None:
            continue
        if fast.read_runs(text) is not None:
            taken += 1
        got, want = both(text, str(path))
        assert got == want, path
    assert taken > len(CORPUS) // 2  # the fast reader is used on most real files


def test_fast_reader_takes_the_bulk_of_a_rule_base() -> None:
    head = (
        "FUNCTION_BLOCK f VAR_INPUT a, b : REAL; END_VAR VAR_OUTPUT y : REAL; END_VAR\n"
        "FUZZIFY a TERM lo := (0, 1) (1, 0); TERM hi := (0, 0) (1, 1); END_FUZZIFY\n"
        "FUZZIFY b TERM lo := (0, 1) (1, 0); TERM hi := (0, 0) (1, 1); END_FUZZIFY\n"
        "DEFUZZIFY y TERM lo := 0; TERM hi := 1; METHOD : COGS; END_DEFUZZIFY\nRULEBLOCK r\n"
    )
    rules = "".join(f"RULE {k} : IF a IS lo AND b IS hi THEN y IS lo;\n" for k in range(50))
    text = head + rules + "END_RULEBLOCK\nEND_FUNCTION_BLOCK\n"
    result = fast.read_runs(text)
    assert result is not None and len(result.items) == 48  # all but the first and the last
    assert_same(text)
    # a mistake in the middle: lark reads it, with its place
    broken = text.replace("RULE 25 : IF a IS lo AND", "RULE 25 : IF a IS lo AND ;")
    got, want = both(broken)
    assert got == want and want[0] is None


# --------------------------------------------------------------------------- generated text

NAMES = ["a", "b", "Temp", "x_1", "lo", "hi", "very", "and", "NC", "with", "is", "not", "inf", "e1", "é"]
WS = [" ", "  ", "\n", "\t", " (* c *) ", " // note\n", "\r\n", " /* x\n y */ "]


def _ws(rng: random.Random) -> str:
    return rng.choice(WS) if rng.random() < 0.3 else " "


def _cond(rng: random.Random, depth: int) -> str:
    r = rng.random()
    if depth > 0 and r < 0.15:
        return "NOT" + _ws(rng) + _cond(rng, depth - 1)
    if depth > 0 and r < 0.3:
        return "(" + _cond(rng, depth - 1) + ")"
    if depth > 0 and r < 0.5:
        op = rng.choice(["AND", "OR", "and", "Or"])
        return _cond(rng, depth - 1) + _ws(rng) + op + _ws(rng) + _cond(rng, depth - 1)
    name = rng.choice(NAMES)
    if r < 0.55:
        return name
    words = [rng.choice(NAMES) for _ in range(rng.choice([1, 1, 1, 2]))]
    neg = "NOT " if rng.random() < 0.15 else ""
    return f"{name}{_ws(rng)}IS{_ws(rng)}{neg}{' '.join(words)}"


def _conclusion(rng: random.Random) -> str:
    text = rng.choice(NAMES)
    if rng.random() < 0.85:
        text += " IS " + " ".join(rng.choice(NAMES) for _ in range(rng.choice([1, 1, 2])))
    if rng.random() < 0.2:
        text += " WITH " + rng.choice(["0.5", "1", "-1", "inf", "1e999", "w", ".5", "2e-3", "\u22121"])
    return text


def _rule(rng: random.Random, k: int) -> str:
    label = rng.choice([str(k), f"R{k}", f"{k}a", f"_{k}", "1.5"])
    concl = (rng.choice([", ", " AND ", " and "])).join(
        _conclusion(rng) for _ in range(rng.choice([1, 1, 2]))
    )
    end = rng.choice([";", ";", ";", ""])
    return f"RULE{_ws(rng)}{label}{_ws(rng)}:{_ws(rng)}IF {_cond(rng, 3)}{_ws(rng)}THEN {concl}{end}\n"


def _term(rng: random.Random, k: int) -> str:
    name = rng.choice(NAMES) + str(k % 3)
    r = rng.random()
    if r < 0.4:
        mf = " ".join(f"({rng.choice(['0', '1', '-2.5', 'x', 'inf'])},{_ws(rng)}{rng.choice(['0', '1'])})"
                      for _ in range(rng.choice([1, 2, 3])))  # fmt: skip
    elif r < 0.55:
        mf = rng.choice(["0", "1.5", "-3", "nan", "x"])
    else:
        shape = rng.choice(["TRIAN", "trian", "TRAP", "GAUSS", "gbell", "Triangle", "Discrete", "nope"])
        mf = (
            shape
            + " "
            + " ".join(rng.choice(["0", "1", "2", "3", "z"]) for _ in range(rng.choice([2, 3, 4])))
        )
    return f"TERM {name} := {mf}{rng.choice([';', ';', ';', ''])}\n"


def _document(rng: random.Random) -> str:
    terms = "".join(_term(rng, k) for k in range(rng.randrange(0, 8)))
    rules = "".join(_rule(rng, k) for k in range(rng.randrange(0, 10)))
    text = (
        "FUNCTION_BLOCK g\nVAR_INPUT a : REAL; b : REAL; Temp : REAL; END_VAR\n"
        "VAR_OUTPUT x_1 : REAL; END_VAR\n"
        f"FUZZIFY a\n{terms}END_FUZZIFY\nFUZZIFY b TERM lo := 0; TERM hi := 1; END_FUZZIFY\n"
        f"DEFUZZIFY x_1 TERM lo := 0; TERM hi := 1; END_DEFUZZIFY\nRULEBLOCK r\n{rules}END_RULEBLOCK\n"
        "END_FUNCTION_BLOCK\n"
    )
    if rng.random() < 0.3:  # a mistake somewhere
        pos = rng.randrange(len(text))
        text = (
            text[:pos] + rng.choice(["(", ")", ";", "RULE", "TERM", "*)", "(*", "x", ":", "IS"]) + text[pos:]
        )
    return text


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 2**32 - 1))
def test_same_model_on_generated_blocks(seed: int) -> None:
    assert_same(_document(random.Random(seed)))


# --------------------------------------------------------------------------- conditions

HEAD = (
    "FUNCTION_BLOCK f VAR_INPUT a, b : REAL; END_VAR VAR_OUTPUT y : REAL; END_VAR\n"
    "FUZZIFY a TERM lo := (0, 1) (1, 0); TERM hi := (0, 0) (1, 1); END_FUZZIFY\n"
    "DEFUZZIFY y TERM lo := 0; TERM hi := 1; END_DEFUZZIFY\nRULEBLOCK r\n"
)
TAIL = "END_RULEBLOCK\nEND_FUNCTION_BLOCK\n"


def _rules(*conditions: str, then: str = " THEN y IS lo;") -> str:
    return HEAD + "".join(f"RULE {k} : IF {c}{then}\n" for k, c in enumerate(conditions)) + TAIL


def _nest(n: int, unit: str = "a IS lo AND (") -> str:
    return unit * n + "b IS hi" + ")" * n


DEEP = {
    # redundant parentheses vanish: the rule reads as a IS lo
    "parens": "(" * 3000 + "a IS lo" + ")" * 3000,
    "parens spaced": "( \n" * 500 + "a IS lo AND b" + " )\n" * 500,
    "parens with comments": "((* c *)(  (/* d */(a IS lo)) // e\n OR (b IS very hi)))",
    "group in groups": "(((a IS lo AND b IS hi))) OR (((NOT a IS lo)))",
    "glued": "(a IS lo)AND(b IS hi)",
    # NOTs: the limit is 100 levels, the atom one of them
    "nots 99": "NOT " * 99 + "a IS lo",
    "nots 100": "NOT " * 100 + "a IS lo",
    "nots 2000": "NOT " * 2000 + "a IS lo",
    "nots in parens": "NOT (" * 60 + "a IS lo" + ")" * 60,
    "nots in parens 3000": "NOT(" * 3000 + "a IS lo" + ")" * 3000,
    "nots and comments": "NOT (* x *) NOT\nNOT // y\n a IS lo",
    # real nesting: each AND level counts
    "nest 98": _nest(98),
    "nest 99": _nest(99),
    "nest 3000": _nest(3000),
    "nest or": _nest(150, "a IS lo OR NOT ("),
    "left nest 120": "(" * 120 + "a IS lo" + " AND b IS hi)" * 120,
    "left nest 99": "(" * 99 + "a IS lo" + " OR b IS hi)" * 99,
    "mixed": "(" * 40 + _nest(70) + " AND NOT a IS hi" + ")" * 40 + " OR " + _nest(30, "NOT ("),
    "too deep then fine": _nest(200) + " OR " + "(" * 50 + "a IS lo" + ")" * 50,
    "long and": " AND ".join(["a IS lo"] * 3000),
    "long or of ands": " OR ".join(["(a IS lo AND b IS hi)"] * 500),
}
BROKEN = {
    "unclosed": "(" * 300 + "a IS lo" + ")" * 299,
    "closed twice": "(" * 300 + "a IS lo" + ")" * 301,
    "no operand": "NOT " * 300,
    "empty group": "(" * 200 + ")" * 200,
    "unclosed comment": "(" * 200 + "(*a IS lo" + ")" * 200,
    "number": "(" * 200 + "a IS 1" + ")" * 200,
}


@pytest.fixture(params=[200, 0], ids=["long-conditions", "every-condition"])
def substitute_min(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> int:
    """The fast reader reads the conditions of the rules that lark reads: long ones (as
    shipped), or every one (to check the substitution on every shape)."""
    monkeypatch.setattr(fast, "SUBSTITUTE_MIN", request.param)
    return int(request.param)


@pytest.mark.parametrize("name", sorted(DEEP))
def test_deep_and_long_conditions(name: str, substitute_min: int) -> None:
    cond = DEEP[name]
    alone = _rules(cond)
    result = fast.read_runs(alone)
    if len(cond) >= substitute_min:  # lark reads the rule, the fast reader its condition
        assert result is not None and len(result.conditions) == 1
    assert_same(alone)
    assert_same(_rules(*[cond] * 4))  # in a run
    assert_same(_rules("a IS lo", cond, "a IS lo", "b IS hi", cond, cond, "a IS hi"))
    # after THEN, a mistake lark reports with the condition read here
    assert_same(_rules(cond, cond, then=" THEN y IS ;"))
    assert_same(_rules(cond, then=" THEN y IS lo WITH ;"))
    assert_same(_rules(cond, then="(* c *) THEN y IS lo;"))


@pytest.mark.parametrize("name", sorted(BROKEN))
def test_broken_deep_conditions(name: str, substitute_min: int) -> None:
    cond = BROKEN[name]
    assert_same(_rules(cond))
    assert_same(_rules("a IS lo", "a IS lo", cond, "a IS lo", "a IS lo", "a IS lo"))


def test_too_deep_is_found_without_building_the_tree() -> None:
    """The place and words lark gives, from a condition the fast reader only measured."""
    text = _rules(
        "a IS lo", "NOT (" * 50_000 + "a IS lo" + ")" * 50_000, "(" * 99_999 + "b IS hi" + ")" * 99_999
    )
    result = fast.read_runs(text)
    assert result is not None
    assert sorted(result.conditions.values(), key=lambda c: c[1])[-1] == (None, 50_001)
    got = parse_source(Source(text, "t.fcl"))
    [diag] = got.diagnostics
    assert diag.message == "rule 1: the condition nests 50001 levels deep (the limit is 100)"
    assert diag.span is not None and (diag.span.line, diag.span.column) == (6, 1)
    assert diag.code == "too-deep"


def test_every_condition_read_fast_on_generated_blocks(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(fast, "SUBSTITUTE_MIN", 0)
    for seed in range(300):
        assert_same(_document(random.Random(seed)))


def test_every_condition_read_fast_on_local_files(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(fast, "SUBSTITUTE_MIN", 0)
    for path in LOCAL:
        text = _read(path)
        if text is not None:
            assert_same(text, str(path))


@pytest.mark.extra("corpus")
def test_every_condition_read_fast_on_the_corpus(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(fast, "SUBSTITUTE_MIN", 0)
    for path in CORPUS:
        text = _read(path)
        if text is not None:
            got, want = both(text, str(path))
            assert got == want, path


POINTS = {
    "long": " ".join(f"({k / 100}, {k % 2})" for k in range(200)) + ";",
    "commas and comments": ", ".join(f"({k}, (* y *) 1)" for k in range(60)) + " // end\n;",
    "names": " ".join(f"(x{k}, {k % 2})" for k in range(60)) + ";",
    "spread over lines": "\n".join(f"( {k},\n 0 )" for k in range(60)) + "\n;",
    "no semicolon": " ".join(f"({k}, 1)" for k in range(60)),
    "huge number": " ".join(f"({k}, 1)" for k in range(60)) + " (1e999, 0);",
    "unclosed": " ".join(f"({k}, 1)" for k in range(60)) + " (3, 1;",
}


@pytest.mark.parametrize("name", sorted(POINTS))
def test_long_point_lists(name: str, substitute_min: int) -> None:
    points = POINTS[name]
    alone = HEAD.replace("TERM hi := (0, 0) (1, 1);", f"TERM hi := {points}")
    assert_same(alone)
    three = HEAD.replace(
        "TERM hi := (0, 0) (1, 1);", f"TERM hi := {points} TERM m := {points} TERM n := {points}"
    )
    assert_same(three + "RULE 1 : IF a IS hi THEN y IS lo;\n" + TAIL)
    if name == "long" and substitute_min:
        result = fast.read_runs(alone + TAIL)
        assert result is not None and len(result.points) == 1


# --------------------------------------------------------------------------- whole blocks

SEP = [" ", "\n", "\n\n", " (* between *) ", "\n// line\n", " /* a\n b */ ", "\t", "\r\n"]


def _sep(rng: random.Random) -> str:
    return rng.choice(SEP) if rng.random() < 0.4 else "\n"


def _small_term(rng: random.Random, k: int) -> str:
    mf = rng.choice(["(0, 1) (1, 0)", "0.5", "TRIAN 0 1 2", "trap 0 1 2 3", "(x, 0)", "gauss 1 2"])
    return f"TERM t{k} := {mf};"


def _block(rng: random.Random, k: int) -> str:
    kind = rng.choice(["FUZZIFY", "FUZZIFY", "DEFUZZIFY", "DEFUZZIFY", "RULEBLOCK", "VAR_OUTPUT", "VAR"])
    parts: list[str] = []
    if kind == "FUZZIFY":
        parts = [f"FUZZIFY v{k}"] + [_small_term(rng, i) for i in range(rng.randrange(0, 4))]
        if rng.random() < 0.3:
            parts.insert(rng.randrange(1, len(parts) + 1), "RANGE := (0 .. 10);")
    elif kind == "DEFUZZIFY":
        parts = [f"DEFUZZIFY w{k}"] + [_small_term(rng, i) for i in range(rng.randrange(0, 3))]
        extra = ["METHOD : COG;", "METHOD : cogs;", "DEFAULT := 0;", "DEFAULT := NC;", "ACCU : MAX;",
                 "RANGE (0, 1);", "METHOD : none;"]  # fmt: skip
        for item in rng.sample(extra, rng.randrange(0, 3)):
            parts.insert(rng.randrange(1, len(parts) + 1), item)
    elif kind == "RULEBLOCK":
        parts = [f"RULEBLOCK r{k}" if rng.random() < 0.8 else "RULEBLOCK"]
        parts += rng.sample(["AND : MIN;", "OR : MAX;", "ACT : PROD;", "ACCU : SUM;"], rng.randrange(0, 3))
        parts += [f"RULE {i} : IF a IS lo AND b IS t{i} THEN y IS hi;" for i in range(rng.randrange(0, 3))]
        rng.shuffle(parts[1:])
    else:
        parts = [kind] + [
            rng.choice([f"o{k}_{i} : REAL;", f"p{k}_{i}, q{k}_{i} : REAL;", f"i{k}_{i} : INT := 3;",
                        f"z{k}_{i} : REAL; RANGE(0 .. 1);", f"f{k}_{i} : BOOL := TRUE;"])
            for i in range(rng.randrange(0, 5))
        ]  # fmt: skip
    end = {"FUZZIFY": "END_FUZZIFY", "DEFUZZIFY": "END_DEFUZZIFY", "RULEBLOCK": "END_RULEBLOCK"}
    return " ".join(parts) + " " + end.get(kind, "END_VAR")


BLOCK_MISTAKES = [
    ("TERM t0 := (0, 1) (1, 0);", "TERM t0 := ;"),  # a bad TERM
    ("(0, 1) (1, 0);", "(0, 1) (1, 0),;"),  # a ',' after the last point
    ("RULE 1 :", "RULE END_RULEBLOCK"),  # a label lark reads: its block does not end there
    ("RULE 1 : IF a IS lo THEN y IS lo;", "RULE // 1 : IF a IS lo THEN y IS lo;\n"),
    ("END_FUZZIFY", ""),  # a missing END_FUZZIFY
    ("END_DEFUZZIFY", "END_FUZZIFY"),
    ("METHOD : COG;", "METHOD : NOPE;"),
    ("METHOD : COG;", "METHOD : COG"),
    ("DEFAULT := 0;", "DEFAULT = 0;"),
    ("RANGE := (0 .. 10);", "RANGE := (10 .. 0);"),
    ("RANGE := (0 .. 10);", "RANGE := (1 .. 1); RANGE (0 .. 2);"),
    ("AND : MIN;", "AND : MIN; AND : PROD;"),
    ("ACCU : MAX;", "ACCU : MAX; ACCU : MAX;"),
    ("TRIAN 0 1 2", "TRIAN 0 1"),
    ("0.5;", "1e999;"),
    (" : REAL;", " : REAL"),
    ("FUZZIFY v", "FUZZIFY rear v"),
    ("THEN y IS hi;", "THEN y IS ;"),
    ("END_VAR", "END_VAR END_VAR"),
    # between FUNCTION_BLOCKs (a run of blocks goes on into the next one)
    ("FUNCTION_BLOCK h", "FUNCTION_BLOCK h-1"),
    ("FUNCTION_BLOCK h", "FUNCTION_BLOCK"),
    ("FUNCTION_BLOCK h", "FUNCTION_BLOCK RULE"),
    ("FUNCTION_BLOCK h", "FUNCTION_BLOCK h;"),
    ("END_FUNCTION_BLOCK\nFUNCTION_BLOCK h", "FUNCTION_BLOCK h"),
    ("END_FUNCTION_BLOCK\nFUNCTION_BLOCK h", "END_FUNCTION_BLOCK (* c *) x FUNCTION_BLOCK h"),
    ("END_FUNCTION_BLOCK\n", "END_FUNCTION_BLOCK\nx"),
]


def _blocks_document(rng: random.Random) -> str:
    decls = "".join(
        f"{rng.choice(['a', 'b', 'c'])}{k} : REAL;{_sep(rng)}" for k in range(rng.randrange(0, 12))
    )
    blocks = [_block(rng, k) for k in range(rng.randrange(1, 14))]
    if rng.random() < 0.2:  # the same block twice
        i = rng.randrange(len(blocks))
        blocks.insert(i, blocks[i])
    body = "".join(b + _sep(rng) for b in blocks)
    text = (
        f"FUNCTION_BLOCK g\nVAR_INPUT a : REAL; b : REAL;\n{decls}END_VAR\nVAR_OUTPUT y : REAL; END_VAR\n"
        f"{body}END_FUNCTION_BLOCK\n"
    )
    for _ in range(rng.choice([0, 0, 1, 2])):
        text += "FUNCTION_BLOCK h\n" + "".join(b + _sep(rng) for b in blocks[::-1]) + "END_FUNCTION_BLOCK\n"
    if rng.random() < 0.4:
        old, new = rng.choice(BLOCK_MISTAKES)
        places = [i for i in range(len(text)) if text.startswith(old, i)]
        if places:
            i = rng.choice(places)
            text = text[:i] + new + text[i + len(old) :]
    if rng.random() < 0.2:  # the whole file on one line
        text = text.replace("// line\n", "(* line *)").replace("\r\n", " ").replace("\n", " ")
    return text


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 2**32 - 1))
def test_same_model_on_generated_runs_of_blocks(seed: int) -> None:
    assert_same(_blocks_document(random.Random(seed)))


def _many(block: str, n: int = 40) -> str:
    head = "FUNCTION_BLOCK f VAR_INPUT a, b : REAL; END_VAR VAR_OUTPUT y : REAL; END_VAR\n"
    return head + "".join(block.format(k=k) for k in range(n)) + "END_FUNCTION_BLOCK\n"


SMALL_BLOCKS = {
    "fuzzify": "FUZZIFY v{k} TERM lo := (0, 1) (1, 0); TERM hi := (0, 0) (1, 1); END_FUZZIFY\n",
    "defuzzify": "DEFUZZIFY w{k} TERM lo := 0; TERM hi := 1; METHOD : COGS; DEFAULT := 0; END_DEFUZZIFY\n",
    "ruleblocks": "RULEBLOCK r{k} AND : MIN; RULE 1 : IF a IS lo THEN y IS lo; END_RULEBLOCK\n",
    "var": "VAR_OUTPUT o{k} : REAL; p{k} : REAL := 1; END_VAR\n",
}


@pytest.mark.parametrize("name", sorted(SMALL_BLOCKS))
def test_fast_reader_takes_runs_of_small_blocks(name: str) -> None:
    text = _many(SMALL_BLOCKS[name])
    result = read_blocks(text)
    # the VAR_OUTPUT block and all the small blocks but the last (VAR_INPUT is the first)
    assert result is not None and len(result.blocks) == 40
    assert_same(text)
    assert_same(text.replace("\n", " "))  # on one line
    assert_same(text.replace("\n", "\n(* c *) // d\n"))  # comments between blocks
    # a mistake in a middle block: lark reads that block, with its place
    for old, new in [*BLOCK_MISTAKES, ("{k} ", "20 "), (" {k}", " AND")]:
        block = SMALL_BLOCKS[name]
        if old in block:
            broken = _many(block).replace(block.format(k=20), block.replace(old, new, 1).format(k=20))
            assert_same(broken)
            assert_same(_many(block, 3).replace(block.format(k=1), block.replace(old, new, 1).format(k=1)))


MUTATIONS = [
    "(",
    ")",
    ";",
    ":",
    ":=",
    ",",
    "-",
    "x",
    "1e999",
    "TERM",
    "RULE",
    "END_FUZZIFY",
    "END_VAR",
    "END_RULEBLOCK",
    "END_FUNCTION_BLOCK",
    "FUNCTION_BLOCK",
    "FUZZIFY",
    "VAR_INPUT",
    "(*",
    "*)",
    "//",
    "\n",
    "RANGE (0..1);",
    "METHOD : COG;",
    "DEFAULT := NC;",
    "OPTIONS",
    "END_OPTIONS",
]


@pytest.mark.parametrize("name", sorted(SMALL_BLOCKS))
def test_same_model_on_mutated_runs_of_blocks(name: str) -> None:
    """Tokens inserted and text deleted anywhere in a run of small blocks."""
    rng = random.Random(name)
    base = _many(SMALL_BLOCKS[name], 6) + _many(SMALL_BLOCKS[name], 4).replace(
        "FUNCTION_BLOCK f", "FUNCTION_BLOCK g"
    )
    for _ in range(150):
        text = base
        for _ in range(rng.choice([1, 1, 2])):
            p = rng.randrange(len(text))
            if rng.random() < 0.3:
                text = text[:p] + text[p + rng.randrange(1, 10) :]
            else:
                text = text[:p] + " " + rng.choice(MUTATIONS) + " " * rng.randrange(2) + text[p:]
        got, want = both(text)
        assert got == want, text


def test_runs_of_blocks_go_on_into_the_next_function_block() -> None:
    fb = (
        "FUNCTION_BLOCK f{k} VAR_INPUT a : REAL; END_VAR VAR_OUTPUT y : REAL; END_VAR\n"
        "FUZZIFY a TERM lo := 0; END_FUZZIFY DEFUZZIFY y TERM lo := 0; END_DEFUZZIFY\n"
        "RULEBLOCK r RULE 1 : IF a IS lo THEN y IS lo; END_RULEBLOCK END_FUNCTION_BLOCK\n"
    )
    text = "".join(fb.format(k=k) for k in range(10))
    result = read_blocks(text)
    assert result is not None and len(result.blocks) == 48  # all but the first and the last
    assert_same(text)
    assert_same(text.replace("\n", " "))
    for old, new in [
        ("FUNCTION_BLOCK f5", "FUNCTION_BLOCK f-5"),
        ("FUNCTION_BLOCK f5", "FUNCTION_BLOCK"),
        ("FUNCTION_BLOCK f5", "FUNCTION_BLOCK (* c *) f5 // d\n"),
        ("END_FUNCTION_BLOCK\nFUNCTION_BLOCK f5", "FUNCTION_BLOCK f5"),
        ("END_FUNCTION_BLOCK\nFUNCTION_BLOCK f5", "END_FUNCTION_BLOCK END_FUNCTION_BLOCK"),
        ("FUNCTION_BLOCK f5", "FUNCTION_BLOCK f4"),  # the same name twice
    ]:
        assert_same(text.replace(old, new))
    assert_same(text + "trailing text")


def test_fast_reader_takes_runs_of_declarations() -> None:
    decls = "".join(f"v{k} : REAL;\n" for k in range(50)) + "x, y2 : REAL := 2; RANGE (0 .. 3);\n"
    text = f"FUNCTION_BLOCK f VAR_INPUT\n{decls}z : BOOL := TRUE;\nEND_VAR END_FUNCTION_BLOCK\n"
    result = read_blocks(text)
    assert result is not None and len(result.decls) == 50
    assert_same(text)
    assert_same(text.replace("v25 : REAL;", "v25 : REAL"))
    assert_same(text.replace("v25 : REAL;", "v25 (* c *) : REAL; // d"))
    assert_same(text.replace("v25 : REAL;", "v25 : REAL; v25 : REAL;"))
    assert_same(text.replace("v25 : REAL;", "v 25 : REAL;"))


def test_declarations_after_a_run_of_blocks() -> None:
    """A VAR block ending a run of blocks: lark reads it, the fast reader its declarations;
    the comments of both runs kept."""
    decls = "".join(f"v{k} : REAL; (* d{k} *)\n" for k in range(20))
    block = SMALL_BLOCKS["fuzzify"].replace("END_FUZZIFY", "END_FUZZIFY (* c{k} *)")
    text = _many(block, 6).replace("END_FUNCTION_BLOCK", f"VAR_INPUT {decls}END_VAR END_FUNCTION_BLOCK")
    result = read_blocks(text)
    assert result is not None and len(result.blocks) == 7 and len(result.decls) == 18
    assert len(result.comments) == 24
    assert_same(text)
