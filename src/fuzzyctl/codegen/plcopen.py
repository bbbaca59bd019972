"""PLCopen TC6 XML 2.01: the function blocks of :mod:`~fuzzyctl.ir.render.st` as the
exchange file CODESYS, TwinCAT, Beremiz / OpenPLC Editor and Simulink PLC Coder import.

One ``<project>`` (``fileHeader``, ``contentHeader``, ``types/pous``, an empty
``instances/configurations``) with one ``<pou pouType="functionBlock">`` per block: the
``interface`` holds the sections of the ST text as ``inputVars``, ``outputVars``,
``localVars`` and ``tempVars`` (types, arrays as ``array/dimension/baseType``, initial values as
``simpleValue`` / ``arrayValue``, comments as ``documentation``), and ``body/ST`` the ST body,
the very lines ``--lang st`` prints between the last ``END_VAR`` and ``END_FUNCTION_BLOCK``.

The formatted text (body, documentation) is an ``<xhtml>`` element of the XHTML namespace,
as CODESYS and TwinCAT export it; for the ``iec`` / ``openplc`` dialects it is an
``<xhtml:p>``, the only form Beremiz and the OpenPLC Editor read.  CODESYS and TwinCAT also
get the declaration part as ST text in their ``interfaceasplaintext`` extension (an
``addData`` other tools skip), so the comments of the parameter arrays survive the import.

The XML is printed as text: every element and attribute name is a constant of this module,
and every value (names, literals, comments, the body) passes :func:`fuzzyctl.escape.xml_attr`
or :func:`fuzzyctl.escape.xml_text`; comments are made ST-safe first
(:func:`fuzzyctl.escape.st_comment`), since the IDEs turn documentation into ST comments.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from datetime import UTC, datetime
from typing import Any

from fuzzyctl.escape import xml_attr, xml_text
from fuzzyctl.ir.render.st import STParts, STSection, STVar, format_st, st_parts
from fuzzyctl.ir.state import CodegenError
from fuzzyctl.kinds import targets
from fuzzyctl.model import Document, FunctionBlock

NS_TC6 = "http://www.plcopen.org/xml/tc6_0201"
NS_XHTML = "http://www.w3.org/1999/xhtml"
#: CODESYS's (and TwinCAT's) extension holding the declaration part as plain ST text.
PLAINTEXT_INTERFACE = "http://www.3s-software.com/plcopenxml/interfaceasplaintext"
#: ST section keyword -> PLCopen variable list.
VAR_LISTS = {"VAR_INPUT": "inputVars", "VAR_OUTPUT": "outputVars", "VAR": "localVars", "VAR_TEMP": "tempVars"}
#: Array elements per line of an ``arrayValue`` (large rule tables stay readable and compact).
VALUES_PER_LINE = 8
_ELEMENTARY = frozenset({"REAL", "LREAL", "INT", "DINT", "LINT", "BOOL", "BYTE"})


class _Xml:
    """Indented XML as lines; tags are this module's constants, values are escaped here."""

    def __init__(self, p_form: bool) -> None:
        self.lines: list[str] = []
        self.depth = 0
        self.p_form = p_form

    @staticmethod
    def _attrs(attrs: dict[str, str]) -> str:
        return "".join(f' {k}="{xml_attr(v)}"' for k, v in attrs.items())

    def open(self, tag: str, **attrs: str) -> None:
        self.lines.append("  " * self.depth + f"<{tag}{self._attrs(attrs)}>")
        self.depth += 1

    def close(self, tag: str) -> None:
        self.depth -= 1
        self.lines.append("  " * self.depth + f"</{tag}>")

    def empty(self, tag: str, **attrs: str) -> None:
        self.lines.append("  " * self.depth + f"<{tag}{self._attrs(attrs)}/>")

    def leaf(self, tag: str, text: str) -> None:
        self.lines.append("  " * self.depth + f"<{tag}>{xml_text(text)}</{tag}>")

    def formatted(self, tag: str, text: str) -> None:
        """A ``formattedText`` element: ``text`` verbatim (no indentation added inside)."""
        inner = (
            f"<xhtml:p>{xml_text(text)}</xhtml:p>"
            if self.p_form
            else f'<xhtml xmlns="{NS_XHTML}">{xml_text(text)}</xhtml>'
        )
        self.lines.append("  " * self.depth + f"<{tag}>{inner}</{tag}>")


def _comment_text(text: str) -> str:
    """A model comment as documentation: each line ST-safe (the IDEs show it as a comment)."""
    return "\n".join(targets.PLCOPEN.comments.escape(line) for line in text.split("\n"))


def _type(v: STVar) -> str:
    if v.base not in _ELEMENTARY:
        raise CodegenError(f"type {v.base} has no PLCopen form here")
    if v.size is None:
        return f"<{v.base}/>"
    dim = f'<dimension lower="0" upper="{xml_attr(str(v.size - 1))}"/>'
    return f"<array>{dim}<baseType><{v.base}/></baseType></array>"


def _variable(x: _Xml, v: STVar) -> None:
    x.open("variable", name=v.name)
    x.lines.append("  " * x.depth + f"<type>{_type(v)}</type>")
    if v.init is not None:
        x.open("initialValue")
        if v.size is None:
            x.empty("simpleValue", value=v.init[0])
        else:
            x.open("arrayValue")
            values = [f'<value><simpleValue value="{xml_attr(literal)}"/></value>' for literal in v.init]
            for k in range(0, len(values), VALUES_PER_LINE):
                x.lines.append("  " * x.depth + "".join(values[k : k + VALUES_PER_LINE]))
            x.close("arrayValue")
        x.close("initialValue")
    if v.comment:
        x.formatted("documentation", _comment_text(v.comment))
    x.close("variable")


def _section(x: _Xml, sec: STSection) -> None:
    tag = VAR_LISTS[sec.keyword]
    x.open(tag)
    for v in sec.variables:
        _variable(x, v)
    if sec.title:
        x.formatted("documentation", _comment_text(sec.title))
    x.close(tag)


def declaration_text(parts: STParts) -> str:
    """The ST declaration part exactly as ``--lang st`` prints it: from ``FUNCTION_BLOCK``
    to the last ``END_VAR``."""
    lines = format_st(parts).split("\n")[len(parts.header) : -1]  # the text ends with "\n"
    return "\n".join(lines[: len(lines) - len(parts.body) - 1])


def body_text(parts: STParts) -> str:
    """The ST body exactly as ``--lang st`` prints it (between the last ``END_VAR`` and
    ``END_FUNCTION_BLOCK``)."""
    return "\n".join(parts.body)


def _pou(x: _Xml, parts: STParts) -> None:
    x.open("pou", name=parts.name, pouType="functionBlock")
    x.open("interface")
    for sec in parts.sections:
        _section(x, sec)
    x.close("interface")
    x.open("body")
    x.formatted("ST", body_text(parts))
    x.close("body")
    if not x.p_form:
        x.open("addData")
        x.open("data", name=PLAINTEXT_INTERFACE, handleUnknown="discard")
        x.formatted("InterfaceAsPlainText", declaration_text(parts))
        x.close("data")
        x.close("addData")
    x.formatted("documentation", _comment_text("\n".join(parts.header)))
    x.close("pou")


def check_dialect(dialect: str) -> None:
    """Refuse a dialect whose record says it cannot be PLCopen XML (``scl``: its text is not
    IEC 61131-3, and TIA Portal imports SCL source)."""
    record = targets.dialect(dialect)
    refusal = record.refused_by.get(targets.PLCOPEN.name)
    if refusal is not None:
        raise CodegenError(
            f"{refusal} (it holds IEC 61131-3 text): use --lang st "
            f"--dialect {record.name}, or another --dialect with --lang plcopen"
        )


def creation_time() -> datetime:
    """Now, or ``SOURCE_DATE_EPOCH`` when set (reproducible builds), in UTC."""
    epoch = os.environ.get("SOURCE_DATE_EPOCH", "").strip()
    if epoch.isdigit():
        return datetime.fromtimestamp(int(epoch), UTC)
    return datetime.now(UTC).replace(microsecond=0)


def render_plcopen(
    blocks: Sequence[STParts], *, project: str, version: str, created: datetime | None = None
) -> str:
    """One PLCopen TC6 XML 2.01 project holding ``blocks`` (all of one dialect)."""
    dialects = {b.dialect for b in blocks}
    for d in dialects:
        check_dialect(d)
    # Beremiz and the OpenPLC Editor read formatted text only from <xhtml:p>
    x = _Xml(p_form=any(targets.dialect(d).plcopen_p_form for d in dialects))
    stamp = (created or creation_time()).strftime("%Y-%m-%dT%H:%M:%S")
    x.lines.append('<?xml version="1.0" encoding="UTF-8"?>')
    x.open("project", xmlns=NS_TC6, **{"xmlns:xhtml": NS_XHTML})
    x.empty(
        "fileHeader",
        companyName="fuzzyctl",
        productName="fuzzyctl",
        productVersion=version,
        creationDateTime=stamp,
        contentDescription="IEC 61131-7 fuzzy control function blocks generated by fuzzyctl",
    )
    x.open("contentHeader", name=project, modificationDateTime=stamp)
    x.leaf("Comment", "\n".join(_comment_text(h) for b in blocks for h in b.header[:1]))
    x.open("coordinateInfo")
    for lang in ("fbd", "ld", "sfc"):
        x.open(lang)
        x.empty("scaling", x="1", y="1")
        x.close(lang)
    x.close("coordinateInfo")
    x.close("contentHeader")
    x.open("types")
    x.empty("dataTypes")
    x.open("pous")
    for parts in blocks:
        _pou(x, parts)
    x.close("pous")
    x.close("types")
    x.open("instances")
    x.empty("configurations")
    x.close("instances")
    x.close("project")
    return "\n".join(x.lines) + "\n"


def st_blocks(
    model: Document | FunctionBlock, block: str | None, dialect: str, lreal: bool, options: dict[str, Any]
) -> list[STParts]:
    """The blocks :func:`fuzzyctl.codegen.api.generate_st` prints, as parts (its
    ``render_st`` is ``format_st(st_parts(...))``): keep the two pipelines in step -
    tests/codegen/test_plcopen.py compares their texts."""
    dialect = targets.dialect(dialect).name  # an alias as its dialect; unknown names refused
    from fuzzyctl.codegen.api import build, plans

    options = dict(options)
    default = options.pop("default", None)  # --default, as generate_st applies it
    parts = []
    for plan in plans(model, block, **options):
        parts.append(st_parts(build(plan, "st", default).program, dialect=dialect, lreal=lreal))
    return parts


def generate_plcopen(
    model: Document | FunctionBlock,
    *,
    block: str | None = None,
    dialect: str = "codesys",
    lreal: bool = False,
    project: str | None = None,
    arith: str = "float",
    lookup: bool = False,
    **options: Any,
) -> str:
    """PLCopen TC6 XML 2.01 (one project, one ``functionBlock`` POU per function block) whose
    ST bodies and declarations are those ``generate_st`` writes for the same ``dialect`` and
    ``lreal``; ``project`` names the project (default: the first block's name).  The ``scl``
    dialect is refused (TIA Portal imports SCL source, not PLCopen XML)."""
    from fuzzyctl import __version__
    from fuzzyctl.codegen.api import check_arith

    if lookup:  # the table blocks (codegen/lookup_st.py), in every arithmetic
        from fuzzyctl.codegen.lookup_st import generate_lookup_plcopen

        return generate_lookup_plcopen(
            model, block=block, dialect=dialect, lreal=lreal, arith=arith, project=project, **options
        )
    check_dialect(dialect)
    from fuzzyctl.type2 import is_type2

    if is_type2(model):
        from fuzzyctl.codegen.type2 import refuse_options, st_blocks_type2

        refuse_options(arith, False, options.get("default"))
        samples = options.get("samples")
        parts = st_blocks_type2(
            model, block, targets.dialect(dialect).name, lreal, *([int(samples)] if samples else [])
        )
    elif check_arith(arith):
        from fuzzyctl.codegen.fixed import fixed_st_blocks

        parts = fixed_st_blocks(model, block, options, arith=arith, dialect=dialect)
    else:
        parts = st_blocks(model, block, dialect, lreal, options)
    name = project or (parts[0].name if parts else "fuzzyctl")
    return render_plcopen(parts, project=name, version=__version__)
