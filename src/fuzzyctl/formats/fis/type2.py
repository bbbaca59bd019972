"""MATLAB's interval type-2 FIS files (``mamfistype2`` / ``sugfistype2``, R2019b on): the
type-1 reader and writer with what type-2 adds.

A type-2 file says ``Type='mamdanitype2'`` or ``'sugenotype2'`` and
``TypeReductionMethod='karnikmendel'`` (``'ekm'``, ``'iasc'``, ``'eiasc'``) in
``[System]``; each membership function of an input (and of a Mamdani output) carries its
lower function after the upper one's parameters::

    MF1='poor':'trimf',[-5 0 5],'LowerScale',0.8,'LowerLag',0.2
    MF2='good':'trapmf',[0 2 8 10],'LowerScale',1,'LowerLag',[0.1 0.3]

``LowerLag=[left right]`` (one value: both sides); the forms ``LowerScale=0.8`` and
``LowerLag=[0.1 0.3]`` are read too.  A membership function without them takes MATLAB's
defaults (scale 1, lag 0.2).  The lines are rewritten in place to the type-1 form (so line
numbers stay) and read by :mod:`.reader`; the lower functions and the method are then put
back on the model.  Other ``[System]`` keys of type-2 files (``OutputSampleNumber``) are
not needed by the exact engine and are read as the type-1 reader reads unknown keys.
"""

from __future__ import annotations

import re
from dataclasses import replace

from fuzzyctl.diagnostics import DiagnosticError, error
from fuzzyctl.formats import Loaded, Loss
from fuzzyctl.formats.common.basics import fmt_number
from fuzzyctl.formats.common.type2 import to_type1
from fuzzyctl.formats.fis import reader as fis_reader
from fuzzyctl.formats.fis.rules import is_ts_term
from fuzzyctl.kinds import type_reduction as tr
from fuzzyctl.model import Document, FunctionBlock, LowerMF, Span, Term

TYPES = {"mamdanitype2": "mamdani", "sugenotype2": "sugeno"}
#: MATLAB's lower function when a type-2 file gives none (fismftype2 defaults).
DEFAULT_LOWER = LowerMF(scale=1.0, lag=(0.2,))

_TYPE = re.compile(r"^(\s*Type\s*=\s*)'([^']*)'", re.IGNORECASE)
_TR = re.compile(r"^\s*TypeReductionMethod\s*=\s*'([^']*)'", re.IGNORECASE)
_MF = re.compile(r"^\s*MF\d+\s*=", re.IGNORECASE)
_LOWER = re.compile(
    r"""\s*,\s*(?:'(LowerScale|LowerLag)'\s*,\s*|(LowerScale|LowerLag)\s*=\s*)(\[[^\]]*\]|[^,\s]+)""",
    re.IGNORECASE,
)


def declares_type2(text: str) -> bool:
    """The file's ``[System]`` says a type-2 ``Type``."""
    return any((m := _TYPE.match(line)) and m.group(2).lower() in TYPES for line in text.splitlines())


def _fail(message: str, path: str | None, line: int) -> DiagnosticError:
    return DiagnosticError([error(message, Span(line, 1), file=path, code="fis-type2")])


def _numbers(text: str, path: str | None, line: int, key: str) -> tuple[float, ...]:
    try:
        return tuple(float(v) for v in text.strip("[]").replace(",", " ").split())
    except ValueError:
        raise _fail(f"{key} must be a number or [numbers], found {text!r}", path, line) from None


def _lower(found: dict[str, tuple[float, ...]], path: str | None, line: int) -> LowerMF:
    scale = found.get("lowerscale", (DEFAULT_LOWER.scale,))
    lag = found.get("lowerlag", DEFAULT_LOWER.lag)
    if len(scale) != 1 or not 0.0 < scale[0] <= 1.0:
        raise _fail(f"LowerScale must be one value in (0, 1], found {list(scale)}", path, line)
    if len(lag) not in (1, 2) or not all(0.0 <= v < 1.0 for v in lag):
        raise _fail(f"LowerLag must be one or two values in [0, 1), found {list(lag)}", path, line)
    return LowerMF(scale=scale[0], lag=lag)


def read(text: str, path: str | None = None, *, dialect: str | None = None) -> Loaded:
    """Read a FIS file, type-1 or type-2."""
    if not declares_type2(text):
        return fis_reader.read(text, path, dialect=dialect)
    lines = text.splitlines()
    lowers: dict[int, LowerMF] = {}
    method: str | None = None
    for i, line in enumerate(lines):
        n = i + 1
        if (m := _TYPE.match(line)) and m.group(2).lower() in TYPES:
            lines[i] = f"{m.group(1)}'{TYPES[m.group(2).lower()]}'" + line[m.end() :]
        elif m := _TR.match(line):
            method = tr.spelled("fis").get(m.group(1).lower())
            if method is None:
                known = ", ".join(s for t in tr.METHODS.values() for s in t.spellings["fis"][:1])
                raise _fail(f"TypeReductionMethod={m.group(1)!r} is not known (known: {known})", path, n)
            lines[i] = ""
        elif _MF.match(line):
            found = {(k1 or k2).lower(): _numbers(v, path, n, k1 or k2) for k1, k2, v in _LOWER.findall(line)}
            lines[i] = _LOWER.sub("", line)
            lowers[n] = _lower(found, path, n)
    loaded = fis_reader.read("\n".join(lines) + "\n", path, dialect=dialect)
    fb = _with_lowers(loaded.document.main, lowers, method)
    return Loaded(Document((fb,), loaded.document.path, loaded.document.comments), loaded.diagnostics)


def _with_lowers(fb: FunctionBlock, lowers: dict[int, LowerMF], method: str | None) -> FunctionBlock:
    def put(t: Term) -> Term:
        if is_ts_term(t.mf) or t.span is None:
            return t
        return replace(t, lower=lowers.get(t.span.line, DEFAULT_LOWER))

    fuzzify = tuple(replace(f, terms=tuple(put(t) for t in f.terms)) for f in fb.fuzzify)
    defuzzify = tuple(
        replace(d, terms=tuple(put(t) for t in d.terms), type_reduction=method or tr.DEFAULT)
        for d in fb.defuzzify
    )
    return replace(fb, fuzzify=fuzzify, defuzzify=defuzzify)


# --------------------------------------------------------------------------- writing


def adapt(document: Document) -> tuple[Document, list[Loss]]:
    """The model as a FIS states it: a type-1 model as the type-1 writer adapts it; a
    type-2 one keeps its lower functions where MATLAB's form (scale and lag of the upper)
    holds them, and says which it cannot."""
    from fuzzyctl.formats.fis import writer as fis_writer  # (reading needs no writer)

    fb = document.main
    if not fb.is_type2:
        return fis_writer.adapt(document)
    losses: list[Loss] = []
    for blocks in (fb.fuzzify, fb.defuzzify):
        for b in blocks:
            for t in b.terms:
                if t.lower is not None and t.lower.mf is not None:
                    losses.append(
                        Loss(
                            f"term {t.name!r} of {b.variable!r}",
                            "a MATLAB type-2 FIS gives the lower function as LowerScale/LowerLag of "
                            "the upper one; an explicit lower function is written as the upper one "
                            "(scale 1, lag 0)",
                        )
                    )
    adapted, more = fis_writer.adapt(replace(document, blocks=(to_type1(fb),)))
    keep = {
        (b.variable, t.name): t.lower
        for blocks in (fb.fuzzify, fb.defuzzify)
        for b in blocks
        for t in b.terms
    }
    back = adapted.main
    restored = replace(
        back,
        fuzzify=tuple(
            replace(f, terms=tuple(replace(t, lower=keep.get((f.variable, t.name))) for t in f.terms))
            for f in back.fuzzify
        ),
        defuzzify=tuple(
            replace(
                d,
                terms=tuple(replace(t, lower=keep.get((d.variable, t.name))) for t in d.terms),
                type_reduction=next(
                    (o.type_reduction for o in fb.defuzzify if o.variable == d.variable), None
                ),
            )
            for d in back.defuzzify
        ),
    )
    methods = {d.type_reduction or tr.DEFAULT for d in fb.defuzzify}
    if len(methods) > 1:
        losses.append(
            Loss("type reduction", f"FIS has one TypeReductionMethod; the outputs use {sorted(methods)}")
        )
    return replace(adapted, blocks=(restored,)), losses + more


def _lower_text(lower: LowerMF | None) -> str:
    scale: float
    lag: tuple[float, ...]
    if lower is None or lower.mf is not None:
        scale, lag = 1.0, (0.0,)
    else:
        scale, lag = lower.scale, lower.lag
    lag_text = fmt_number(lag[0]) if len(lag) == 1 else f"[{' '.join(fmt_number(v) for v in lag)}]"
    return f",'LowerScale',{fmt_number(scale)},'LowerLag',{lag_text}"


def write(document: Document) -> str:
    """FIS text of a document :func:`adapt` returned (type-2: MATLAB's type-2 form)."""
    from fuzzyctl.formats.fis import writer as fis_writer

    fb = document.main
    if not fb.is_type2:
        return fis_writer.write(document)
    text = fis_writer.write(replace(document, blocks=(to_type1(fb),)))
    method = tr.spelling(next((d.type_reduction for d in fb.defuzzify if d.type_reduction), None), "fis")
    out: list[str] = []
    terms: tuple[Term, ...] = ()
    section = ""
    for line in text.splitlines():
        if line.startswith("["):
            section = line
            terms = ()
        if line.startswith("Type='"):
            line = "Type='" + line[len("Type='") :].replace("'", "type2'", 1)
        if line.startswith("Name='") and section.startswith(("[Input", "[Output")):
            name = _name_of(line)
            block = fb.fuzzify_block(name) if section.startswith("[Input") else fb.defuzzify_block(name)
            terms = block.terms if block is not None else ()
        if (m := re.match(r"MF(\d+)=", line)) and terms and not is_ts_term(terms[int(m.group(1)) - 1].mf):
            line += _lower_text(terms[int(m.group(1)) - 1].lower)
        out.append(line)
        if line.startswith("DefuzzMethod="):
            out.append(f"TypeReductionMethod='{method}'")
    return "\n".join(out) + "\n"


def _name_of(line: str) -> str:
    return line[len("Name='") : line.rindex("'")]
