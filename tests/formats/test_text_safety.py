"""A file runs what it says (issue 25, point 3): no comment, description or free-text name of
any format becomes syntax of the file a writer produces.

Hostile text (comment terminators of FCL, C and ST, whole rules and function blocks, every
kind of line end, NUL, the BOM, lone surrogates, 20,000 characters) is put in every text
field of every reader - comments in every position of an FCL file, FPL comments, FLL
descriptions, JSON comments on every element, names where a format takes free text - and
the model is written by every writer and read back.  The oracle is the same system with
benign text in that field, taken along the same path: the hostile one must evaluate to the
same numbers with the same number of blocks and rules (or be refused by the writer with a
diagnostic, for a name).  The escaping functions are checked with hypothesis against the
FCL readers themselves (lark and the fast reader), the C compiler, tree-sitter's ST grammar
and lxml; the CLI and the studio's Import -> Save go through the same writers."""

from __future__ import annotations

import base64
import json
import re
import shutil
import subprocess
from collections.abc import Callable
from dataclasses import replace
from functools import cache
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import fuzzyctl
from fuzzyctl import formats
from fuzzyctl.cli.app import main
from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.escape import fcl_comment, fcl_options, json_text, one_line, visible_text
from fuzzyctl.fcl import load_text, write
from fuzzyctl.fcl.parser import parse_source
from fuzzyctl.fcl.source import Source
from fuzzyctl.formats.json.writer import dumps as json_dumps
from fuzzyctl.model import Document, FunctionBlock, OptionsBlock
from tests.codegen import hostile as H
from tests.fcl.strategies import documents as random_documents

#: The codegen injection strings, and what smuggles syntax into the interchange formats.
HOSTILE: dict[str, str] = {
    **H.HOSTILE,
    "fcl-rule": "*) RULE 99 : IF QQinQQ IS zero THEN QQoutQQ IS big; (*",
    "fcl-rule-nested": "(* reviewed *) RULE 99 : IF rate IS pos THEN QQoutQQ IS big; (* ok *)",
    "fcl-block": (
        "*) END_RULEBLOCK END_FUNCTION_BLOCK FUNCTION_BLOCK evil VAR_OUTPUT y : REAL; END_VAR "
        "DEFUZZIFY y TERM t := 100; METHOD : CoGS; DEFAULT := 100; END_DEFUZZIFY "
        "END_FUNCTION_BLOCK (*"
    ),
    "fcl-default": "(* steering *) DEFAULT := 0.9; (* see manual *)",
    "c-rule": "*/ RULE 97 : IF rate IS pos THEN QQoutQQ IS big; /*",
    "line-ends": "a\rRULE 95 : IF rate IS pos THEN QQoutQQ IS big;\x0bb\x0cc\x1cd\x85e\u2028f\u2029g",
    "controls": "\ufeffa\x00b\x07c\x7fd\u200be\u202ef\u2066g",
    "options": "END_OPTIONS END_FUNCTION_BLOCK FUNCTION_BLOCK evil END_FUNCTION_BLOCK OPTIONS",
    "fll-lines": "x\nRuleBlock: evil\n  rule: if rate is pos then QQoutQQ is big\n",
    "fis-lines": "x'\n[Rules]\n1 1, 3 (1) : 1\n",
    "fpl-lines": "x */ RULE evil IF (rate is pos) THEN QQoutQQ = big END /* ",
    "xml": "]]></ST><ST><![CDATA[ PWNED := 1; <!-- ",
}
#: Only JSON (and XFUZ's JSON) can carry a lone surrogate.
JSON_ONLY = {"surrogates": "a\ud800b\udfffc"}

POINTS = ((-3.0, -0.7), (-1.2, 0.4), (0.3, 0.1), (1.5, 0.9))
WRITERS = [f.name for f in formats.available() if f.write is not None]
#: The fields of each reader's template that hold free text (comments, descriptions, and the
#: names the format quotes or writes to the end of the line).
FREE = {"QQcmtQQ", "QQvcmtQQ", "QQlabelQQ", "QQblockQQ", "comment", "all-comments"}
FIELDS = {
    "fcl": ["QQcmtQQ", "QQvcmtQQ", "QQfbQQ", "QQlabelQQ", "QQblockQQ"],
    "fis": ["QQfbQQ", "QQinQQ", "QQtermQQ"],
    "fll": ["QQcmtQQ", "QQvcmtQQ", "QQfbQQ", "QQblockQQ", "QQinQQ", "QQtermQQ"],
    "fpl": ["QQcmtQQ", "QQfbQQ", "QQlabelQQ", "QQblockQQ"],
    "json": ["all-comments", "QQfbQQ", "QQinQQ", "QQtermQQ", "QQotermQQ", "QQlabelQQ", "QQblockQQ"],
    "xfuz": ["comment"],
}


# --------------------------------------------------------------------------- the escapers

_FCL_COMMENT = re.compile(r"\(\*.*?\*\)|/\*.*?\*/|//[^\r\n]*", re.S)  # fcl.lark's COMMENT_*
_LINE_BREAKS = "\r\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029"  # str.splitlines' breaks but \n
any_text = st.text(st.characters(codec=None, exclude_categories=()), max_size=60) | st.sampled_from(
    [*HOSTILE.values(), *JSON_ONLY.values()]
)


def _with_comment(comment: str) -> str:
    """A small FCL block with ``comment`` written before a rule, after a term and at the end."""
    return (
        "FUNCTION_BLOCK f\nVAR_INPUT x : REAL; END_VAR\nVAR_OUTPUT y : REAL; END_VAR\n"
        "FUZZIFY x TERM lo := (0, 1) (1, 0); TERM hi := (0, 0) (1, 1); " + comment + "\nEND_FUZZIFY\n"
        "DEFUZZIFY y TERM a := 0; TERM b := 10; METHOD : CoGS; DEFAULT := 0; END_DEFUZZIFY\n"
        "RULEBLOCK r AND : MIN;\n" + comment + "\nRULE 1 : IF x IS lo THEN y IS a;\n"
        "RULE 2 : IF x IS hi THEN y IS b;\nEND_RULEBLOCK\nEND_FUNCTION_BLOCK\n" + comment + "\n"
    )


def _comments(doc: Document) -> list[str]:
    """Every comment text the model holds, in no particular order (also those placed around
    an element's keywords, where the model has ``placed_comments``)."""

    def of(element: Any) -> list[str]:
        return [*element.comments, *(text for _, text in getattr(element, "placed_comments", ()))]

    out = of(doc)
    for fb in doc.blocks:
        out.extend(of(fb))
        for elements in (fb.variables, fb.fuzzify, fb.defuzzify, fb.rule_blocks, fb.options):
            for e in elements:
                out.extend(of(e) if hasattr(e, "comments") else [])
                for inner in getattr(e, "terms", ()) or getattr(e, "rules", ()):
                    out.extend(of(inner))
    return sorted(out)


@given(any_text)
def test_fcl_comment_is_one_comment_for_both_readers(text: str) -> None:
    comment = fcl_comment(text)
    comment.encode("utf-8")  # a file can hold it
    assert not any(ch in _LINE_BREAKS for ch in comment)
    found = _FCL_COMMENT.match(comment)
    assert found is not None and found.end() == len(comment), comment
    if comment != text.replace("\r\n", "\n").replace("\r", "\n"):  # not kept as the file had it
        assert comment.startswith("(* ") and not re.search(r"\(\*|\*\)", comment[2:-2])  # nor nested
    for fast in (False, True):  # lark alone, and the fast reader with lark
        plain = parse_source(Source(_with_comment("")), fast=fast).document
        doc = parse_source(Source(_with_comment(comment)), fast=fast).document
        assert doc is not None and doc == plain
        assert _comments(doc) == [comment] * 3


@given(st.text(st.characters(min_codepoint=0x20, max_codepoint=0x2FF), max_size=40))
def test_fcl_comment_keeps_plain_text_readable(text: str) -> None:
    """Text that cannot end or open a comment is written as it is, between ``(* *)``."""
    if re.search(r"[(/]\*|\*[)/]|^\s*//|^\(\*.*\*\)$|^/\*.*\*/$|[\x7f-\x9f\u00ad]", text, re.S):
        return
    assert fcl_comment(text) == f"(* {text} *)"


def test_fcl_comment_keeps_fcl_comments_as_the_file_wrote_them() -> None:
    assert fcl_comment("(* a\n   b *)") == "(* a\n   b *)"
    assert fcl_comment("/* see (*) */") == "/* see (*) */"  # FCL's own: one C comment
    assert fcl_comment("// a *) b") == "// a *) b"
    assert fcl_comment("/* a *)\r\n b */") == "/* a *)\n b */"  # a CRLF file's comment
    assert fcl_comment("/* a *)\x0c b */") == "(* a * )<U+000C> b *)"
    assert fcl_comment("// line") == "(* line *)"
    assert fcl_comment("a\r\nb") == "(* a\nb *)"
    assert fcl_comment("*) RULE 9 (*") == "(* * ) RULE 9 ( * *)"
    assert fcl_comment("(* a *) b (* c *)") == "(* a * ) b ( * c *)"
    assert fcl_comment("nul\x00 bom\ufeff ls\u2028 lone\ud800") == (
        "(* nul<U+0000> bom<U+FEFF> ls<U+2028> lone<U+D800> *)"
    )


@given(any_text)
def test_one_line_stays_on_its_line(text: str) -> None:
    line = one_line(text)
    line.encode("utf-8")
    assert len(line.splitlines()) <= 1 and "\n" not in line
    if text.isprintable() and text.isascii():
        assert line == text


@given(any_text)
def test_options_text_cannot_end_its_block(text: str) -> None:
    body = fcl_options(text)
    body.encode("utf-8")
    assert not re.search(r"\bEND_OPTIONS?\b", body, re.I)
    fb = fuzzyctl.load(_with_comment(""), format="fcl").blocks[0]
    written = write(replace(fb, options=(OptionsBlock(text, "OPTIONS"),)))
    again = fuzzyctl.load(written, format="fcl").blocks[0]
    assert len(again.options) <= 1 and replace(again, options=()) == replace(fb, options=())


@given(any_text)
def test_json_text_reads_back_the_same(text: str) -> None:
    written = json_text(json.dumps(text, ensure_ascii=False))
    written.encode("utf-8")
    assert json.loads(written) == text
    shown = visible_text(text)
    shown.encode("utf-8")
    assert not any(ch in _LINE_BREAKS for ch in shown)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_documents, any_text)
def test_random_models_with_hostile_comments_round_trip(doc: Document, text: str) -> None:
    """Random valid models (tests/fcl/strategies.py) with ``text`` as the comment of every
    element: the FCL read back is the same model, and holds exactly one comment per comment."""
    hostile = _all_comments(doc, text)
    written = write(hostile)
    assert load_text(written).document == doc, written[:2000]
    if not any(fb.options for fb in doc.blocks):  # OPTIONS text may look like a comment
        assert len(_FCL_COMMENT.findall(written)) == len(_comments(hostile))


# --------------------------------------------------------------------------- every reader, every writer


@cache
def _benign_fcl() -> Document:
    return fuzzyctl.load(H.fill(H.FCL, None, ""), format="fcl")


def _all_comments(doc: Document, text: str) -> Document:
    """``doc`` with ``text`` as the comment of every element that holds comments."""
    c = (text,)

    def block(fb: FunctionBlock) -> FunctionBlock:
        return replace(
            fb,
            comments=c,
            variables=tuple(replace(v, comments=c) for v in fb.variables),
            fuzzify=tuple(
                replace(b, comments=c, terms=tuple(replace(t, comments=c) for t in b.terms))
                for b in fb.fuzzify
            ),
            defuzzify=tuple(
                replace(b, comments=c, terms=tuple(replace(t, comments=c) for t in b.terms))
                for b in fb.defuzzify
            ),
            rule_blocks=tuple(
                replace(rb, comments=c, rules=tuple(replace(r, comments=c) for r in rb.rules))
                for rb in fb.rule_blocks
            ),
        )

    return replace(doc, blocks=tuple(block(fb) for fb in doc.blocks), comments=c)


@cache
def _xfuz_base() -> str:
    text, _ = formats.convert(_benign_fcl(), "xfuz", lossy=True)
    return text


def _source(fmt: str, field: str | None, text: str) -> str:
    if fmt == "json":
        if field == "all-comments":
            return json_dumps(_all_comments(_benign_fcl(), text))
        return H.json_model(_benign_fcl(), field, text)
    if fmt == "xfuz":
        data = json.loads(_xfuz_base())
        if field == "comment":
            data["comment"] = text
        return json.dumps(data)
    source = H.fill(H.TEMPLATES[fmt], field, text)
    if fmt == "fll" and field == "QQvcmtQQ":  # a description under every variable too
        source = re.sub(r"^((?:In|Out)putVariable: .*)$", r"\1\n  description: QQvcmtQQ", source, flags=re.M)
        source = source.replace("QQvcmtQQ", text)
    return source


def _numbers(doc: Document) -> tuple[Any, ...]:
    """Blocks, rules and the outputs at POINTS (inputs in declaration order), or the error."""
    rules = sum(len(rb.rules) for fb in doc.blocks for rb in fb.rule_blocks)
    try:
        ctl = fuzzyctl.compile(doc, backend="python")
        values = tuple(
            tuple(round(v, 9) for v in ctl.evaluate(dict(zip(ctl.inputs, p, strict=False))).values())
            for p in POINTS
        )
    except FuzzyctlError as exc:
        values = (type(exc).__name__,)
    return (len(doc.blocks), rules, values)


def _path(doc: Document, writer: str) -> tuple[Any, ...]:
    """What ``doc`` written by ``writer`` and read back computes; a refusal to write, or a
    file the reader cannot read back, as a tagged outcome."""
    try:
        text, _ = formats.convert(doc, writer, lossy=True)
    except FuzzyctlError:
        return ("refused",)
    text.encode("utf-8")  # a file can hold it
    try:
        again = formats.read_text(text, writer).document
    except FuzzyctlError as exc:
        return ("unreadable", str(exc)[:300])
    return _numbers(again)


@cache
def _benign(fmt: str, field: str, writer: str) -> tuple[Any, ...]:
    doc = formats.read_text(_source(fmt, field, BENIGN_TEXT.get(field, "benign")), fmt).document
    return _path(doc, writer)


BENIGN_TEXT = {"QQcmtQQ": "a comment", "QQvcmtQQ": "a note"}


def _cases() -> list[Any]:
    return [
        pytest.param(fmt, field, id=f"{fmt}-{field.strip('Q')}") for fmt, fs in FIELDS.items() for field in fs
    ]


@pytest.mark.parametrize(("fmt", "field"), _cases())
def test_hostile_text_converts_to_what_the_benign_system_computes(fmt: str, field: str) -> None:
    benign_doc = formats.read_text(_source(fmt, field, BENIGN_TEXT.get(field, "benign")), fmt).document
    benign_numbers = _numbers(benign_doc)
    strings = {**HOSTILE, **(JSON_ONLY if fmt in ("json", "xfuz") else {})}
    compared = 0
    for key, text in strings.items():
        if field in ("QQfbQQ", "QQinQQ", "QQtermQQ", "QQotermQQ") and key == "flood":
            continue  # a 20,000-character name: the readers' name limits, not this test's
        try:
            doc = formats.read_text(_source(fmt, field, text), fmt).document
        except FuzzyctlError:
            assert field not in FREE or fmt not in ("json", "xfuz"), f"{fmt} refused {key} in {field}"
            continue  # the reader refused the file (the text broke its own syntax)
        if _numbers(doc) != benign_numbers:
            # the source itself says something else (an FPL comment closed by the text): not
            # a writer's doing; free text of JSON must never get here
            assert fmt not in ("json", "xfuz"), f"{fmt} {field} {key}: read differently"
            continue
        for writer in WRITERS:
            got, want = _path(doc, writer), _benign(fmt, field, writer)
            if got == ("refused",) and field not in FREE:
                continue  # a name the writer cannot write: refused with a diagnostic
            assert got == want, f"{fmt} {field} {key} -> {writer}: {got} != {want}"
            compared += 1
    if fmt in ("json", "xfuz"):  # free text there: every string read, every path compared
        assert compared >= len(WRITERS) * (len(strings) - 1)


def test_hostile_comments_in_every_position_of_an_fcl_file() -> None:
    """Each hostile string that can be an FCL comment (as ``(* *)``, ``/* */`` or ``//``)
    after every line of the template: fmt writes a file that reads back as the same model."""
    lines = H.fill(H.FCL, None, "").splitlines()
    plain = fuzzyctl.load("\n".join(lines), format="fcl")
    tried = 0
    covered: set[int] = set()
    for key, text in HOSTILE.items():
        if key == "flood":
            continue  # the length is tested elsewhere; here it would only cost time
        forms = []
        if "*)" not in text:
            forms.append(f"(*{text}*)")
        if "*/" not in text:
            forms.append(f"/*{text}*/")
        if not any(ch in text for ch in "\r\n"):
            forms.append(f"//{text}")
        for form in forms:
            tried += 1
            for at in range(1 + tried % 3, len(lines), 3):  # every line, over three forms
                covered.add(at)
                source = "\n".join([*lines[:at], form, *lines[at:]])
                try:
                    doc = fuzzyctl.load(source, format="fcl")
                except FuzzyctlError:
                    continue  # e.g. a NUL the reader refuses
                assert doc == plain
                again = fuzzyctl.load(write(doc), format="fcl")
                assert again == plain, (form[:60], at)  # equal models compute the same
    assert tried > 50 and covered == set(range(1, len(lines)))


# --------------------------------------------------------------------------- CLI and studio


def _smuggling_json() -> str:
    """The tank-like template as JSON with the reproducer's comments: an extra rule in one, a
    whole function block placed first in another."""
    doc = _all_comments(_benign_fcl(), HOSTILE["fcl-rule"])
    doc = replace(doc, blocks=(replace(doc.blocks[0], comments=(HOSTILE["fcl-block"],)),))
    return json_dumps(doc)


def test_cli_convert_writes_an_fcl_that_runs_what_the_json_says(tmp_path: Path) -> None:
    src = tmp_path / "evil.json"
    src.write_text(_smuggling_json(), encoding="utf-8")
    assert main(["convert", str(src), str(tmp_path / "evil.fcl")]) == 0
    assert main(["convert", str(src), str(tmp_path / "again.json")]) == 0
    written = fuzzyctl.load(tmp_path / "evil.fcl")
    assert written == fuzzyctl.load(src) and _numbers(written) == _numbers(fuzzyctl.load(src))
    text = (tmp_path / "evil.fcl").read_text(encoding="utf-8")
    assert text.count("FUNCTION_BLOCK evil") == 1  # still there, inside a comment
    assert len(_FCL_COMMENT.findall(text)) == len(_comments(fuzzyctl.load(src)))  # each one comment


def test_cli_convert_of_a_lone_surrogate_is_no_internal_error(tmp_path: Path) -> None:
    src = tmp_path / "s.json"
    src.write_text(json_dumps(_all_comments(_benign_fcl(), JSON_ONLY["surrogates"])), encoding="utf-8")
    for out in ("s.fcl", "s2.json"):
        assert main(["convert", str(src), str(tmp_path / out)]) == 0
    assert fuzzyctl.load(tmp_path / "s2.json") == fuzzyctl.load(src)
    assert "<U+D800>" in (tmp_path / "s.fcl").read_text(encoding="utf-8")


def test_words_that_are_not_words_are_refused() -> None:
    data = json.loads(H.json_model(_benign_fcl(), None, ""))
    evil = "MIN; END_RULEBLOCK END_FUNCTION_BLOCK FUNCTION_BLOCK evil END_FUNCTION_BLOCK (*"
    setters: list[Callable[[dict[str, Any]], None]] = [
        lambda b: b["rule_blocks"][0].__setitem__("and_op", evil),
        lambda b: b["defuzzify"][0].__setitem__("method", evil),
        lambda b: b["variables"][0].__setitem__("data_type", "REAL; END_VAR VAR_INPUT z : REAL"),
        lambda b: b["variables"][0].__setitem__("initial", {"text": "1; END_VAR VAR_INPUT z : REAL"}),
        lambda b: b["rule_blocks"][0]["rules"][1]["condition"].__setitem__("hedges", [evil]),
        lambda b: b["rule_blocks"][0]["rules"][1]["conclusions"][0].__setitem__("term", evil),
        lambda b: b.__setitem__("options", [{"keyword": evil, "text": ""}]),
    ]
    setters += [
        lambda b: b["rule_blocks"][0].__setitem__("or_op", evil),
        lambda b: b["rule_blocks"][0].__setitem__("act", evil),
        lambda b: b["rule_blocks"][0].__setitem__("accu", evil),
        lambda b: b["defuzzify"][0].__setitem__("accu", evil),
    ]
    for setter in setters:
        bad = json.loads(json.dumps(data))
        setter(bad["blocks"][0])
        doc = formats.read_text(json.dumps(bad), "json").document
        with pytest.raises(FuzzyctlError, match="cannot be written in FCL"):
            formats.convert(doc, "fcl", lossy=True)
        for writer in WRITERS:  # the others refuse it, drop it, or write it inert: no crash
            try:
                text, _ = formats.convert(doc, writer, lossy=True)
            except FuzzyctlError:
                continue
            again = formats.read_text(text, writer).document
            assert len(again.blocks) == 1 and (writer == "json" or evil not in text), writer


def test_studio_import_then_save_runs_what_the_json_says(tmp_path: Path) -> None:
    from fastapi.testclient import TestClient

    from fuzzyctl.studio import create_app

    root = tmp_path / "project"
    root.mkdir()
    token = "text-safety-test-token-0123456789"
    client = TestClient(
        create_app(root, token=token),
        base_url="http://127.0.0.1:8770",
        headers={"Authorization": f"Bearer {token}"},
    )
    raw = _smuggling_json().encode()
    r = client.post(
        "/api/import", json={"filename": "evil.json", "data_base64": base64.b64encode(raw).decode()}
    )
    assert r.status_code == 200, r.text
    imported = r.json()
    assert fuzzyctl.load(imported["text"], format="fcl") == _benign_fcl()
    r = client.post("/api/save", json={"path": "evil.fcl", "document": imported["document"]})
    assert r.status_code == 200, r.text
    saved = fuzzyctl.load(root / "evil.fcl")
    assert len(saved.blocks) == 1 and _numbers(saved) == _numbers(_benign_fcl())
    assert "FUNCTION_BLOCK evil" in (root / "evil.fcl").read_text(encoding="utf-8")  # as a comment


# --------------------------------------------------------------------------- generated code


def test_generated_code_with_hostile_comments_is_still_one_block(tmp_path: Path) -> None:
    from lxml import etree

    from fuzzyctl.codegen import generate_c, generate_st
    from fuzzyctl.codegen.plcopen import generate_plcopen
    from tests.codegen.test_st import tree_sitter_errors

    cc = shutil.which("cc")
    assert cc, "the system C compiler 'cc' checks the generated C"
    for key, text in HOSTILE.items():
        data = json.loads(json_dumps(_all_comments(_benign_fcl(), text)))
        for k, rule in enumerate(data["blocks"][0]["rule_blocks"][0]["rules"]):
            rule["label"] = f"{text} {k}"  # labels are free text in JSON and reach the comments
        doc = formats.read_text(json.dumps(data), "json").document
        files = generate_c(doc, testbench=3)
        for name, source in files.items():
            (tmp_path / name).write_text(source, encoding="utf-8")
        for name in files:
            if name.endswith(".c"):
                res = subprocess.run(
                    [cc, "-std=c99", "-Wall", "-Werror", "-fsyntax-only", str(tmp_path / name)],
                    capture_output=True,
                    text=True,
                )
                assert res.returncode == 0, (key, res.stderr[:2000])
        st_text = generate_st(doc, testbench=3)
        assert tree_sitter_errors(st_text) == [], key
        assert len(re.findall(r"^FUNCTION_BLOCK\b", st_text, re.M)) == 1, key
        xml = generate_plcopen(doc)
        root = etree.fromstring(xml.encode("utf-8"))
        pous = root.findall(".//{*}pou")
        assert len(pous) == 1, key


def test_fpl_comments_are_written_once() -> None:
    """The FPL reader put its comments on the block and on the document: FCL had them twice
    (the reproducer's smuggled block was 'defined twice')."""
    doc = formats.read_text(H.fill(H.FPL, "QQcmtQQ", "one note"), "fpl").document
    text, _ = formats.convert(doc, "fcl", lossy=True)
    assert _FCL_COMMENT.findall(text) == ["(* one note *)"]
