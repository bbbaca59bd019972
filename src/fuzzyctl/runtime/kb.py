"""Knowledge bases of the runtime's instances: read from a file or from text in any
format of the registry (FCL, FPL, XFUZ tables, FIS, FLL, JSON), prepared for the block
style of the instance.

Preparing is the slow part of a download (parsing, checking, compiling the controller or
decoding the XFUZ tables); it happens before the cycle is touched, so that the switch
itself is a reference swap (see :mod:`fuzzyctl.runtime.instance`).
"""

from __future__ import annotations

import functools
import hashlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fuzzyctl.diagnostics import Diagnostic, DiagnosticError, FuzzyctlError
from fuzzyctl.model import Document

__all__ = ["KnowledgeBaseSource", "PreparedKB", "prepare_kb", "read_kb"]


@dataclass(frozen=True)
class KnowledgeBaseSource:
    """The text of a knowledge base and where it came from."""

    text: str
    format: str
    origin: str
    """A file path, or ``"api"``."""

    @property
    def sha256(self) -> str:
        return hashlib.sha256(self.text.encode("utf-8")).hexdigest()


@dataclass(frozen=True)
class PreparedKB:
    """A knowledge base ready to be switched in: the block object for its style, built
    and checked, and the names of its inputs and outputs."""

    source: KnowledgeBaseSource
    document: Document
    block: Any
    """A :class:`FuzzyFB` (siemens) or :class:`XfuzConstants` (xfuz)."""
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    labels: dict[str, str]
    """xfuz: variable name -> ``INPn``/``OUTn``; siemens: name -> ``INPUTn``/``OUTPUTn``."""
    warnings: tuple[Diagnostic, ...] = ()


def read_kb(path: Path, format: str | None = None) -> KnowledgeBaseSource:
    """Read a knowledge-base file; the format comes from ``format`` or the extension."""
    from fuzzyctl import formats

    fmt = formats.get(format) if format else formats.for_path(path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise FuzzyctlError(f"{path}: cannot read the knowledge base: {exc.strerror or exc}") from exc
    return KnowledgeBaseSource(formats.decode(data), fmt.name, str(path))


@functools.lru_cache(maxsize=8)
def _parse(text: str, format: str, path: str | None) -> Document:
    """The model of a knowledge-base text.  Cached: a configuration often runs many
    instances of one file, and a model is immutable (each instance still gets its own
    block, with its own state)."""
    from fuzzyctl import formats

    return formats.read_text(text, format, path=path).document


def prepare_kb(
    source: KnowledgeBaseSource, style: str, *, check_profile: bool = True, span_rule: bool = True
) -> PreparedKB:
    """Parse, check and build the block object of a knowledge base.  Raises
    DiagnosticError (with file:line:column diagnostics) or FuzzyctlError."""
    path = source.origin if source.origin != "api" else None
    document = _parse(source.text, source.format, path)
    fb = document.main
    inputs = tuple(v.name for v in fb.inputs)
    outputs = tuple(v.name for v in fb.outputs)
    if style == "siemens":
        from fuzzyctl.blocks.siemens import FuzzyFB

        block = FuzzyFB(document, check_profile=check_profile)
        warnings = tuple(block.diagnostics)
        labels = {n: f"INPUT{i}" for i, n in enumerate(inputs, 1)} | {
            n: f"OUTPUT{i}" for i, n in enumerate(outputs, 1)
        }
        return PreparedKB(source, document, block, inputs, outputs, labels, warnings)
    if style != "xfuz":
        raise FuzzyctlError(f"unknown block style {style!r} (siemens or xfuz)")
    from fuzzyctl.formats.xfuz.reader import read_tables
    from fuzzyctl.formats.xfuz.tables import decode_kb
    from fuzzyctl.formats.xfuz.writer import constants_from_model, slot_labels

    diags: list[Diagnostic] = []
    if source.format == "xfuz":
        constants = read_tables(source.text, path=path)
    else:
        constants, diags = constants_from_model(document)
        if any(d.is_error for d in diags):
            raise DiagnosticError(diags, source.text)
    kb = decode_kb(constants, span_rule=span_rule)
    if kb.error_bits:
        raise FuzzyctlError(
            f"{source.origin}: the XFUZ block would refuse this knowledge base (STATUS error bits "
            + ", ".join(str(b) for b in sorted(kb.error_bits))
            + "):\n"
            + "\n".join(f"  {i.location}: {i.message}" for i in kb.issues)
        )
    labels = slot_labels(document)
    return PreparedKB(source, document, constants, inputs, outputs, labels, tuple(diags))
