"""The public facade: ``load()`` a fuzzy system from any supported format and
``compile()`` it into something that evaluates."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.model import Document, FunctionBlock


def load(path_or_text: str | Path, *, format: str | None = None) -> Document:
    """Read a fuzzy system from a file path or from source text.

    ``format`` (``"fcl"``, ...) overrides detection by file extension; text that is not an
    existing path is parsed as FCL unless ``format`` says otherwise.  Raises
    :class:`fuzzyctl.diagnostics.DiagnosticError` with file:line:column diagnostics when the
    input is not valid."""
    from fuzzyctl import formats

    if isinstance(path_or_text, Path) or (
        isinstance(path_or_text, str) and "\n" not in path_or_text and Path(path_or_text).is_file()
    ):
        return formats.read_path(path_or_text, format).document
    return formats.read_text(str(path_or_text), format or "fcl").document


def compile(
    model: Document | FunctionBlock, *, block: str | None = None, backend: str = "python", **options: Any
) -> Any:
    """Turn a model into an evaluator (see ``fuzzyctl.engine``)."""
    raise FuzzyctlError("no engine is available yet")
