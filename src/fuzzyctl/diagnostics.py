"""Diagnostics shared by every reader and checker.

A diagnostic prints as ``file:line:col: error|warning: message`` followed by the source
line and a caret under the column, the format compilers use, so editors can jump to it.
``to_dict`` gives the same content for ``--json`` output.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from enum import StrEnum
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # the model is imported by whoever makes a diagnostic with a span
    from fuzzyctl.model import Span


class Severity(StrEnum):
    ERROR = "error"
    WARNING = "warning"
    NOTE = "note"


@dataclass(frozen=True)
class Diagnostic:
    """One finding about a source file.

    ``code`` is a short stable identifier (``"undeclared-variable"``) that tests and tools
    can match on; ``message`` is for people."""

    severity: Severity
    message: str
    span: Span | None = None
    file: str | None = None
    code: str = ""
    hint: str | None = None
    source_line: str | None = field(default=None, compare=False)

    @property
    def is_error(self) -> bool:
        return self.severity is Severity.ERROR

    def location(self) -> str:
        where = self.file or "<input>"
        if self.span is not None:
            where += f":{self.span.line}:{self.span.column}"
        return where

    def render(self, source: str | None = None) -> str:
        """The compiler-style text: location, severity, message, source line and caret."""
        text = f"{self.location()}: {self.severity.value}: {self.message}"
        line = self.source_line
        if line is None and source is not None and self.span is not None:
            lines = source.splitlines()
            if 1 <= self.span.line <= len(lines):
                line = lines[self.span.line - 1]
        if line is not None and self.span is not None:
            shown = line.expandtabs(1).rstrip("\r\n")
            caret_col = max(self.span.column - 1, 0)
            width = 1
            if self.span.end_line == self.span.line and self.span.end_column:
                width = max(self.span.end_column - self.span.column, 1)
            text += f"\n    {shown}\n    {' ' * caret_col}^{'~' * (width - 1)}"
        if self.hint:
            text += f"\n    hint: {self.hint}"
        return text

    def to_dict(self) -> dict[str, Any]:
        return {
            "file": self.file,
            "line": self.span.line if self.span else None,
            "column": self.span.column if self.span else None,
            "severity": self.severity.value,
            "code": self.code,
            "message": self.message,
            "hint": self.hint,
        }


def error(
    message: str,
    span: Span | None = None,
    *,
    code: str = "",
    file: str | None = None,
    hint: str | None = None,
) -> Diagnostic:
    return Diagnostic(Severity.ERROR, message, span, file, code, hint)


def warning(
    message: str,
    span: Span | None = None,
    *,
    code: str = "",
    file: str | None = None,
    hint: str | None = None,
) -> Diagnostic:
    return Diagnostic(Severity.WARNING, message, span, file, code, hint)


def has_errors(diagnostics: Iterable[Diagnostic]) -> bool:
    return any(d.is_error for d in diagnostics)


class FuzzyctlError(Exception):
    """Base of every error fuzzyctl raises on purpose.  The CLI prints these without a
    traceback; anything else reaching the CLI is a bug in fuzzyctl."""


class DiagnosticError(FuzzyctlError):
    """Raised when a file cannot be loaded; carries every diagnostic found."""

    def __init__(self, diagnostics: Sequence[Diagnostic], source: str | None = None) -> None:
        self.diagnostics = list(diagnostics)
        self.source = source
        first = next((d for d in self.diagnostics if d.is_error), None)
        super().__init__(first.render(source) if first else "invalid input")

    def render(self) -> str:
        return "\n".join(d.render(self.source) for d in self.diagnostics)


class InputError(FuzzyctlError, ValueError):
    """A bad value given to an evaluation (missing input, NaN, not a number); the message
    names the parameter."""
