"""MATLAB / Octave FIS files (versions 1.0-3.0) and fuzzylite's FIS export (6.0).

Reading follows MATLAB's own engine (the Fuzzy Logic Toolbox C sources, ``fiscore.c`` and
``mf.c``): a rule's weight multiplies its firing strength before implication; 0 in a rule
is "don't care"; a negative index is NOT (1 - mu); AND (connection 1) or OR (2) joins the
whole antecedent; when no rule fires an output takes the middle of its range; inputs are
not clamped to their range.  Two dialects differ in details, told apart by the file:

* ``matlab`` (default): fractional rule indices are Octave's hedges, ``2.3`` meaning term 2
  with its degree cubed (Octave's fuzzy-logic-toolkit ``get_mf_index_and_hedge``).
* ``fuzzylite``: a comment before ``[System]`` mentioning fuzzylite, or fuzzylite's own keys
  (``Default``, ``LockPrevious``, ``LockRange``, ``Enabled``).  Hedge codes are fuzzylite's
  (``.01`` seldom, ``.05`` somewhat, ``.2`` very, ``.3`` extremely, ``.4`` very very,
  ``.99`` any), an output without ``Default=`` defaults to NaN, and fuzzylite's extra
  membership types (``rampmf``, ``discretemf``, ``function``, a trailing height) are
  accepted.

The writer lives in :mod:`fuzzyctl.formats.fis.writer`; what both use, in :mod:`.names`.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import TypeVar

from fuzzyctl.diagnostics import DiagnosticError
from fuzzyctl.formats import Loaded
from fuzzyctl.formats.common.basics import Reporter, parse_count, parse_number
from fuzzyctl.formats.common.expr import ExprError, names_in, parse_expr
from fuzzyctl.formats.common.terms import (
    FIS_TS_TYPES,
    FIS_TYPES,
    MATLAB_TYPES,
    MONOTONIC_KINDS,
    fis_shape_problem,
)
from fuzzyctl.formats.fis.names import AGG_METHODS, AND_METHODS, DEFUZZ_METHODS, OR_METHODS
from fuzzyctl.formats.fis.rules import TS_KINDS, is_ts_term, numbers, rules
from fuzzyctl.kinds import methods
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.model import (
    Default,
    DefuzzifyBlock,
    Document,
    FunctionBlock,
    FunctionMF,
    FuzzifyBlock,
    MembershipFunction,
    Point,
    PointsMF,
    Range,
    RuleBlock,
    ShapeMF,
    Term,
    Variable,
    VarKind,
)

#: What a Mamdani output of a file naming a Sugeno-only method computes (MATLAB's centroid).
_CENTROID = methods.spelled("fis")["centroid"]


@dataclass
class _Section:
    header: str
    line: int
    entries: list[tuple[str, str, int]] = field(default_factory=list)  # key, value, line
    rules: list[tuple[str, int]] = field(default_factory=list)

    def get(self, key: str) -> tuple[str, int] | None:
        for k, v, line in self.entries:
            if k == key:
                return v, line
        return None


_SECTION = re.compile(r"\[\s*(System|Input\s*\d+|Output\s*\d+|Rules)\s*\]", re.IGNORECASE)
_KEY_VALUE = re.compile(r"([A-Za-z][A-Za-z0-9_]*)\s*=\s*(.*)$")
_MF = re.compile(r"'([^']*)'\s*:\s*'([^']*)'\s*,\s*\[(.*)\]\s*(?:,\s*(\S+))?\s*$")


# Text outside quotes and whole quoted strings; what follows is a comment, an unclosed
# quote (quoted to the end of the line) or the end.
_CODE = re.compile(r"(?:[^'#%]++|'[^']*+')*+")


def _strip_comment(line: str) -> str:
    """Drop a trailing ``#`` or ``%`` comment that is outside quotes."""
    if "#" not in line and "%" not in line:
        return line
    end = _CODE.match(line).end()  # type: ignore[union-attr]  # matches at least ""
    return line[:end] if end < len(line) and line[end] != "'" else line


def _unquote(value: str) -> str:
    value = value.strip()
    if len(value) >= 2 and value[0] == "'" and value[-1] == "'":
        return value[1:-1]
    return value


def _sections(text: str, rep: Reporter) -> tuple[list[_Section], bool]:
    """Split the file into sections; also tell whether a comment names fuzzylite."""
    sections: list[_Section] = []
    mentions_fuzzylite = False
    current: _Section | None = None
    rule_lines: list[tuple[str, int]] | None = None  # the current section's, in [Rules]
    for number, raw in enumerate(rep.lines, start=1):
        stripped = raw.strip()
        if not stripped:
            continue
        if stripped[0] in "#%" or stripped.startswith("//"):
            if not sections and "fuzzylite" in stripped.lower():
                mentions_fuzzylite = True
            continue
        line = _strip_comment(stripped).strip() if "#" in stripped or "%" in stripped else stripped
        if not line:
            continue
        if line[0] == "[":
            m = _SECTION.fullmatch(line)
            if m is None:
                raise rep.fail(f"unknown section {line}", number, code="fis-syntax")
            current = _Section(re.sub(r"\s+", "", m.group(1)), number)
            sections.append(current)
            rule_lines = current.rules if current.header.lower() == "rules" else None
            continue
        if rule_lines is not None:
            rule_lines.append((line, number))
            continue
        if current is None:
            raise rep.fail("text before the [System] section", number, code="fis-syntax")
        kv = _KEY_VALUE.match(line)
        if kv is None:
            raise rep.fail(f"expected 'Key=value' in [{current.header}]", number, code="fis-syntax")
        current.entries.append((kv.group(1), kv.group(2).strip(), number))
    return sections, mentions_fuzzylite


def _range(value: str, rep: Reporter, line: int) -> Range:
    inner = value.strip()
    if not (inner.startswith("[") and inner.endswith("]")):
        raise rep.fail(f"Range must be written [min max], found {value!r}", line, code="fis-range")
    low_high = numbers(inner[1:-1], rep, line, "Range")
    if len(low_high) != 2:
        raise rep.fail(f"Range needs 2 numbers, found {len(low_high)}", line, code="fis-range")
    if low_high[0] > low_high[1]:
        raise rep.fail(
            f"Range [{low_high[0]:g} {low_high[1]:g}] has its minimum above its maximum",
            line,
            code="fis-range",
        )
    return Range(low_high[0], low_high[1])


@dataclass
class _Var:
    name: str
    range: Range | None
    terms: list[Term]
    entries: _Section
    default: Default | None = None
    clamp: bool = False


def _membership(
    kind: str,
    params_text: str,
    height_text: str | None,
    rep: Reporter,
    line: int,
    dialect: str,
    n_inputs: int,
    names: set[str],
) -> MembershipFunction:
    kind_lower = kind.strip().lower()
    if kind_lower == "function":
        try:
            expr = parse_expr(params_text)
        except ExprError as exc:
            raise rep.fail(f"function term: {exc}", line, code="fis-function") from None
        argument = "x" if "x" in names_in(expr) and "x" not in names else None
        return FunctionMF(expr, params_text.strip(), argument)
    params = numbers(params_text, rep, line, f"parameters of {kind!r}")
    if height_text is not None:
        params.append(numbers(height_text, rep, line, "height")[0])
    ts_kind = FIS_TS_TYPES.get(kind_lower)
    if ts_kind is not None and registry.flag(ts_kind, "ts_constant"):
        if not params:
            raise rep.fail(f"{kind_lower!r} needs a value", line, code="fis-params")
        return ShapeMF(ts_kind, (params[0],))
    if ts_kind is not None:  # linear: a coefficient per input and a constant
        if len(params) == n_inputs:  # fuzzylite allows leaving out the constant term
            params = [*params, 0.0]
        if len(params) != n_inputs + 1:
            raise rep.fail(
                f"{kind_lower!r} needs {n_inputs + 1} parameters (one per input and a constant), "
                f"found {len(params)}",
                line,
                code="fis-params",
            )
        return ShapeMF(ts_kind, tuple(params))
    if kind_lower == "discretemf":
        height = params.pop() if len(params) % 2 == 1 else 1.0
        if len(params) < 2:
            raise rep.fail("'discretemf' needs x y pairs", line, code="fis-params")
        xs, ys = params[0::2], params[1::2]
        # one pair is a constant degree (fuzzylite); the model says it with two points (5.2.2)
        xs, ys = (xs * 2, ys * 2) if len(xs) == 1 else (xs, ys)
        return PointsMF(tuple(Point(x, y * height) for x, y in zip(xs, ys, strict=True)))
    mapping = FIS_TYPES.get(kind_lower)
    if mapping is None or (
        dialect == "matlab" and kind_lower not in MATLAB_TYPES and kind_lower not in FIS_TYPES
    ):
        known = ", ".join(sorted([*FIS_TYPES, *FIS_TS_TYPES, "discretemf", "function"]))
        raise rep.fail(
            f"unknown membership function type {kind!r} (known: {known})", line, code="fis-mf-type"
        )
    if len(params) < mapping.arity:
        raise rep.fail(
            f"{kind_lower} needs {mapping.arity} parameters, found {len(params)}", line, code="fis-params"
        )
    height = 1.0
    if len(params) > mapping.arity:
        extra = params[mapping.arity :]
        if dialect == "fuzzylite" and len(extra) == 1:
            height = extra[0]
        elif dialect == "fuzzylite":
            raise rep.fail(
                f"{kind_lower} takes {mapping.arity} parameters and a height, found {len(params)}",
                line,
                code="fis-params",
            )
        else:
            rep.warning(
                f"{kind_lower}: extra parameters {' '.join(f'{v:g}' for v in extra)} ignored "
                f"(MATLAB reads {mapping.arity})",
                line,
                code="fis-extra-param",
            )
    values = mapping.to_model(params[: mapping.arity])
    problem = fis_shape_problem(kind_lower, values)
    if problem is not None:
        raise rep.fail(problem, line, code="fis-params")
    return ShapeMF(mapping.kind, values, height)


def _number(digits: str) -> tuple[int, int] | tuple[int, int, str]:
    """The number of a section or of an MF key as a sort key: ``(0, n)``, or for more
    digits than Python converts (4300, leading zeros aside), ``(1, ...)`` after every
    smaller number."""
    if len(digits) > 4300:
        digits = digits.lstrip("0") or "0"
    if len(digits) <= 4300:
        return (0, int(digits))
    return (1, len(digits), digits)


class _UniqueNames:
    """Term names made unique as :func:`~fuzzyctl.formats.common.basics.unique_name` makes them
    (``name``, ``name_2``, ``name_3``...), remembering where each name's search stopped:
    100,000 terms of one name would otherwise take 5 * 10**9 lookups."""

    def __init__(self) -> None:
        self.taken: set[str] = set()
        self.next: dict[str, int] = {}

    def unique(self, name: str) -> str:
        candidate, n = name, self.next.get(name, 2)
        while candidate in self.taken:
            candidate, n = f"{name}_{n}", n + 1
        self.next[name] = n  # every name_k below n is taken, and stays taken
        self.taken.add(candidate)
        return candidate


def _variable(
    section: _Section, kind: str, rep: Reporter, dialect: str, n_inputs: int, names: set[str]
) -> _Var:
    name_entry = section.get("Name")
    if name_entry is None:
        raise rep.fail(f"[{section.header}] has no Name", section.line, code="fis-missing-key")
    name = _unquote(name_entry[0])
    range_entry = section.get("Range")
    rng = _range(range_entry[0], rep, range_entry[1]) if range_entry else None
    if rng is None:
        rep.warning(f"[{section.header}] has no Range", section.line, code="fis-missing-key")
    var = _Var(name, rng, [], section)
    taken = _UniqueNames()
    mf_entries = [(k, v, line) for k, v, line in section.entries if re.fullmatch(r"MF\d+", k)]
    for position, (key, value, line) in enumerate(mf_entries, start=1):
        if _number(key[2:]) != (0, position):
            # MATLAB and fuzzylite both take the MF lines in file order, whatever their numbers.
            rep.warning(
                f"{key} is membership function number {position} of {name!r} (taken in file order)",
                line,
                code="fis-mf-number",
            )
        m = _MF.match(value)
        if m is None:
            raise rep.fail(f"{key}: expected 'name':'type',[parameters]", line, code="fis-mf-syntax")
        term_name = m.group(1).strip()
        if not term_name:
            term_name = f"mf{position}"
            rep.warning(
                f"{key} of {name!r} has an empty name; called {term_name!r}", line, code="fis-mf-name"
            )
        mf = _membership(m.group(2), m.group(3), m.group(4), rep, line, dialect, n_inputs, names)
        if kind == "input" and isinstance(mf, ShapeMF) and mf.kind in TS_KINDS:
            raise rep.fail(
                f"{key}: '{m.group(2)}' is a Sugeno output type, not an input membership function",
                line,
                code="fis-mf-type",
            )
        unique = taken.unique(term_name)
        if unique != term_name:
            # Rules refer to terms by position, so both stay reachable under distinct names.
            rep.warning(
                f"duplicate term name {term_name!r} in {name!r}: {key} renamed {unique!r}",
                line,
                code="duplicate-term",
            )
        var.terms.append(Term(unique, mf, rep.span(line)))
    declared = section.get("NumMFs")
    if declared is not None:
        count = _value(declared, parse_count, "NumMFs", "a whole number", rep)
        if count != len(var.terms):
            rep.warning(
                f"NumMFs={count} but {len(var.terms)} membership functions are listed",
                declared[1],
                code="fis-count",
            )
    for key in ("Enabled",):
        entry = section.get(key)
        if entry is not None and not _flag(section, key, rep):
            raise rep.fail(
                f"{name!r} is disabled (Enabled=0): disabled variables are not supported",
                entry[1],
                code="fis-unsupported",
            )
    return var


def _flag(section: _Section, key: str, rep: Reporter) -> bool:
    entry = section.get(key)
    if entry is None:
        return False
    return _value(entry, parse_number, key, "0 or 1", rep) == 1.0


_T = TypeVar("_T")


def _value(entry: tuple[str, int], parse: Callable[[str], _T], key: str, what: str, rep: Reporter) -> _T:
    """The value of ``key``'s ``(text, line)`` entry read by ``parse``; an error saying it must be
    ``what`` when it is not."""
    try:
        return parse(entry[0])
    except ValueError:
        raise rep.fail(f"{key} must be {what}, found {entry[0]!r}", entry[1], code="fis-number") from None


def read(text: str, path: str | None = None, *, dialect: str | None = None) -> Loaded:
    """Parse a FIS file into a one-block :class:`Document`.

    ``dialect`` (``"matlab"`` or ``"fuzzylite"``) overrides detection from the file."""
    lines = text.splitlines()
    rep = Reporter(path, lines)
    sections, mentions_fuzzylite = _sections(text, rep)
    systems = [s for s in sections if s.header.lower() == "system"]
    if not systems:
        raise rep.fail("no [System] section: this is not a FIS file", 1 if lines else None, code="fis-syntax")
    system = systems[0]
    inputs_s = sorted(
        (s for s in sections if s.header.lower().startswith("input")), key=lambda s: _number(s.header[5:])
    )
    outputs_s = sorted(
        (s for s in sections if s.header.lower().startswith("output")), key=lambda s: _number(s.header[6:])
    )
    rules_s = next((s for s in sections if s.header.lower() == "rules"), None)
    fuzzylite_keys = any(
        s.get(k) for s in outputs_s + inputs_s for k in ("Default", "LockPrevious", "LockRange", "Enabled")
    )
    dialect = dialect or ("fuzzylite" if mentions_fuzzylite or fuzzylite_keys else "matlab")

    def system_value(key: str) -> tuple[str, int] | None:
        entry = system.get(key)
        return (_unquote(entry[0]), entry[1]) if entry else None

    def count(key: str) -> int | None:
        entry = system_value(key)
        if entry is None:
            return None
        return _value(entry, parse_count, key, "a whole number", rep)

    for key, found in (("NumInputs", len(inputs_s)), ("NumOutputs", len(outputs_s))):
        declared = count(key)
        if declared is not None and declared != found:
            entry = system_value(key)
            raise rep.fail(
                f"{key}={declared} but the file has {found} [{key[3:-1]}N] sections",
                entry[1] if entry else system.line,
                code="fis-count",
            )
    fis_type = (system_value("Type") or ("mamdani", system.line))[0].lower()
    if fis_type not in {"mamdani", "sugeno", "hybrid", "tsukamoto"}:
        entry = system_value("Type")
        raise rep.fail(
            f"unknown FIS Type {fis_type!r} (mamdani, sugeno)",
            entry[1] if entry else system.line,
            code="fis-type",
        )

    def method(key: str, table: dict[str, str], default: str | None) -> str | None:
        entry = system_value(key)
        if entry is None or entry[0] == "":
            return default
        name = entry[0].lower()
        if name not in table:
            raise rep.fail(
                f"{key}={entry[0]!r} is not known (known: {', '.join(table)}); user-defined MATLAB "
                "functions cannot be imported",
                entry[1],
                code="fis-method",
            )
        return table[name]

    and_op = method("AndMethod", AND_METHODS, None)
    or_op = method("OrMethod", OR_METHODS, None)
    act = method("ImpMethod", AND_METHODS, "MIN")
    accu = method("AggMethod", AGG_METHODS, "MAX")
    defuzz = method("DefuzzMethod", DEFUZZ_METHODS, "COG" if fis_type == "mamdani" else "WTAVER")

    n_inputs = len(inputs_s)
    names: set[str] = set()
    for s in inputs_s + outputs_s:
        entry = s.get("Name")
        if entry:
            names.add(_unquote(entry[0]))
    inputs = [_variable(s, "input", rep, dialect, n_inputs, names) for s in inputs_s]
    outputs = [_variable(s, "output", rep, dialect, n_inputs, names) for s in outputs_s]
    seen: set[str] = set()
    for var in inputs + outputs:
        if var.name in seen:
            raise rep.fail(
                f"two variables are called {var.name!r}", var.entries.line, code="duplicate-variable"
            )
        seen.add(var.name)

    defuzzify: list[DefuzzifyBlock] = []
    any_mamdani_output = False
    for var in outputs:
        ts = bool(var.terms) and all(is_ts_term(t.mf) for t in var.terms)
        has_ts = any(is_ts_term(t.mf) for t in var.terms)
        if has_ts and not ts:
            raise rep.fail(
                f"output {var.name!r} mixes constant/linear terms with membership functions",
                var.entries.line,
                code="fis-mf-type",
            )
        if fis_type == "mamdani" and ts:
            raise rep.fail(
                f"output {var.name!r} of a Mamdani system has constant/linear terms",
                var.entries.line,
                code="fis-mf-type",
            )
        if fis_type == "sugeno" and not ts and var.terms:
            monotonic = all(isinstance(t.mf, ShapeMF) and t.mf.kind in MONOTONIC_KINDS for t in var.terms)
            if not (dialect == "fuzzylite" and monotonic):
                raise rep.fail(
                    f"output {var.name!r} of a Sugeno system must have constant or linear terms",
                    var.entries.line,
                    code="fis-mf-type",
                )
        weighted = ts or fis_type in {"sugeno", "tsukamoto"}
        out_method: str | None
        if weighted:
            out_method = defuzz if defuzz in methods.SUGENO else methods.ts_method(None)
        else:
            any_mamdani_output = True
            sugeno_only = defuzz in methods.SUGENO
            out_method = defuzz if not sugeno_only else _CENTROID
            if defuzz is not None and sugeno_only and fis_type == "mamdani":
                entry = system_value("DefuzzMethod")
                raise rep.fail(
                    f"DefuzzMethod {defuzz.lower()} needs a Sugeno system",
                    entry[1] if entry else None,
                    code="fis-method",
                )
        default = _default(var, rep, dialect)
        defuzzify.append(
            DefuzzifyBlock(
                var.name,
                tuple(var.terms),
                var.range,
                out_method,
                default,
                None,
                rep.span(var.entries.line),
                clamp=_flag(var.entries, "LockRange", rep),
            )
        )
    # AggMethod is the aggregation of Mamdani outputs; Sugeno outputs weigh every rule on its
    # own (MATLAB, and fuzzylite's "aggregation: none").  With both kinds in one file
    # (fuzzylite's hybrid) it is said on the Mamdani outputs alone.
    block_accu: str | None = None
    if any_mamdani_output and all(d.method not in methods.SUGENO for d in defuzzify):
        block_accu = accu
    elif any_mamdani_output:
        defuzzify = [d if d.method in methods.SUGENO else replace(d, accu=accu) for d in defuzzify]
    declared_rules = count("NumRules")
    rule_list = rules(rules_s.rules, inputs, outputs, rep, dialect) if rules_s is not None else []
    if declared_rules is not None and rules_s is not None and declared_rules != len(rules_s.rules):
        rep.warning(
            f"NumRules={declared_rules} but [Rules] lists {len(rules_s.rules)} rules",
            system.line,
            code="fis-count",
        )
    rep.raise_if_errors()
    name_entry = system_value("Name")
    fb = FunctionBlock(
        name=(name_entry[0] or None) if name_entry else None,
        variables=tuple(
            [Variable(v.name, VarKind.INPUT, range=v.range) for v in inputs]
            + [Variable(v.name, VarKind.OUTPUT, range=v.range) for v in outputs]
        ),
        fuzzify=tuple(
            FuzzifyBlock(
                v.name,
                tuple(v.terms),
                v.range,
                rep.span(v.entries.line),
                clamp=_flag(v.entries, "LockRange", rep),
            )
            for v in inputs
        ),
        defuzzify=tuple(defuzzify),
        rule_blocks=(RuleBlock(None, tuple(rule_list), and_op, or_op, act, block_accu),)
        if rules_s is not None
        else (),
        span=rep.span(system.line),
    )
    return Loaded(Document((fb,), path), rep.warnings)


def _default(var: _Var, rep: Reporter, dialect: str) -> Default:
    entry = var.entries.get("Default")
    lock_previous = _flag(var.entries, "LockPrevious", rep)
    if entry is not None:
        return Default(_value(entry, parse_number, "Default", "a number", rep), lock_previous)
    if dialect == "fuzzylite":
        return Default(math.nan, lock_previous)
    # MATLAB: "no rules fired ... output set to its mean range value"
    if var.range is None:
        return Default(math.nan, lock_previous)
    return Default((var.range.low + var.range.high) / 2.0, lock_previous)


__all__ = ["DiagnosticError", "read"]
