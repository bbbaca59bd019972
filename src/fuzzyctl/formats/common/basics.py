"""Pieces the FIS and FLL readers and writers share: numbers, names, diagnostics."""

from __future__ import annotations

import math
import re
from collections.abc import Iterable

from fuzzyctl.diagnostics import Diagnostic, DiagnosticError, error, warning
from fuzzyctl.fcl.numbers import number_text
from fuzzyctl.model import (
    POWER_HEDGE_PREFIX,
    Conclusion,
    DefuzzifyBlock,
    FunctionBlock,
    FuzzifyBlock,
    Param,
    Ref,
    Span,
    Term,
)


def fmt_number(value: float) -> str:
    """The shortest text that reads back as exactly ``value`` (``1`` not ``1.0``): FCL's
    spelling of numbers, which every text format here shares."""
    return number_text(float(value))


def parse_number(text: str) -> float:
    """A number as MATLAB and fuzzylite write them (``1.5``, ``-Inf``, ``NaN``, ``1e-3``)."""
    try:
        value = float(text)  # the common case, at once
    except ValueError:
        pass
    else:
        if not math.isinf(value):
            return value
    lowered = text.strip().lower()
    if lowered in {"inf", "+inf", "infinity"}:
        return math.inf
    if lowered in {"-inf", "-infinity"}:
        return -math.inf
    if lowered == "nan":
        return math.nan
    value = float(lowered)  # raises ValueError: the caller reports where
    if math.isinf(value):  # 1e400, 5001 digits: not the infinity the file would spell inf
        raise ValueError(f"{text.strip()[:24]} is too large (beyond 1.8e308)")
    return value


def parse_count(text: str) -> int:
    """A count (``NumMFs=3``, ``NumRules=9``): a whole number from 0 to 10**9; ValueError
    for anything else (``Infinity``, ``NaN``, ``2.5``, ``-1``, 5001 digits), which the caller
    reports with its place."""
    value = parse_number(text)
    if not (math.isfinite(value) and 0 <= value <= 1e9 and value == int(value)):
        raise ValueError(f"not a count: {text!r}")
    return int(value)


_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


def is_identifier(name: str) -> bool:
    return bool(_IDENT.match(name))


def identifier(name: str, taken: set[str]) -> str:
    """A valid, unused identifier close to ``name`` (``LDL-Level`` -> ``LDL_Level``)."""
    base = re.sub(r"[^A-Za-z0-9_]", "_", name.strip()) or "x"
    if base[0].isdigit():
        base = "_" + base
    candidate, n = base, 2
    while candidate in taken:
        candidate, n = f"{base}_{n}", n + 1
    taken.add(candidate)
    return candidate


def unique_name(name: str, taken: set[str]) -> str:
    """``name`` itself when free, else ``name_2``, ``name_3``, ..."""
    candidate, n = name, 2
    while candidate in taken:
        candidate, n = f"{name}_{n}", n + 1
    taken.add(candidate)
    return candidate


def power_hedge(power: float) -> str:
    return f"{POWER_HEDGE_PREFIX}{fmt_number(power)}"


def hedge_power(hedge: str) -> float | None:
    """The exponent of a power hedge (``very`` is 2, ``somewhat`` 0.5), else None."""
    if hedge == "very":
        return 2.0
    if hedge == "somewhat":
        return 0.5
    if hedge.startswith(POWER_HEDGE_PREFIX):
        try:
            return float(hedge[len(POWER_HEDGE_PREFIX) :])
        except ValueError:
            return None
    return None


def constant(p: Param) -> float | None:
    """The literal value of a parameter, None when it is a variable reference."""
    return None if isinstance(p, Ref) else float(p)


class Reporter:
    """Collects diagnostics for one file and raises them together."""

    def __init__(self, path: str | None, lines: list[str]) -> None:
        self.path = path
        self.lines = lines
        self.items: list[Diagnostic] = []

    def _line(self, line: int) -> str | None:
        return self.lines[line - 1] if 1 <= line <= len(self.lines) else None

    def span(self, line: int, column: int = 1, width: int = 0) -> Span:
        text = self._line(line) or ""
        if column == 1 and width == 0:
            stripped = text.lstrip()
            column = len(text) - len(stripped) + 1
            width = len(stripped.rstrip())
        return Span(line, column, line, column + max(width, 1))

    def error(self, message: str, line: int | None, *, code: str, column: int = 1, width: int = 0) -> None:
        span = self.span(line, column, width) if line else None
        self.items.append(error(message, span, code=code, file=self.path))

    def warning(self, message: str, line: int | None, *, code: str, column: int = 1, width: int = 0) -> None:
        span = self.span(line, column, width) if line else None
        self.items.append(warning(message, span, code=code, file=self.path))

    def fail(
        self, message: str, line: int | None, *, code: str, column: int = 1, width: int = 0
    ) -> DiagnosticError:
        """Record an error and return the exception to raise at once."""
        self.error(message, line, code=code, column=column, width=width)
        return self.exception()

    def exception(self) -> DiagnosticError:
        return DiagnosticError(self.items, "\n".join(self.lines))

    def raise_if_errors(self) -> None:
        if any(d.is_error for d in self.items):
            raise self.exception()

    @property
    def warnings(self) -> tuple[Diagnostic, ...]:
        return tuple(d for d in self.items if not d.is_error)


def term_of(block: FuzzifyBlock | DefuzzifyBlock | None, name: str | None) -> Term | None:
    return block.term(name) if block is not None and name is not None else None


def output_blocks(fb: FunctionBlock) -> dict[str, DefuzzifyBlock]:
    return {d.variable: d for d in fb.defuzzify}


def input_blocks(fb: FunctionBlock) -> dict[str, FuzzifyBlock]:
    return {f.variable: f for f in fb.fuzzify}


def conclusions_of(fb: FunctionBlock) -> Iterable[Conclusion]:
    for _, rule in fb.rules():
        yield from rule.conclusions
