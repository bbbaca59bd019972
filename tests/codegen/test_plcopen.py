"""``codegen --lang plcopen``: PLCopen TC6 XML 2.01 that PLCopen's own schema accepts (lxml,
``../shared/tools/plcopen/tc6_xml_v201.xsd``) and that holds exactly the Structured Text of
``--lang st``: the body is the ST body character for character, and the interface, read back
from the XML by this test and printed as ST declarations, is the ST's declaration part.  Hostile
model text gives well-formed, valid XML with the same element structure as the plain system
(nothing injected), and the text stays inert for an ST reader too."""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Iterator
from functools import cache
from pathlib import Path

import pytest
from lxml import etree

import fuzzyctl
from fuzzyctl.cli.app import main
from fuzzyctl.codegen import CodegenError, generate_plcopen, generate_st, lower_block
from fuzzyctl.codegen.api import DIALECTS
from fuzzyctl.codegen.plcopen import render_plcopen
from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.ir.programs.plc_block import build_program
from fuzzyctl.ir.render.st import STParts, st_parts
from fuzzyctl.model import Document
from tests.codegen import hostile as H
from tests.conftest import EXAMPLES, shared_path

TC6 = "http://www.plcopen.org/xml/tc6_0201"
XHTML = "http://www.w3.org/1999/xhtml"
NS = {"p": TC6, "x": XHTML}
#: Dialects PLCopen XML is written for (scl is refused: TIA Portal does not import it).
XML_DIALECTS = [d for d in DIALECTS if d != "scl"]
LISTS = {"inputVars": "VAR_INPUT", "outputVars": "VAR_OUTPUT", "localVars": "VAR", "tempVars": "VAR_TEMP"}

plcopen = pytest.mark.extra("plcopen")


@cache
def schema() -> etree.XMLSchema:
    return etree.XMLSchema(etree.parse(str(shared_path("tools", "plcopen", "tc6_xml_v201.xsd"))))


def valid(text: str) -> etree._Element:
    """The parsed document; fails unless the schema accepts it."""
    root = etree.fromstring(text.encode("utf-8"))
    if not schema().validate(root):
        pytest.fail(f"not valid PLCopen TC6 XML 2.01: {schema().error_log}")
    return root


def examples() -> Iterator[Path]:
    """Every model file in examples/ that loads and whose ST generates."""
    for path in sorted(EXAMPLES.iterdir()):
        if not path.is_file():
            continue
        try:
            doc = fuzzyctl.load(path)
            generate_st(doc)
        except FuzzyctlError:
            assert path.suffix != ".fcl", f"{path.name}: every FCL example generates ST"
            continue
        yield path


EXAMPLE_FILES = list(examples())


# --------------------------------------------------------------------------- reading back


def formatted(el: etree._Element) -> str:
    """The text of a formattedText element (either form: ``<xhtml>`` or ``<xhtml:p>``)."""
    (child,) = list(el)
    assert child.tag in (f"{{{XHTML}}}xhtml", f"{{{XHTML}}}p"), child.tag
    assert len(child) == 0, "formatted text is plain text"
    return child.text or ""


def type_text(t: etree._Element) -> str:
    (child,) = list(t)
    name = etree.QName(child).localname
    if name != "array":
        assert len(child) == 0
        return name
    dims = child.findall("p:dimension", NS)
    base = child.find("p:baseType", NS)
    assert len(dims) == 1 and base is not None
    return f"ARRAY[{dims[0].get('lower')}..{dims[0].get('upper')}] OF {type_text(base)}"


def value_text(v: etree._Element) -> str:
    (child,) = list(v)
    if etree.QName(child).localname == "simpleValue":
        return str(child.get("value"))
    assert etree.QName(child).localname == "arrayValue"
    items = []
    for item in child.findall("p:value", NS):
        assert item.get("repetitionValue", "1") == "1"
        items.append(value_text(item))
    return "[" + ", ".join(items) + "]"


def declarations_from_xml(pou: etree._Element) -> list[tuple[str, str]]:
    """(section keyword, ``name : TYPE := init``) for every variable of the interface."""
    out = []
    for vl in pou.find("p:interface", NS):
        keyword = LISTS[etree.QName(vl).localname]
        for var in vl.findall("p:variable", NS):
            decl = f"{var.get('name')} : {type_text(var.find('p:type', NS))}"
            init = var.find("p:initialValue", NS)
            if init is not None:
                decl += f" := {value_text(init)}"
            out.append((keyword, decl))
    return out


def st_sections(st: str) -> list[tuple[str, str, list[tuple[str, str]], str]]:
    """(block name, declaration text, [(section keyword, declaration)], body) of every
    FUNCTION_BLOCK of an ST text, read from the text alone."""
    out = []
    for m in re.finditer(r"^FUNCTION_BLOCK (\w+)\n(.*?)^END_FUNCTION_BLOCK$", st, flags=re.S | re.M):
        lines = m.group(0).split("\n")
        last = max(i for i, line in enumerate(lines) if line == "END_VAR")
        decls: list[tuple[str, str]] = []
        section = ""
        for line in lines[1:last]:
            code = re.sub(r"\(\*.*?\*\)", "", line).strip()
            if code in LISTS.values():
                section = code
            elif code and code != "END_VAR":
                assert code.endswith(";"), line
                decls.append((section, code[:-1]))
        out.append((m.group(1), "\n".join(lines[: last + 1]), decls, "\n".join(lines[last + 1 : -1])))
    return out


def check_same_as_st(xml: str, st: str) -> etree._Element:
    root = valid(xml)
    pous = root.findall("p:types/p:pous/p:pou", NS)
    blocks = st_sections(st)
    assert [p.get("name") for p in pous] == [b[0] for b in blocks]
    for pou, (name, declaration, decls, body) in zip(pous, blocks, strict=True):
        assert pou.get("pouType") == "functionBlock"
        assert formatted(pou.find("p:body/p:ST", NS)) == body, f"{name}: the body differs from --lang st"
        assert declarations_from_xml(pou) == decls, f"{name}: the interface differs from --lang st"
        plain = pou.find("p:addData/p:data/p:InterfaceAsPlainText", NS)
        if plain is not None:
            assert formatted(plain) == declaration
    return root


# --------------------------------------------------------------------------- tests


@plcopen
@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=lambda p: p.name)
def test_every_example_is_valid_and_is_the_st(path: Path) -> None:
    doc = fuzzyctl.load(path)
    for dialect in XML_DIALECTS:
        for lreal in (False, True):
            xml = generate_plcopen(doc, dialect=dialect, lreal=lreal)
            root = check_same_as_st(xml, generate_st(doc, dialect=dialect, lreal=lreal))
            real = "LREAL" if lreal else "REAL"
            assert root.find(f".//p:inputVars/p:variable/p:type/p:{real}", NS) is not None


def test_the_examples_are_many() -> None:
    assert len(EXAMPLE_FILES) >= 10
    assert {p.suffix for p in EXAMPLE_FILES} >= {".fcl", ".fis", ".fpl", ".xfuz"}


@plcopen
def test_beremiz_form_is_valid_and_is_the_st() -> None:
    """For the iec / openplc dialects the formatted text is ``<xhtml:p>``, the form Beremiz
    and the OpenPLC Editor read (``xpath("xhtml:p")[0].text``)."""
    doc = fuzzyctl.load(EXAMPLES / "heater_extension.fcl")
    parts = st_parts(build_program(lower_block(doc), "st"))
    xml = render_plcopen([dataclasses.replace(parts, dialect="openplc")], project="p", version="1")
    st = generate_st(doc)
    root = check_same_as_st(xml, st.replace("dialect: codesys", "dialect: openplc"))
    assert root.findall(".//p:ST/x:p", NS) and not root.findall(".//x:xhtml", NS)
    assert root.find(".//p:addData", NS) is None  # CODESYS's extension only for CODESYS/TwinCAT
    assert etree.QName(root.find(".//p:ST", NS)[0]).localname == "p"


@plcopen
def test_several_blocks_make_one_project() -> None:
    text = (EXAMPLES / "figure7.fcl").read_text()
    second = text.replace("FUNCTION_BLOCK Fuzzy_FB", "FUNCTION_BLOCK Second_FB", 1)
    doc = fuzzyctl.load(text + "\n" + second, format="fcl")
    assert len(doc.blocks) == 2
    root = check_same_as_st(generate_plcopen(doc), generate_st(doc))
    assert len(root.findall("p:types/p:pous/p:pou", NS)) == 2
    one = valid(generate_plcopen(doc, block="Second_FB"))
    assert [p.get("name") for p in one.findall(".//p:pou", NS)] == ["Second_FB"]


def test_scl_is_refused() -> None:
    with pytest.raises(CodegenError, match="TIA Portal"):
        generate_plcopen(fuzzyctl.load(EXAMPLES / "figure7.fcl"), dialect="scl")


def test_reproducible_with_source_date_epoch(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    doc = fuzzyctl.load(EXAMPLES / "tank.fcl")
    xml = generate_plcopen(doc)
    assert 'creationDateTime="2023-11-14T22:13:20"' in xml and xml == generate_plcopen(doc)


# --------------------------------------------------------------------------- hostile text


def _structure(root: etree._Element) -> list[tuple[str, tuple[str, ...]]]:
    """Element tags and attribute names in document order (no text, no values)."""
    return [(str(el.tag), tuple(sorted(el.attrib))) for el in root.iter()]


@cache
def _benign(fmt: str) -> list[tuple[str, tuple[str, ...]]]:
    doc = _hostile_doc(fmt, None, "")
    assert doc is not None
    return _structure(valid(generate_plcopen(doc)))


@cache
def _benign_fcl() -> Document:
    return fuzzyctl.load(H.fill(H.FCL, None, ""), format="fcl")


def _hostile_doc(fmt: str, field: str | None, text: str) -> Document | None:
    source = (
        H.json_model(_benign_fcl(), field, text) if fmt == "json" else H.fill(H.TEMPLATES[fmt], field, text)
    )
    try:
        return fuzzyctl.load(source, format=fmt)
    except FuzzyctlError:
        return None


@plcopen
@pytest.mark.parametrize("fmt", ["fcl", "json"])
def test_hostile_text_is_refused_or_inert(fmt: str) -> None:
    benign = _benign(fmt)
    benign_body = list(H.st_tokens(st_sections(generate_st(_hostile_doc(fmt, None, "")))[0][3]))  # type: ignore[arg-type]
    written: dict[str, int] = {}
    for field in H.PLACEHOLDERS:
        for key, text in H.HOSTILE.items():
            doc = _hostile_doc(fmt, field, text)
            if doc is None:
                continue
            try:
                st = generate_st(doc)
            except CodegenError:
                with pytest.raises(CodegenError):
                    generate_plcopen(doc)
                continue
            xml = generate_plcopen(doc)
            root = check_same_as_st(xml, st)  # parses, validates, body and interface are the ST's
            assert _structure(root) == benign, f"{fmt} {field} {key}: the XML structure changed"
            for el in [*root.findall(".//p:documentation/*", NS), *root.findall(".//p:Comment", NS)]:
                # documentation becomes ST comments in the IDEs: one ST-safe text per line
                assert not re.search(r"\(\*|\*\)|[^\n\x20-\x7e]", el.text or ""), (fmt, field, key)
            body = formatted(root.find(".//p:ST", NS))
            assert list(H.st_tokens(body)) == benign_body, f"{fmt} {field} {key}: the ST body changed"
            written[field] = written.get(field, 0) + 1
    # the free-text fields were written with every hostile string (so this tested something)
    if fmt == "json":
        assert all(written.get(f) == len(H.HOSTILE) for f in ("QQlabelQQ", "QQblockQQ", "QQcmtQQ")), written
    else:  # an FCL comment cannot hold "*)": two strings end it early and the file is refused
        assert written.get("QQvcmtQQ", 0) >= len(H.HOSTILE) - 2, written


_XML_INVALID = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def _with_text(parts: STParts, text: str) -> STParts:
    """``parts`` with ``text`` in every string the writer is given."""
    sections = tuple(
        dataclasses.replace(
            sec,
            title=text,
            variables=tuple(
                dataclasses.replace(
                    v,
                    name=v.name + text,
                    comment=text,
                    init=None if v.init is None else tuple(i + text for i in v.init),
                )
                for v in sec.variables
            ),
        )
        for sec in parts.sections
    )
    return dataclasses.replace(
        parts, name=text, header=(text, text), sections=sections, body=(*parts.body, text)
    )


@plcopen
@pytest.mark.parametrize("key", list(H.HOSTILE))
def test_every_string_the_writer_gets_is_escaped(key: str) -> None:
    """The writer on its own: a hostile string in every text it is given - block and variable
    names, literals, header, section titles, variable comments, a body line - stays data:
    the structure of the same parts with a plain word, the names and the body read back as
    given (characters XML cannot hold become U+FFFD), the documentation ST-safe."""
    text = H.HOSTILE[key]
    parts = st_parts(build_program(lower_block(fuzzyctl.load(EXAMPLES / "figure7.fcl")), "st"))
    benign = _structure(valid(render_plcopen([_with_text(parts, "plain")], project="p", version="1")))
    hostile = _with_text(parts, text)
    root = valid(render_plcopen([hostile], project=text, version=text))
    assert _structure(root) == benign
    shown = _XML_INVALID.sub("\ufffd", text)
    (pou,) = root.findall(".//p:pou", NS)
    assert pou.get("name") == shown and root.find("p:contentHeader", NS).get("name") == shown
    names = [v.get("name") for v in pou.iterfind(".//p:variable", NS)]
    assert names == [_XML_INVALID.sub("\ufffd", v.name) for sec in hostile.sections for v in sec.variables]
    assert formatted(pou.find("p:body/p:ST", NS)) == _XML_INVALID.sub("\ufffd", "\n".join(hostile.body))
    for el in [*root.findall(".//p:documentation/*", NS), *root.findall(".//p:Comment", NS)]:
        assert el.text and not re.search(r"\(\*|\*\)|[^\n\x20-\x7e]", el.text), key


# --------------------------------------------------------------------------- command line


@plcopen
def test_cli_writes_the_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "tank.xml"
    src = str(EXAMPLES / "tank.fcl")
    assert main(["codegen", src, "--lang", "plcopen", "--dialect", "twincat", "--lreal", "-o", str(out)]) == 0
    assert f"wrote {out}" in capsys.readouterr().err
    assert main(["codegen", src, "--lang", "st", "--dialect", "twincat", "--lreal"]) == 0
    check_same_as_st(out.read_text(), capsys.readouterr().out)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--dialect", "scl"], "TIA Portal does not import PLCopen XML"),
        (["--float"], "--float applies to --lang c"),
    ],
)
def test_cli_refuses_what_does_not_apply(
    args: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["codegen", str(EXAMPLES / "tank.fcl"), "--lang", "plcopen", *args]) == 2
    err = capsys.readouterr().err
    assert message in " ".join(err.split()) and "Traceback" not in err
