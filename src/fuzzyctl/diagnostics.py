"""Diagnostics shared by every reader and checker.

A diagnostic prints as ``file:line:col: error|warning: message`` followed by the source
line and a caret under the column, the format compilers use, so editors can jump to it.
``to_dict`` gives the same content for ``--json`` output.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from enum import StrEnum
from typing import TYPE_CHECKING, Any, TypedDict, Unpack

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
            line = source_line(source, self.span.line)
        if line is not None and self.span is not None:
            width = 1
            if self.span.end_line == self.span.line and self.span.end_column:
                width = max(self.span.end_column - self.span.column, 1)
            shown, caret_col, width = _window(line.expandtabs(1).rstrip("\r\n"), self.span.column - 1, width)
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


#: How many diagnostics :meth:`DiagnosticError.render` and the CLI print for one file; the
#: rest are counted in a last line ("... and N more").
MAX_DIAGNOSTICS_SHOWN = 20
#: Widest source line shown under a diagnostic (a window around the column).
MAX_LINE_SHOWN = 120

_LINES: tuple[str, list[str]] | None = None


def source_line(source: str, number: int) -> str | None:
    """Line ``number`` (1-based; lines end at ``\\n`` as every reader counts them) of
    ``source``.  The text is split once and kept for the next call with the same text, so
    rendering many diagnostics of one file is linear, not quadratic."""
    global _LINES
    cached = _LINES
    if cached is None or cached[0] is not source:
        cached = (source, source.split("\n"))
        _LINES = cached
    lines = cached[1]
    return lines[number - 1] if 1 <= number <= len(lines) else None


def _window(line: str, col: int, width: int) -> tuple[str, int, int]:
    """At most :data:`MAX_LINE_SHOWN` characters of ``line`` around column ``col`` (0-based),
    the caret column in that window and the underline width that fits in it."""
    col = max(col, 0)
    if len(line) <= MAX_LINE_SHOWN:
        return line, col, width
    start = max(0, min(col - MAX_LINE_SHOWN // 3, len(line) - MAX_LINE_SHOWN))
    piece = line[start : start + MAX_LINE_SHOWN]
    prefix = "..." if start > 0 else ""
    suffix = "..." if start + MAX_LINE_SHOWN < len(line) else ""
    caret = col - start + len(prefix)
    return prefix + piece + suffix, caret, max(1, min(width, MAX_LINE_SHOWN - (col - start)))


def select_shown(
    diagnostics: Sequence[Diagnostic], limit: int = MAX_DIAGNOSTICS_SHOWN
) -> tuple[list[Diagnostic], list[Diagnostic]]:
    """``(shown, left out)``: at most ``limit`` diagnostics, errors chosen first, the shown
    ones in file order."""
    items = list(diagnostics)
    if len(items) <= limit:
        return items, []
    errors = [i for i, d in enumerate(items) if d.is_error]
    others = [i for i, d in enumerate(items) if not d.is_error]
    kept = set((errors + others)[:limit])
    return [d for i, d in enumerate(items) if i in kept], [d for i, d in enumerate(items) if i not in kept]


def more_line(rest: Sequence[Diagnostic]) -> str:
    """The last line after a capped list: how many were left out, and how many errors."""
    n_err = sum(1 for d in rest if d.is_error)
    return f"... and {len(rest)} more diagnostic(s) not shown ({n_err} error(s), {len(rest) - n_err} other)"


def render_all(
    diagnostics: Sequence[Diagnostic], source: str | None = None, limit: int = MAX_DIAGNOSTICS_SHOWN
) -> list[str]:
    """The rendered diagnostics (at most ``limit``, see :func:`select_shown`) and, when some
    were left out, a last line counting them."""
    shown, rest = select_shown(diagnostics, limit)
    return [d.render(source) for d in shown] + ([more_line(rest)] if rest else [])


class Where(TypedDict, total=False):
    """The keywords :func:`error` and :func:`warning` take (the :class:`Diagnostic` fields
    of the same names; left out: their defaults)."""

    code: str
    file: str | None
    hint: str | None


def error(message: str, span: Span | None = None, **where: Unpack[Where]) -> Diagnostic:
    return Diagnostic(Severity.ERROR, message, span, **where)


def warning(message: str, span: Span | None = None, **where: Unpack[Where]) -> Diagnostic:
    return Diagnostic(Severity.WARNING, message, span, **where)


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

    def render(self, limit: int = MAX_DIAGNOSTICS_SHOWN) -> str:
        """Every diagnostic (at most ``limit`` of them, then a line counting the others)."""
        return "\n".join(render_all(self.diagnostics, self.source, limit))


class OptionError(FuzzyctlError):
    """Options that do not go together, or an option's value the library refuses before it
    starts; ``option`` names it (``--lang``), as the CLI's usage error does."""

    def __init__(self, message: str, option: str) -> None:
        super().__init__(message)
        self.option = option


class InputError(FuzzyctlError, ValueError):
    """A bad value given to an evaluation (missing input, NaN, not a number); the message
    names the parameter."""


def apart(a: float, b: float, digits: int = 3) -> tuple[str, str]:
    """``a`` and ``b`` written with ``digits`` significant digits, or more where that is what
    tells them apart: a message comparing a bound with a limit it misses by a hair must not
    read "1% exceeds 1%".  The two texts are the same only when the numbers are."""
    for d in range(digits, 18):  # 17 significant digits tell any two doubles apart
        first, second = f"{a:.{d}g}", f"{b:.{d}g}"
        if first != second or a == b:
            return first, second
    return repr(a), repr(b)  # NaN: nothing to align
