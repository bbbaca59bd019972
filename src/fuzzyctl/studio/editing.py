"""Editing aids that need the FCL parser: the rule text editor and terms written as FCL.

Both read what the user typed with the parser and the checks of the FCL text (one
language, one set of diagnostics): the typed lines are placed into the FCL of the edited
function block, the whole text is checked as ``fuzzyctl check`` would, and the
diagnostics that fall on the typed lines are handed back with the line and column *of the
typed text*.

* **Rules**: one rule per line, ``IF ... THEN ...`` with OR, NOT, parentheses, hedges,
  several conclusions and WITH weights; ``RULE label :`` in front keeps a label, other
  lines are numbered by their position (the next free number when that label is taken).
* **A term**: the right-hand side of ``TERM name := ...;`` in any spelling the parser
  reads (points, a singleton, ``GAUSS 0 2``, ``FUNCTION ...``).
"""

from __future__ import annotations

import hashlib
import re
import secrets
import threading
from collections import OrderedDict
from dataclasses import dataclass, replace
from typing import Any

from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.fcl.no_if import always_name
from fuzzyctl.formats.json.writer import encode
from fuzzyctl.model import Degree, Document, FunctionBlock, SingletonMF, Term, Variable, VarKind
from fuzzyctl.studio import analysis

_LABELLED = re.compile(r"^\s*RULE\s+(\w+)\s*:", re.IGNORECASE)
_LABEL_OF_PREFIX = re.compile(r"RULE (\w+) : ")
_COMMENT_LINE = re.compile(r"^\s*(//|\(\*|/\*)")


def strip_spans(data: Any) -> Any:
    """JSON of model objects without source positions (they would point into the
    synthetic text the typed lines were checked in)."""
    if isinstance(data, dict):
        return {k: strip_spans(v) for k, v in data.items() if k not in ("span", "item_spans")}
    if isinstance(data, list):
        return [strip_spans(v) for v in data]
    return data


@dataclass(frozen=True)
class _Placed:
    """Typed lines placed into FCL text: ``first`` is the 1-based line of the first typed
    line, ``prefixes[i]`` what was written before typed line ``i``."""

    text: str
    first: int
    prefixes: list[str]

    def locate(self, diagnostic: dict[str, Any]) -> dict[str, Any] | None:
        """The diagnostic with line and column in the typed text, or None when it is about
        another part of the function block."""
        line = diagnostic.get("line")
        if not isinstance(line, int):
            return None
        index = line - self.first
        if not 0 <= index < len(self.prefixes):
            return None
        shift = len(self.prefixes[index])
        out = dict(diagnostic)
        out["line"] = index + 1
        column = diagnostic.get("column")
        out["column"] = max(1, column - shift) if isinstance(column, int) else None
        end_line = diagnostic.get("end_line")
        if isinstance(end_line, int) and 0 <= end_line - self.first < len(self.prefixes):
            out["end_line"] = end_line - self.first + 1
            end_column = diagnostic.get("end_column")
            end_shift = len(self.prefixes[end_line - self.first])
            out["end_column"] = max(1, end_column - end_shift) if isinstance(end_column, int) else None
        else:
            out["end_line"] = out["line"]
            out["end_column"] = None
        out["element"] = None
        return out


def _labels(lines: list[str]) -> tuple[list[str], list[int]]:
    """The prefix of each typed line (``RULE n : `` for a rule without a label) and the
    line numbers (1-based) of the rules."""
    explicit = {m.group(1) for line in lines if (m := _LABELLED.match(line))}
    taken = set(explicit)
    prefixes: list[str] = []
    rule_lines: list[int] = []
    position = 0
    closing: str | None = None  # the end of a comment that spans lines
    for i, line in enumerate(lines):
        stripped = line.strip()
        if closing is not None:
            prefixes.append("")
            if closing in line:
                closing = None
            continue
        if not stripped or _COMMENT_LINE.match(line):
            prefixes.append("")
            for start, end in (("(*", "*)"), ("/*", "*/")):
                if stripped.startswith(start) and end not in stripped[2:]:
                    closing = end
            continue
        position += 1
        rule_lines.append(i + 1)
        if _LABELLED.match(line):
            prefixes.append("")
            continue
        number = position
        while str(number) in taken:
            number += 1
        taken.add(str(number))
        prefixes.append(f"RULE {number} : ")
    return prefixes, rule_lines


class _LineCache:
    """Rules already read, by (function block without its rules, typed line): editing one
    line of a 500-rule block re-reads that line only.  Least recently used out first."""

    def __init__(self, size: int = 20000) -> None:
        self.size = size
        self._items: OrderedDict[tuple[str, str], tuple[Any, list[dict[str, Any]]]] = OrderedDict()
        self._lock = threading.Lock()

    def get(self, key: tuple[str, str]) -> tuple[Any, list[dict[str, Any]]] | None:
        with self._lock:
            if key in self._items:
                self._items.move_to_end(key)
                return self._items[key]
        return None

    def put(self, key: tuple[str, str], value: tuple[Any, list[dict[str, Any]]]) -> None:
        with self._lock:
            self._items[key] = value
            while len(self._items) > self.size:
                self._items.popitem(last=False)


_LINES = _LineCache()


def _mentions(condition: Any, name: str) -> bool:
    """Whether a condition (JSON form) reads variable ``name``."""
    if isinstance(condition, dict):
        if condition.get("variable") == name:
            return True
        return any(_mentions(v, name) for v in condition.values())
    if isinstance(condition, list):
        return any(_mentions(v, name) for v in condition)
    return False


def parse_rules(fb: FunctionBlock, rule_block: int, text: str) -> dict[str, Any]:
    """The rules of ``text`` (one per line) as rule block ``rule_block`` of ``fb``:
    ``{"ok", "rules", "lines", "diagnostics"}``; ``rules`` is None when a line has an
    error.  Lines are read in the function block with this rule block alone (its
    declarations, terms and operators); lines read before are taken from a cache, so the
    checks that compare rules with each other (a label used twice) come with the check of
    the whole model, not here."""
    if not 0 <= rule_block < len(fb.rule_blocks):
        raise FuzzyctlError(f"rule block {rule_block}: the function block has {len(fb.rule_blocks)}")
    block = fb.rule_blocks[rule_block]
    # a rule without an IF part (Siemens 1.5) is typed as FCL writes it, IF ALWAYS THEN:
    # the lines are read with that always-1 input declared, and turned back into rules
    # without a condition (fcl/no_if.py)
    always = always_name(fb)
    declared = Variable(always, VarKind.INPUT, "REAL", 1.0)
    skeleton = replace(
        fb,
        variables=(*fb.variables, declared),
        rule_blocks=(replace(block, rules=(), comments=(), placed_comments=()),),
        options=(),
    )
    written = analysis.fcl_text(Document((skeleton,))).split("\n")
    context = hashlib.sha256("\n".join(written).encode("utf-8")).hexdigest()
    end = max(i for i, line in enumerate(written) if line.strip().upper() == "END_RULEBLOCK")
    typed = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    prefixes, rule_lines = _labels(typed)
    # a rule is cached as typed, with the comment lines before it (they become its
    # comments); the label a prefix gives is set when it is taken out, so inserting a line
    # above (which renumbers the rest) re-reads only the new line
    leads: dict[int, range] = {}
    previous = 0
    for i in rule_lines:
        leads[i] = range(previous, i - 1)  # 0-based indices of the lines before rule line i
        previous = i
    keys = {i: (context, "\n".join(typed[k] for k in (*leads[i], i - 1))) for i in rule_lines}
    known = {i: _LINES.get(keys[i]) for i in rule_lines}
    missing = [i for i in rule_lines if known[i] is None]
    diagnostics: list[dict[str, Any]] = []
    syntax_error = False
    if missing:
        # the rules not read before (and their comments), each at its own line number
        inserted = ["" for _ in typed]
        for i in missing:
            for k in leads[i]:
                inserted[k] = typed[k]
            inserted[i - 1] = prefixes[i - 1] + typed[i - 1]
        placed = _Placed("\n".join([*written[:end], *inserted, *written[end:]]), end + 1, prefixes)
        report = analysis.check_text(placed.text)
        found = [d for d in (placed.locate(x) for x in report.diagnostics) if d is not None]
        diagnostics.extend(found)
        if report.parsed is None:
            syntax_error = True
        else:
            parsed = report.parsed.main.rule_blocks[0].rules
            for i, rule in zip(missing, parsed, strict=True):
                own = [d for d in found if d["line"] == i]
                if isinstance(rule.condition, Degree) and rule.condition.variable == always:
                    rule = replace(rule, condition=None)
                elif rule.condition is not None and _mentions(encode(rule.condition), always):
                    message = f"{always} stands alone (IF {always} THEN: a rule without an IF part)"
                    own.append({"severity": "error", "message": message, "line": i, "column": None})
                    diagnostics.append(own[-1])
                value = (strip_spans(encode(rule)), own)
                _LINES.put(keys[i], value)
                known[i] = value
    for i in rule_lines:
        cached = known[i]
        if cached is not None and i not in missing:
            diagnostics.extend({**d, "line": i, "end_line": i} for d in cached[1])
    diagnostics.sort(key=lambda d: (d["line"], d.get("column") or 0))
    errors = syntax_error or any(d["severity"] == "error" for d in diagnostics)
    rules: list[dict[str, Any]] | None = None
    if not errors:
        rules = []
        for i in rule_lines:
            entry = known[i]
            assert entry is not None  # read now or before, and no error
            item: dict[str, Any] = dict(entry[0])
            label = _LABEL_OF_PREFIX.match(prefixes[i - 1])
            if label is not None:
                item["label"] = label.group(1)
            rules.append(item)
    return {"ok": rules is not None, "rules": rules, "lines": rule_lines, "diagnostics": diagnostics}


def parse_term(fb: FunctionBlock, variable: str, text: str) -> dict[str, Any]:
    """A membership function written as FCL (the part after ``:=``) for a term of
    ``variable``: ``{"ok", "mf", "diagnostics"}`` (``mf`` in the model's JSON form, None
    on errors)."""
    if "\n" in text.strip():
        raise FuzzyctlError("write the term on one line")
    body = text.strip().removesuffix(";").strip()
    if not body:
        raise FuzzyctlError("the term is empty")
    sentinel = f"studio_term_{secrets.token_hex(6)}"
    fuzzify = fb.fuzzify_block(variable)
    defuzzify = fb.defuzzify_block(variable)
    if fuzzify is None and defuzzify is None:
        raise FuzzyctlError(f"{variable!r} has no FUZZIFY or DEFUZZIFY block")
    probe = Term(sentinel, SingletonMF(0.0))
    skeleton = replace(
        fb,
        rule_blocks=(),
        options=(),
        fuzzify=tuple(replace(b, terms=(*b.terms, probe)) if b is fuzzify else b for b in fb.fuzzify),
        defuzzify=tuple(replace(b, terms=(*b.terms, probe)) if b is defuzzify else b for b in fb.defuzzify),
    )
    written = analysis.fcl_text(Document((skeleton,))).split("\n")
    at = next(i for i, line in enumerate(written) if f"TERM {sentinel} :=" in line)
    prefix = written[at][: written[at].index("TERM")] + f"TERM {sentinel} := "
    written[at] = prefix + body + ";"
    placed = _Placed("\n".join(written), at + 1, [prefix])
    report = analysis.check_text(placed.text)
    diagnostics = [d for d in (placed.locate(x) for x in report.diagnostics) if d is not None]
    mf = None
    errors = any(d["severity"] == "error" for d in diagnostics)
    if report.parsed is not None and not errors:
        main = report.parsed.main
        blk = main.fuzzify_block(variable) or main.defuzzify_block(variable)
        term = blk.term(sentinel) if blk is not None else None
        if term is not None:
            mf = strip_spans(encode(term.mf))
    return {"ok": mf is not None, "mf": mf, "diagnostics": diagnostics}
