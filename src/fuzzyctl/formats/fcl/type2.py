"""Writing interval type-2 models as FCL: the type-1 writer's text with each term's
``LOWER ...`` and each output's ``TYPE_REDUCTION : ...;`` added (the form
:mod:`fuzzyctl.fcl.type2` reads, docs/fcl.md).  A type-1 model is written as before."""

from __future__ import annotations

import re
from dataclasses import replace

from fuzzyctl.formats import Loss
from fuzzyctl.formats.common.basics import fmt_number
from fuzzyctl.formats.fcl import writer as fcl_writer
from fuzzyctl.kinds import type_reduction as tr
from fuzzyctl.model import (
    Document,
    FunctionBlock,
    FuzzifyBlock,
    LowerMF,
    MembershipFunction,
    Term,
    Variable,
    VarKind,
)

_TERM = re.compile(r"\bTERM\s+([A-Za-z_]\w*)\s*:=[^;]*;", re.IGNORECASE)
_BLOCK = re.compile(r"^\s*(FUZZIFY|DEFUZZIFY)\s+([A-Za-z_]\w*)", re.IGNORECASE)


def _positions(fb: FunctionBlock) -> list[list[LowerMF | None]]:
    return [[t.lower for t in f.terms] for f in fb.fuzzify] + [
        [t.lower for t in d.terms] for d in fb.defuzzify
    ]


def adapt(document: Document) -> tuple[Document, list[Loss]]:
    """The type-1 adaptation, the lower functions and type reductions kept (by position:
    the adaptation may rename terms)."""
    adapted, losses = fcl_writer.adapt(document)
    blocks = []
    for before, after in zip(document.blocks, adapted.blocks, strict=True):
        if not before.is_type2:
            blocks.append(after)
            continue
        lowers = _positions(before)
        n = len(after.fuzzify)
        fuzzify = tuple(
            replace(f, terms=tuple(replace(t, lower=lowers[i][j]) for j, t in enumerate(f.terms)))
            for i, f in enumerate(after.fuzzify)
        )
        defuzzify = tuple(
            replace(
                d,
                terms=tuple(replace(t, lower=lowers[n + i][j]) for j, t in enumerate(d.terms)),
                type_reduction=before.defuzzify[i].type_reduction,
            )
            for i, d in enumerate(after.defuzzify)
        )
        blocks.append(replace(after, fuzzify=fuzzify, defuzzify=defuzzify))
    return replace(adapted, blocks=tuple(blocks)), losses


def _mf_text(mf: MembershipFunction) -> str:
    """How the type-1 writer writes ``mf`` as a term's function."""
    fb = FunctionBlock("lower", (Variable("v", VarKind.INPUT),), (FuzzifyBlock("v", (Term("t", mf),)),))
    doc, _ = fcl_writer.adapt(Document((fb,)))
    m = _TERM.search(fcl_writer.write(doc))
    assert m is not None
    return m.group(0).split(":=", 1)[1].rstrip(";").strip()


def lower_text(lower: LowerMF) -> str:
    if lower.mf is not None:
        return f"LOWER {_mf_text(lower.mf)}"
    return f"LOWER SCALE {fmt_number(lower.scale)} LAG {' '.join(fmt_number(v) for v in lower.lag)}"


def write(document: Document) -> str:
    """FCL text of a document :func:`adapt` returned."""
    text = fcl_writer.write(replace(document, blocks=tuple(_type1(fb) for fb in document.blocks)))
    if not any(fb.is_type2 for fb in document.blocks):
        return text
    out: list[str] = []
    blocks = iter(document.blocks)
    fb: FunctionBlock | None = None
    current = None
    for line in text.splitlines():
        if re.match(r"^\s*FUNCTION_BLOCK\b", line, re.IGNORECASE):
            fb = next(blocks)
        if (m := _BLOCK.match(line)) and fb is not None:
            side, name = m.group(1).upper(), m.group(2)
            current = fb.fuzzify_block(name) if side == "FUZZIFY" else fb.defuzzify_block(name)
        if current is not None and (t := _TERM.search(line)):
            term = current.term(t.group(1))
            if term is not None and term.lower is not None:
                end = t.end() - 1  # the statement's semicolon
                line = f"{line[:end]} {lower_text(term.lower)}{line[end:]}"
        if re.match(r"^\s*END_DEFUZZIFY\b", line, re.IGNORECASE) and current is not None:
            code = getattr(current, "type_reduction", None)
            if code is not None:
                indent = line[: len(line) - len(line.lstrip())]
                out.append(f"{indent}    TYPE_REDUCTION : {tr.spelling(code, 'fcl')};")
            current = None
        out.append(line)
    return "\n".join(out) + ("\n" if text.endswith("\n") else "")


def _type1(fb: FunctionBlock) -> FunctionBlock:
    from fuzzyctl.formats.common.type2 import to_type1

    return to_type1(fb) if fb.is_type2 else fb
