"""IEC 61131-7 Fuzzy Control Language: parser, checks, writer and conformance report.

>>> from fuzzyctl.fcl import load_text
>>> result = load_text("FUNCTION_BLOCK f VAR_INPUT t : REAL; END_VAR END_FUNCTION_BLOCK")
>>> result.document.main.inputs[0].name
't'
"""

from __future__ import annotations

import os
from dataclasses import dataclass, replace

from fuzzyctl.diagnostics import Diagnostic, DiagnosticError, has_errors
from fuzzyctl.fcl.checks import CheckContext, register_provider, run_checks
from fuzzyctl.fcl.no_if import without_if_parts
from fuzzyctl.fcl.parser import parse_source
from fuzzyctl.fcl.source import Source, decode, read_source
from fuzzyctl.fcl.writer import write
from fuzzyctl.gcpause import gc_paused
from fuzzyctl.model import Document


@dataclass
class LoadResult:
    """A loaded document (``None`` when the file has errors) with every diagnostic."""

    document: Document | None
    diagnostics: list[Diagnostic]
    source: Source
    spellings: frozenset[str] = frozenset()

    @property
    def ok(self) -> bool:
        return self.document is not None and not has_errors(self.diagnostics)

    def raise_for_errors(self) -> Document:
        """The document, or :class:`DiagnosticError` carrying every diagnostic."""
        if self.document is None or has_errors(self.diagnostics):
            raise DiagnosticError(self.diagnostics, self.source.text)
        return self.document


@gc_paused()
def check_source(source: Source, *, strict: bool = False, compat: str = "iec") -> LoadResult:
    """Parse and check decoded text; never raises for bad input.

    ``strict``: what a strict IEC 61131-7 tool refuses is an error (identifiers that are
    Table 7 keywords), not a warning.  ``compat="jfuzzylogic"`` adds a warning for each
    construct jFuzzyLogic 3.3 would reject or misread (:mod:`fuzzyctl.fcl.jfl`)."""
    from fuzzyctl.limits import check_document, check_text

    try:
        check_text(source.text, source.path, "fcl")
    except DiagnosticError as exc:  # over the size limit: said, not parsed
        return LoadResult(None, exc.diagnostics, source)
    from fuzzyctl.fcl import type2

    masked, extras = type2.split(source.text)  # interval type-2 terms (Open level), if any
    parsed = parse_source(replace(source, text=masked) if extras else source)
    diagnostics = list(parsed.diagnostics)
    document = parsed.document
    if document is not None and extras and not has_errors(diagnostics):
        document, found = type2.attach(document, extras, source.path)
        diagnostics.extend(found)
    if document is not None and not has_errors(diagnostics):
        diagnostics.extend(check_document(document, source.path))
    if document is not None and not has_errors(diagnostics):
        document, notes = without_if_parts(document)  # IF ALWAYS THEN: Siemens 1.5 rules
        diagnostics.extend(notes)
        context = CheckContext(source.path, {"strict": strict, "compat": compat, "parsed": parsed})
        diagnostics.extend(run_checks(document, context))
    return LoadResult(document, diagnostics, source, parsed.spellings)


def load_text(text: str, path: str | None = None, *, strict: bool = False, compat: str = "iec") -> LoadResult:
    """Parse and check FCL source text (``strict``, ``compat``: see :func:`check_source`)."""
    return check_source(Source(text.removeprefix("\ufeff"), path), strict=strict, compat=compat)


def load_file(path: str | os.PathLike[str], *, strict: bool = False, compat: str = "iec") -> LoadResult:
    """Read, parse and check an FCL file (missing file, directory, binary data and
    undecodable text raise :class:`DiagnosticError`); ``strict``, ``compat``: see
    :func:`check_source`."""
    return check_source(read_source(path), strict=strict, compat=compat)


def parse_fcl(text: str, path: str | None = None) -> Document:
    """The document for ``text``; raises :class:`DiagnosticError` on any error."""
    return load_text(text, path).raise_for_errors()


__all__ = [
    "CheckContext",
    "LoadResult",
    "check_source",
    "decode",
    "load_file",
    "load_text",
    "parse_fcl",
    "register_provider",
    "run_checks",
    "write",
]
