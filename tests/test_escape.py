"""The escaping functions of :mod:`fuzzyctl.escape`, checked against the languages' own
readers: Python's tokenizer and ``ast``, the C preprocessor (``cc -E``), the XML parser of
the standard library, and a Structured Text comment scanner that follows IEC 61131-3."""

from __future__ import annotations

import ast
import re
import shutil
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from fuzzyctl.codegen import CodegenError
from fuzzyctl.escape import (
    MAX_COMMENT,
    c_comment,
    c_ident,
    c_string,
    py_ident,
    py_str,
    st_comment,
    st_ident,
    st_string,
    xml_attr,
    xml_comment,
    xml_text,
)

HOSTILE = [
    '1 */ { extern int system(const char *); system("touch pwned"); } /*',
    "*/ PWNED(); /*",
    "*) PWNED := 1; (*",
    "(*) PWNED (*)",
    "x\nPWNED();\n",
    "x\\\nPWNED();",
    "x\\",
    "??/\nPWNED();",
    "*??/\n/ PWNED();",
    "x\" PWNED ' $",
    "a\x00PWNED\x7f\x1b[2J",
    "]]> <PWNED/> <!-- --> &amp;",
    "${PWNED} %s {0}",
    "a\u2028PWNED\u2029b\u202eevil\u2066",
    "// PWNED\n",
    "Temperatur über 30 °C",
    "\ud800 lone surrogate",
    "P" * 100_000,
]


def _st_strip(text: str) -> str:
    """Structured Text without its ``(* *)`` comments (not nested, as IEC says)."""
    return re.sub(r"\(\*.*?\*\)", " ", text, flags=re.S)


@pytest.mark.parametrize("text", HOSTILE)
def test_comment_bodies_are_one_inert_line(text: str) -> None:
    for body in (c_comment(text), st_comment(text)):
        assert "\n" not in body and "\r" not in body
        assert all(" " <= ch <= "~" for ch in body)
        for opener in ("*/", "/*", "(*", "*)", "??"):
            assert opener not in body
        assert len(body) <= MAX_COMMENT
    # wrapped in its comment, it leaves nothing behind as ST code
    assert _st_strip(f"A := 1; (* {st_comment(text)} *) B := 2;").split() == [
        "A",
        ":=",
        "1;",
        "B",
        ":=",
        "2;",
    ]


def test_comment_keeps_what_is_readable() -> None:
    assert c_comment("RULE 7 (block velocity)") == "RULE 7 (block velocity)"
    assert st_comment("über") == "<U+00FC>ber"
    assert c_comment("a*/b") == "a* /b"
    assert c_comment("x" * 10_000).endswith("...")


def _cc() -> str:
    cc = shutil.which("cc")
    if cc is None:
        pytest.fail("the escaping tests need the system compiler 'cc'")
    return cc


def test_c_comments_and_strings_survive_the_preprocessor(tmp_path: Path) -> None:
    """One C file with every hostile text as a comment and as a string literal: the
    preprocessor (trigraphs and line splices on, as -std=c99 has them) sees exactly the
    declarations we wrote, and each string holds the text's UTF-8 bytes."""
    lines = ["#include <string.h>", "int n_ok = 0;"]
    checks = []
    for k, text in enumerate(HOSTILE):
        lines.append(f"/* {c_comment(text)} */ static const char s{k}[] = {c_string(text)};")
        raw = text.encode("utf-8", "surrogatepass")
        checks.append(
            f"n_ok += sizeof(s{k}) == {len(raw) + 1} && memcmp(s{k}, {c_string(text)}, {len(raw)}) == 0;"
        )
    src = tmp_path / "t.c"
    src.write_text(
        "\n".join(lines)
        + "\nint main(void)\n{\n"
        + "\n".join(checks)
        + f"\nreturn n_ok == {len(HOSTILE)} ? 0 : 1;\n}}\n"
    )
    pre = subprocess.run([_cc(), "-std=c99", "-E", "-P", str(src)], capture_output=True, text=True)
    assert pre.returncode == 0, pre.stderr[-2000:]
    code = re.sub(r'"(?:\\.|[^"\\\n])*"', '""', pre.stdout)  # string literals emptied
    assert "PWNED" not in code and "system" not in code and "touch" not in code
    assert code.count(" static const char s") == len(HOSTILE)
    exe = tmp_path / "t"
    res = subprocess.run(
        # C99 promises 4095 characters in a literal: the 100,000 of the flood are a gcc extension
        [
            _cc(),
            "-std=c99",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-pedantic",
            "-Wno-overlength-strings",
            "-o",
            str(exe),
            str(src),
        ],
        capture_output=True,
        text=True,
    )
    assert res.returncode == 0, res.stderr[-2000:]
    assert subprocess.run([str(exe)]).returncode == 0


@given(st.text())
def test_py_str_is_a_literal_of_the_same_text(text: str) -> None:
    lit = py_str(text)
    node = ast.parse(lit, mode="eval").body
    assert isinstance(node, ast.Constant) and node.value == text


@pytest.mark.parametrize("text", HOSTILE)
def test_st_string_decodes_back(text: str) -> None:
    lit = st_string(text)
    assert lit[0] == lit[-1] == "'" and "\n" not in lit
    body = lit[1:-1]
    assert re.fullmatch(r"(?:[ -#%-&(-~]|\$\$|\$'|\$[NRTP]|\$[0-9A-F]{2})*", body), body
    named = {"$": "$", "'": "'", "N": "\n", "R": "\r", "T": "\t", "P": "\f"}
    decoded = re.sub(r"\$([0-9A-F]{2}|.)", lambda m: named.get(m[1]) or chr(int(m[1], 16)), body)
    expected = "".join(ch if ord(ch) < 256 else "?" for ch in text)
    assert decoded == expected


@pytest.mark.parametrize("text", HOSTILE)
def test_xml_text_attribute_and_comment_parse_back(text: str) -> None:
    doc = f"<r a=\"{xml_attr(text)}\" b='{xml_attr(text)}'><!--{xml_comment(text)}-->{xml_text(text)}</r>"
    root = ET.fromstring(doc)
    valid = re.sub("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]", "\ufffd", text)
    assert root.get("a") == valid and root.get("b") == valid
    assert root.text == valid
    assert len(root) == 0  # no element was injected


@pytest.mark.parametrize(
    ("check", "name"),
    [
        (c_ident, "a b"),
        (c_ident, "x;system"),
        (c_ident, "int"),
        (c_ident, "M_PI"),
        (c_ident, "__x"),
        (c_ident, "_X"),
        (c_ident, "é"),
        (c_ident, "a" * 64),
        (st_ident, "END_VAR"),
        (st_ident, "a__b"),
        (st_ident, "a" * 25),
        (st_ident, "x(*"),
        (py_ident, "import"),
        (py_ident, "a.b"),
    ],
)
def test_identifiers_are_refused_not_rewritten(check: object, name: str) -> None:
    with pytest.raises(CodegenError) as info:
        check(name, "variable")  # type: ignore[operator]
    assert "variable" in str(info.value)


def test_plain_identifiers_pass_unchanged() -> None:
    assert c_ident("Temp_1", "variable") == "Temp_1"
    assert st_ident("Temp_1", "variable") == "Temp_1"
    assert py_ident("Temp_1", "variable") == "Temp_1"


def test_refusal_messages_do_not_echo_a_flood() -> None:
    with pytest.raises(CodegenError) as info:
        c_ident("x\n" * 10_000, "variable")
    assert len(str(info.value)) < 200 and "\n" not in str(info.value)
