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

The writer lives in :mod:`fuzzyctl.formats.fis_write`.
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass, field, replace

from fuzzyctl.diagnostics import DiagnosticError
from fuzzyctl.formats import Format, Loaded
from fuzzyctl.formats._common import Reporter, parse_count, parse_number, power_hedge, unique_name
from fuzzyctl.formats._expr import ExprError, eval_constant, names_in, parse_expr
from fuzzyctl.formats._terms import FIS_TYPES, MATLAB_TYPES, MONOTONIC_KINDS, fis_shape_problem
from fuzzyctl.model import (
    And,
    Conclusion,
    Condition,
    Default,
    DefuzzifyBlock,
    Document,
    FunctionBlock,
    FunctionMF,
    FuzzifyBlock,
    Is,
    MembershipFunction,
    Or,
    Point,
    PointsMF,
    Range,
    Rule,
    RuleBlock,
    ShapeMF,
    Term,
    Variable,
    VarKind,
)

AND_METHODS = {
    "min": "MIN",
    "prod": "PROD",
    "bounded_difference": "BDIF",
    "drastic_product": "DMIN",
    "einstein_product": "EINSTEIN",
    "hamacher_product": "HAMACHER",
    "nilpotent_minimum": "NIPMIN",
}
OR_METHODS = {
    "max": "MAX",
    "probor": "ASUM",
    "bounded_sum": "BSUM",
    "drastic_sum": "DMAX",
    "einstein_sum": "EINSTEIN",
    "hamacher_sum": "HAMACHER",
    "nilpotent_maximum": "NIPMAX",
}
AGG_METHODS = {
    "max": "MAX",
    "sum": "SUM",
    "probor": "PROBOR",
    "bounded_sum": "BSUM",
    "drastic_sum": "DMAX",
    "einstein_sum": "EINSTEIN",
    "hamacher_sum": "HAMACHER",
    "nilpotent_maximum": "NIPMAX",
}
DEFUZZ_METHODS = {
    "centroid": "COG",
    "bisector": "COA",
    "mom": "MOM",
    "som": "LM",
    "lom": "RM",
    "wtaver": "WTAVER",
    "wtsum": "WTSUM",
    # A user-defined function of the Octave toolkit's demos: the centroid by integration,
    # which is what our COG computes exactly.
    "centroid_integral": "COG",
}
# fuzzylite's hedge codes (FisImporter::translateProposition); "any" is resolved apart.
FUZZYLITE_HEDGE_CODES: dict[int, tuple[str, ...]] = {
    1: ("seldom",),
    5: ("somewhat",),
    20: ("very",),
    30: ("extremely",),
    40: ("very", "very"),
}
ANY_CODE = 99
TS_KINDS = frozenset({"constant", "linear"})


def _is_ts_term(mf: MembershipFunction) -> bool:
    """A Takagi-Sugeno output term: constant, linear, or a function of the variables."""
    return (isinstance(mf, ShapeMF) and mf.kind in TS_KINDS) or (
        isinstance(mf, FunctionMF) and mf.argument is None
    )


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
_RULE = re.compile(r"^(?P<ante>[^,]*),(?P<cons>[^(]*)\((?P<w>[^)]*)\)\s*:\s*(?P<conn>\S+)\s*$")


def _strip_comment(line: str) -> str:
    """Drop a trailing ``#`` or ``%`` comment that is outside quotes."""
    quoted = False
    for i, ch in enumerate(line):
        if ch == "'":
            quoted = not quoted
        elif ch in "#%" and not quoted:
            return line[:i]
    return line


def _unquote(value: str) -> str:
    value = value.strip()
    if len(value) >= 2 and value[0] == "'" and value[-1] == "'":
        return value[1:-1]
    return value


def _sections(text: str, rep: Reporter) -> tuple[list[_Section], bool]:
    """Split the file into sections; also tell whether a comment names fuzzylite."""
    sections: list[_Section] = []
    mentions_fuzzylite = False
    for number, raw in enumerate(rep.lines, start=1):
        stripped = raw.strip()
        if not stripped:
            continue
        if stripped[0] in "#%" or stripped.startswith("//"):
            if not sections and "fuzzylite" in stripped.lower():
                mentions_fuzzylite = True
            continue
        line = _strip_comment(stripped).strip()
        if not line:
            continue
        m = _SECTION.fullmatch(line)
        if m:
            sections.append(_Section(re.sub(r"\s+", "", m.group(1)), number))
            continue
        if line.startswith("["):
            raise rep.fail(f"unknown section {line}", number, code="fis-syntax")
        if not sections:
            raise rep.fail("text before the [System] section", number, code="fis-syntax")
        current = sections[-1]
        if current.header.lower() == "rules":
            current.rules.append((line, number))
            continue
        kv = _KEY_VALUE.match(line)
        if kv is None:
            raise rep.fail(f"expected 'Key=value' in [{current.header}]", number, code="fis-syntax")
        current.entries.append((kv.group(1), kv.group(2).strip(), number))
    return sections, mentions_fuzzylite


_SEPARATORS = re.compile(r"[\s,;]+")


def _numbers(text: str, rep: Reporter, line: int, what: str) -> list[float]:
    parts = [p for p in _SEPARATORS.split(text.strip()) if p]
    out: list[float] = []
    for part in parts:
        try:
            out.append(parse_number(part))
        except ValueError:
            try:  # MATLAB evaluates entries such as -pi/4
                out.append(eval_constant(parse_expr(part)))
            except (ValueError, ZeroDivisionError) as exc:
                # the entry, shortened (it may be 5001 digits or 1000 parentheses), and why
                shown = part if len(part) <= 40 else f"{part[:30]}... ({len(part)} characters)"
                raise rep.fail(
                    f"{what}: expected numbers, found {shown!r} ({exc})", line, code="fis-number"
                ) from None
    return out


def _range(value: str, rep: Reporter, line: int) -> Range:
    inner = value.strip()
    if not (inner.startswith("[") and inner.endswith("]")):
        raise rep.fail(f"Range must be written [min max], found {value!r}", line, code="fis-range")
    numbers = _numbers(inner[1:-1], rep, line, "Range")
    if len(numbers) != 2:
        raise rep.fail(f"Range needs 2 numbers, found {len(numbers)}", line, code="fis-range")
    if numbers[0] > numbers[1]:
        raise rep.fail(
            f"Range [{numbers[0]:g} {numbers[1]:g}] has its minimum above its maximum", line, code="fis-range"
        )
    return Range(numbers[0], numbers[1])


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
    params = _numbers(params_text, rep, line, f"parameters of {kind!r}")
    if height_text is not None:
        params.append(_numbers(height_text, rep, line, "height")[0])
    if kind_lower == "constant":
        if not params:
            raise rep.fail("'constant' needs a value", line, code="fis-params")
        return ShapeMF("constant", (params[0],))
    if kind_lower == "linear":
        if len(params) == n_inputs:  # fuzzylite allows leaving out the constant term
            params = [*params, 0.0]
        if len(params) != n_inputs + 1:
            raise rep.fail(
                f"'linear' needs {n_inputs + 1} parameters (one per input and a constant), "
                f"found {len(params)}",
                line,
                code="fis-params",
            )
        return ShapeMF("linear", tuple(params))
    if kind_lower == "discretemf":
        height = params.pop() if len(params) % 2 == 1 else 1.0
        if len(params) < 2:
            raise rep.fail("'discretemf' needs x y pairs", line, code="fis-params")
        xs, ys = params[0::2], params[1::2]
        if any(b < a for a, b in itertools.pairwise(xs)):
            raise rep.fail("'discretemf' points must be in ascending x", line, code="fis-params")
        return PointsMF(tuple(Point(x, y * height) for x, y in zip(xs, ys, strict=True)))
    mapping = FIS_TYPES.get(kind_lower)
    if mapping is None or (
        dialect == "matlab" and kind_lower not in MATLAB_TYPES and kind_lower not in FIS_TYPES
    ):
        known = ", ".join(sorted([*FIS_TYPES, "constant", "linear", "discretemf", "function"]))
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
    taken: set[str] = set()
    mf_entries = [(k, v, line) for k, v, line in section.entries if re.fullmatch(r"MF\d+", k)]
    for position, (key, value, line) in enumerate(mf_entries, start=1):
        if int(key[2:]) != position:
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
        unique = unique_name(term_name, taken)
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
        try:
            count = parse_count(declared[0])
        except ValueError:
            raise rep.fail(
                f"NumMFs must be a whole number, found {declared[0]!r}", declared[1], code="fis-number"
            ) from None
        if count != len(var.terms):
            rep.warning(
                f"NumMFs={count} but {len(var.terms)} membership functions are listed",
                declared[1],
                code="fis-count",
            )
    for key in ("Enabled",):
        entry = section.get(key)
        if entry is not None and parse_number(entry[0]) != 1.0:
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
    try:
        return parse_number(entry[0]) == 1.0
    except ValueError:
        raise rep.fail(f"{key} must be 0 or 1, found {entry[0]!r}", entry[1], code="fis-number") from None


def _hedges(code: float, dialect: str, rep: Reporter, line: int) -> tuple[int, tuple[str, ...], bool]:
    """Term index (1-based, 0 for "any"), hedges, negation of one rule entry."""
    if not math.isfinite(code) or abs(code) > 1e9:
        raise rep.fail(f"rule entry {code:g} is not a term number", line, code="fis-rule")
    negated = code < 0
    magnitude = abs(code)
    index = math.floor(magnitude + 1e-9)
    fraction = round((magnitude - index) * 100)
    if fraction == 0:
        return index, (), negated
    if dialect == "fuzzylite":
        if fraction == ANY_CODE:
            return 0, ("any",), negated
        hedges = FUZZYLITE_HEDGE_CODES.get(fraction)
        if hedges is None:
            raise rep.fail(
                f"rule entry {code:g}: no fuzzylite hedge has code .{fraction:02d}", line, code="fis-hedge"
            )
        return index, hedges, negated
    # Octave: the two decimals times 10 give the power (.05 -> 0.5, .2 -> 2, .3 -> 3)
    power = fraction / 10.0
    if power == 2.0:
        return index, ("very",), negated
    if power == 0.5:
        return index, ("somewhat",), negated
    if power == 4.0:
        return index, ("very", "very"), negated
    return index, (power_hedge(power),), negated


def _rules(
    section: _Section | None,
    inputs: list[_Var],
    outputs: list[_Var],
    rep: Reporter,
    dialect: str,
    declared: int | None,
    system_line: int,
) -> list[Rule]:
    rules: list[Rule] = []
    if section is None:
        return rules
    n_in, n_out = len(inputs), len(outputs)
    for text, line in section.rules:
        m = _RULE.match(text)
        if m:
            ante = _numbers(m.group("ante"), rep, line, "rule antecedent")
            cons = _numbers(m.group("cons"), rep, line, "rule consequent")
        else:
            # Version 1.0 writes "i1 i2 o1 w c" without punctuation.
            values = _numbers(text.replace("(", " ").replace(")", " ").replace(":", " "), rep, line, "rule")
            if len(values) != n_in + n_out + 2:
                raise rep.fail(
                    f"rule: expected '{' '.join(['i'] * n_in)}, {' '.join(['o'] * n_out)} (weight) : 1|2'",
                    line,
                    code="fis-rule-syntax",
                )
            ante, cons = values[:n_in], values[n_in : n_in + n_out]
            m = None
            weight_value, conn_value = values[-2], values[-1]
        if m is not None:
            weight_list = _numbers(m.group("w"), rep, line, "rule weight")
            conn_list = _numbers(m.group("conn"), rep, line, "rule connection")
            if len(weight_list) != 1 or len(conn_list) != 1:
                raise rep.fail(
                    "rule: weight and connection must be single numbers", line, code="fis-rule-syntax"
                )
            weight_value, conn_value = weight_list[0], conn_list[0]
        if len(ante) != n_in:
            raise rep.fail(
                f"rule has {len(ante)} antecedent entries but the system has {n_in} inputs",
                line,
                code="fis-rule-arity",
            )
        if len(cons) != n_out:
            raise rep.fail(
                f"rule has {len(cons)} consequent entries but the system has {n_out} outputs",
                line,
                code="fis-rule-arity",
            )
        if conn_value not in (1.0, 2.0):
            raise rep.fail(
                f"rule connection must be 1 (AND) or 2 (OR), found {conn_value:g}",
                line,
                code="fis-rule-syntax",
            )
        if not 0.0 <= weight_value <= 1.0:
            rep.warning(f"rule weight {weight_value:g} is outside [0, 1]", line, code="fis-weight")
        operands: list[Condition] = []
        always = False
        for var, code in zip(inputs, ante, strict=True):
            if code == 0:
                continue
            index, hedges, negated = _hedges(code, dialect, rep, line)
            if hedges == ("any",):
                # fuzzylite's "x is any" holds with degree 1
                if negated:
                    raise rep.fail(
                        "'not any' (never true) in a rule is not supported", line, code="fis-hedge"
                    )
                always = True
                continue
            if not 1 <= index <= len(var.terms):
                raise rep.fail(
                    f"rule refers to MF{index} of {var.name!r}, which has {len(var.terms)}",
                    line,
                    code="fis-rule-index",
                )
            operands.append(Is(var.name, var.terms[index - 1].name, negated, hedges, rep.span(line)))
        condition: Condition | None
        if not operands:
            if conn_value == 2.0 and not always:
                rep.warning(
                    "rule has no antecedent and connection OR: it never fires (MATLAB); dropped",
                    line,
                    code="fis-empty-rule",
                )
                continue
            if not always:
                rep.warning(
                    "rule has no antecedent: it fires with degree 1 (MATLAB's AND of don't-cares)",
                    line,
                    code="fis-empty-rule",
                )
            condition = None
        elif len(operands) == 1:
            condition = operands[0]
        elif conn_value == 1.0:
            condition = And(tuple(operands), rep.span(line))
        else:
            condition = Or(tuple(operands), rep.span(line))
        if always and conn_value == 2.0:
            condition = None  # "x is any OR ..." is 1
        conclusions: list[Conclusion] = []
        running: tuple[str, ...] = ()
        for var, code in zip(outputs, cons, strict=True):
            if code == 0:
                continue
            if code < 0:
                raise rep.fail(
                    f"negated consequent (-{abs(code):g}) for {var.name!r} is not supported",
                    line,
                    code="fis-unsupported",
                )
            index, hedges, _ = _hedges(code, dialect, rep, line)
            if dialect == "fuzzylite":
                # fuzzylite reads the FIS as rule text and hedges a running degree (see fll.py):
                # a conclusion without hedges of its own still gets the earlier ones
                hedges = running = (*hedges, *running)
            elif hedges:
                if not all(_is_ts_term(t.mf) for t in var.terms):
                    raise rep.fail(
                        f"a hedge on the Mamdani consequent of {var.name!r} is not supported",
                        line,
                        code="fis-hedge",
                    )
                # Octave raises a Sugeno rule's degree to 1/p for a consequent hedge of power p
                power = 1.0
                for h in hedges:
                    power *= {"very": 2.0, "somewhat": 0.5}.get(h, 0.0) or float(h[4:])
                hedges = (
                    (power_hedge(1.0 / power),)
                    if 1.0 / power not in (2.0, 0.5)
                    else (("very",) if 1.0 / power == 2.0 else ("somewhat",))
                )
            if not 1 <= index <= len(var.terms):
                raise rep.fail(
                    f"rule refers to MF{index} of output {var.name!r}, which has {len(var.terms)}",
                    line,
                    code="fis-rule-index",
                )
            conclusions.append(Conclusion(var.name, var.terms[index - 1].name, None, rep.span(line), hedges))
        if not conclusions:
            rep.warning("rule concludes nothing (all consequents 0); dropped", line, code="fis-empty-rule")
            continue
        weight = None if weight_value == 1.0 else weight_value
        rules.append(Rule(str(len(rules) + 1), condition, tuple(conclusions), rep.span(line), weight=weight))
    if declared is not None and declared != len(section.rules):
        rep.warning(
            f"NumRules={declared} but [Rules] lists {len(section.rules)} rules", system_line, code="fis-count"
        )
    return rules


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
        (s for s in sections if s.header.lower().startswith("input")), key=lambda s: int(s.header[5:])
    )
    outputs_s = sorted(
        (s for s in sections if s.header.lower().startswith("output")), key=lambda s: int(s.header[6:])
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
        try:
            return parse_count(entry[0])
        except ValueError:
            raise rep.fail(
                f"{key} must be a whole number, found {entry[0]!r}", entry[1], code="fis-number"
            ) from None

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
        ts = bool(var.terms) and all(_is_ts_term(t.mf) for t in var.terms)
        has_ts = any(_is_ts_term(t.mf) for t in var.terms)
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
            out_method = defuzz if defuzz in {"WTAVER", "WTSUM"} else "WTAVER"
        else:
            any_mamdani_output = True
            out_method = defuzz if defuzz not in {"WTAVER", "WTSUM"} else "COG"
            if defuzz in {"WTAVER", "WTSUM"} and fis_type == "mamdani":
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
    if any_mamdani_output and all(d.method not in {"WTAVER", "WTSUM"} for d in defuzzify):
        block_accu = accu
    elif any_mamdani_output:
        defuzzify = [d if d.method in {"WTAVER", "WTSUM"} else replace(d, accu=accu) for d in defuzzify]
    rules = _rules(rules_s, inputs, outputs, rep, dialect, count("NumRules"), system.line)
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
        rule_blocks=(RuleBlock(None, tuple(rules), and_op, or_op, act, block_accu),)
        if rules_s is not None
        else (),
        span=rep.span(system.line),
    )
    return Loaded(Document((fb,), path), rep.warnings)


def _default(var: _Var, rep: Reporter, dialect: str) -> Default:
    entry = var.entries.get("Default")
    lock_previous = _flag(var.entries, "LockPrevious", rep)
    if entry is not None:
        try:
            value = parse_number(entry[0])
        except ValueError:
            raise rep.fail(
                f"Default must be a number, found {entry[0]!r}", entry[1], code="fis-number"
            ) from None
        return Default(value, lock_previous)
    if dialect == "fuzzylite":
        return Default(math.nan, lock_previous)
    # MATLAB: "no rules fired ... output set to its mean range value"
    if var.range is None:
        return Default(math.nan, lock_previous)
    return Default((var.range.low + var.range.high) / 2.0, lock_previous)


def _read(text: str, path: str | None) -> Loaded:
    return read(text, path)


def _write(document: Document) -> str:
    from fuzzyctl.formats.fis_write import write

    return write(document)


def _lower(document: Document) -> tuple[Document, list]:  # type: ignore[type-arg]
    from fuzzyctl.formats.fis_write import lower

    return lower(document)


FORMAT = Format(
    name="fis",
    extensions=(".fis",),
    description="MATLAB / Octave Fuzzy Logic Toolbox FIS (and fuzzylite's FIS export)",
    read=_read,
    write=_write,
    lower=_lower,
)

__all__ = ["FORMAT", "DiagnosticError", "read"]
