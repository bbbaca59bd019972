"""Limits on what fuzzyctl reads, so that no input can take unbounded time or memory.

* :func:`max_input_bytes` - the largest model file read, per format (each format's
  entry in the registry's table, :mod:`fuzzyctl.formatspec`): 1.5 MiB of FCL or FLL (the
  10,000-rule 8-input system is 1.31 / 1.19 MiB), 512 KiB of FIS, 1 MiB of FPL and of
  XFUZ, 96 MiB of JSON (which spells out every span: that 10,000-rule system is 43.5 MB of
  JSON).
  ``FUZZYCTL_MAX_INPUT_BYTES`` sets one limit for every format.  A larger file is refused
  before it is read, with a diagnostic saying the size and the limit; reading time is
  linear in the size below it.
* :data:`MAX_DIAGNOSTICS_SHOWN` - how many diagnostics the CLI prints per file; the rest
  are summarised as "N more".
* :data:`MAX_NESTING` - how deep conditions and expressions may nest (a rule with more
  than that many nested NOTs, ANDs in ORs or parentheses is refused with its place, never
  a RecursionError); JSON may nest :data:`MAX_JSON_DEPTH` levels.
* :data:`MAX_DIGITS` - the longest number literal read (Python refuses to convert
  integers over 4300 digits; a literal that long is an error with its place).
  :func:`load_json` reads JSON under both limits for every JSON reader (the model's and the
  XFUZ tables').

The limits are documented in docs/limits.md.
"""
# MAX_DIAGNOSTICS_SHOWN lives in fuzzyctl.diagnostics (the renderer uses it); re-exported here.

from __future__ import annotations

import json
import math
import os
import re
import stat
import sys
from pathlib import Path
from typing import Any

from fuzzyctl import model as m
from fuzzyctl.diagnostics import MAX_DIAGNOSTICS_SHOWN, Diagnostic, DiagnosticError, error
from fuzzyctl.formatspec import DEFAULT_MAX_BYTES, SPECS

DEFAULT_MAX_INPUT_BYTES = DEFAULT_MAX_BYTES

MAX_NESTING = 100
MAX_JSON_DEPTH = 2 * MAX_NESTING + 40  # a condition's levels are two JSON levels each
MAX_DIGITS = 400


__all__ = [
    "DEFAULT_MAX_INPUT_BYTES",
    "MAX_DIAGNOSTICS_SHOWN",
    "MAX_DIGITS",
    "MAX_JSON_DEPTH",
    "MAX_NESTING",
    "check_document",
    "check_text",
    "depth",
    "expr_depth",
    "load_json",
    "max_input_bytes",
    "read_input",
    "shorten",
    "too_large",
]


def shorten(text: str, limit: int = 24, keep: int = 20) -> str:
    """``text`` as a message quotes it: whole up to ``limit`` characters, else its first
    ``keep`` and its length (a diagnostic never echoes a long piece of the input)."""
    return text if len(text) <= limit else f"{text[:keep]}... ({len(text)} characters)"


def max_input_bytes(format: str | None = None) -> int:
    """The size limit of a model file of ``format`` in bytes (``FUZZYCTL_MAX_INPUT_BYTES``
    when set, else :data:`DEFAULT_MAX_INPUT_BYTES` or the format's own)."""
    value = os.environ.get("FUZZYCTL_MAX_INPUT_BYTES", "")
    try:
        limit = int(value)
    except ValueError:
        limit = 0
    if limit > 0:
        return limit
    spec = SPECS.get((format or "").lower().lstrip("."))
    return DEFAULT_MAX_INPUT_BYTES if spec is None else spec.max_bytes


def _mib(n: int) -> str:
    return f"{n / (1024 * 1024):.1f} MiB" if n >= 1024 * 1024 else f"{n} bytes"


def too_large(size: int, path: str | None, format: str | None = None) -> DiagnosticError:
    limit = max_input_bytes(format)
    what = f"{format.upper()} files" if format else "model files"
    return DiagnosticError(
        [
            error(
                f"the file is {_mib(size)}, over the {_mib(limit)} limit for {what}",
                file=path,
                code="too-large",
                hint="set FUZZYCTL_MAX_INPUT_BYTES to read larger files",
            )
        ]
    )


def _unreadable(exc: OSError, name: str) -> DiagnosticError:
    return DiagnosticError([error(f"cannot read: {exc.strerror or exc}", file=name, code="unreadable")])


def read_input(path: str | os.PathLike[str], format: str | None = None) -> bytes:
    """The bytes of a model file, or :class:`DiagnosticError` for a missing file, a
    directory, an unreadable file or one over :func:`max_input_bytes` (checked before
    reading; a pipe or device is read up to the limit and no further)."""
    p = Path(path)
    name = str(path)
    try:
        st = p.stat()
    except FileNotFoundError:
        raise DiagnosticError([error("no such file", file=name, code="no-file")]) from None
    except OSError as exc:
        raise _unreadable(exc, name) from None
    if stat.S_ISDIR(st.st_mode):
        what = f"an {format.upper()} file" if format else "a model file"
        raise DiagnosticError([error(f"is a directory, not {what}", file=name, code="is-directory")])
    limit = max_input_bytes(format)
    if stat.S_ISREG(st.st_mode) and st.st_size > limit:
        raise too_large(st.st_size, name, format)
    try:
        with p.open("rb") as handle:
            data = handle.read(limit + 1)
    except OSError as exc:
        raise _unreadable(exc, name) from None
    if len(data) > limit:
        raise too_large(len(data), name, format)
    return data


def check_text(text: str, path: str | None = None, format: str | None = None) -> None:
    """Refuse source text over the size limit of ``format`` (in UTF-8 bytes; the encoding is
    only measured when the length leaves a doubt)."""
    limit = max_input_bytes(format)
    if len(text) > limit or (len(text) * 4 > limit and len(text.encode("utf-8", "surrogatepass")) > limit):
        raise too_large(len(text.encode("utf-8", "surrogatepass")), path, format)


def depth(node: object) -> int:
    """How deep a condition or an expression nests (``a IS b``: 1, ``NOT (a IS b)``: 2; a
    chain ``x + y + z`` counts each operator), computed without recursion so that any tree
    can be measured."""
    if isinstance(node, m.Is | m.Degree):
        return 1
    if isinstance(node, m.And | m.Or) and all(isinstance(o, m.Is | m.Degree) for o in node.operands):
        return 2  # the common rule, measured without the stack
    deepest = 0
    stack = [(node, 1)]
    while stack:
        item, level = stack.pop()
        deepest = max(deepest, level)
        if isinstance(item, m.Not | m.Unary):
            stack.append((item.operand, level + 1))
        elif isinstance(item, m.And | m.Or):
            stack.extend((o, level + 1) for o in item.operands)
        elif isinstance(item, m.Binary):
            stack.append((item.left, level + 1))
            stack.append((item.right, level + 1))
        elif isinstance(item, m.Call):
            stack.extend((a, level + 1) for a in item.args)
    return deepest


expr_depth = depth


def check_document(document: m.Document, path: str | None = None) -> list[Diagnostic]:
    """What every reader refuses, whatever the format says: a rule condition or function
    term nesting deeper than :data:`MAX_NESTING` (it would overflow the stack of every later
    step) and a RANGE with a NaN bound (``RANGE := (nan .. 100)``: no value is inside it)."""
    out: list[Diagnostic] = []
    for fb in document.blocks:
        for owner, rng in _ranges(fb):
            if math.isnan(rng.low) or math.isnan(rng.high):
                out.append(
                    error(
                        f"{owner}: RANGE ({rng.low:g} .. {rng.high:g}) has a bound that is not a number",
                        rng.span,
                        code="range-nan",
                        file=path,
                    )
                )
        for _block, rule in fb.rules():
            if rule.condition is not None and (d := depth(rule.condition)) > MAX_NESTING:
                out.append(
                    error(
                        f"rule {rule.label}: the condition nests {d} levels deep "
                        f"(the limit is {MAX_NESTING})",
                        rule.span,
                        code="too-deep",
                        file=path,
                    )
                )
        blocks: tuple[m.FuzzifyBlock | m.DefuzzifyBlock, ...] = (*fb.fuzzify, *fb.defuzzify)
        for block in blocks:
            for term in block.terms:
                mf = term.mf
                if isinstance(mf, m.FunctionMF) and (d := depth(mf.expr)) > MAX_NESTING:
                    out.append(
                        error(
                            f"term {term.name}: the function nests {d} levels deep "
                            f"(the limit is {MAX_NESTING})",
                            term.span,
                            code="too-deep",
                            file=path,
                        )
                    )
    return out


def _ranges(fb: m.FunctionBlock) -> list[tuple[str, m.Range]]:
    out = [(f"variable {v.name}", v.range) for v in fb.variables if v.range is not None]
    out += [(f"FUZZIFY {b.variable}", b.range) for b in fb.fuzzify if b.range is not None]
    out += [(f"DEFUZZIFY {b.variable}", b.range) for b in fb.defuzzify if b.range is not None]
    return out


def _line_column(text: str, position: int) -> m.Span:
    line = text.count("\n", 0, position) + 1
    return m.Span(line, position - (text.rfind("\n", 0, position) + 1) + 1)


def _deep_position(text: str) -> int:
    """Where ``text`` opens its (MAX_JSON_DEPTH + 1)-th nested array or object (0 when it
    never does): only called for a document already found too deep."""
    level, in_string, escaped = 0, False, False
    for i, ch in enumerate(text):
        if in_string:
            if escaped:
                escaped = False
            elif ch == "\\":
                escaped = True
            elif ch == '"':
                in_string = False
        elif ch == '"':
            in_string = True
        elif ch in "[{":
            level += 1
            if level > MAX_JSON_DEPTH:
                return i
        elif ch in "]}":
            level -= 1
    return 0


_NUMBER = re.compile(r"-?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?")


class _Spelt(float):
    """A ``NaN`` / ``Infinity`` the JSON text spells out (not a literal that overflowed)."""


def _json_problem(data: Any) -> str | None:
    """``"depth"`` when ``data`` nests deeper than :data:`MAX_JSON_DEPTH`, ``"range"`` when
    it holds a number literal beyond 1.8e308 (read as an infinity or an integer no float
    holds), else ``None`` (measured without recursion: the readers' decoders recurse; only
    containers go on the stack, leaves are tested by their exact type, which is what keeps
    this a fraction of ``json.loads``'s own time)."""
    top = sys.float_info.max
    stack = [(data, 1)]
    while stack:
        item, level = stack.pop()
        if level > MAX_JSON_DEPTH:
            return "depth"
        for value in item.values() if type(item) is dict else item if type(item) is list else ():
            kind = type(value)
            if kind is dict or kind is list:
                stack.append((value, level + 1))
            # an int is compared exactly (no conversion); a float read from a literal is only
            # infinite when it overflowed (spelt NaN / Infinity are _Spelt, not float)
            elif (kind is float or kind is int) and not -top <= value <= top:
                return "range"
    return None


def _large_number(text: str) -> re.Match[str] | None:
    """The first number literal of ``text`` beyond 1.8e308 or :data:`MAX_DIGITS` digits long."""
    for found in _NUMBER.finditer(text):
        literal = found.group()
        if len(literal) > MAX_DIGITS or not math.isfinite(float(literal)):
            return found
    return None


def load_json(text: str, path: str | None = None, code: str = "json-syntax") -> Any:
    """``json.loads(text)`` under the limits every reader has, or :class:`DiagnosticError`
    at the place: invalid JSON (line:column), nesting deeper than :data:`MAX_JSON_DEPTH` (at
    the bracket that goes deeper), a number beyond 1.8e308 (``1e400``, 401 digits: what the
    FCL reader refuses) or of more than :data:`MAX_DIGITS` digits (at the number); ``code``
    is the code of a syntax error.  ``NaN`` and ``Infinity`` spelt out are read as such."""
    problem: str | None
    try:
        data = json.loads(text, parse_constant=lambda name: _Spelt(name.lower().replace("infinity", "inf")))
    except json.JSONDecodeError as exc:
        raise DiagnosticError(
            [error(f"invalid JSON: {exc.msg}", m.Span(exc.lineno, exc.colno), code=code, file=path)], text
        ) from None
    except RecursionError:  # the json module's own limit, far above ours
        problem = "depth"
    except ValueError:  # an integer literal of more than 4300 digits
        problem = "range"
    else:
        problem = _json_problem(data)
    if problem is None:
        return data
    if problem == "depth":
        where = _line_column(text, _deep_position(text))
        message = f"the JSON nests more than {MAX_JSON_DEPTH} levels deep"
        raise DiagnosticError([error(message, where, code="json-depth", file=path)], text)
    found = _large_number(text)
    at = _line_column(text, found.start()) if found else None
    message = f"the number {shorten(found.group()) if found else ''} is too large (beyond 1.8e308)"
    raise DiagnosticError([error(message, at, code="number-range", file=path)], text)
