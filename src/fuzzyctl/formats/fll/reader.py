"""fuzzylite language (FLL) files: fuzzylite 5 and 6 (C++) and pyfuzzylite 8.

Semantics follow fuzzylite's C++ sources, which the ``.fld`` datasets were made with:

* ``lock-range`` clamps an input before fuzzification and an output after defuzzification;
  ``lock-previous`` keeps the last valid output (``DEFAULT := nan | NC`` in the model).
* A rule weight (``with 0.5``) multiplies the antecedent degree before implication
  (model :attr:`Rule.weight`).
* Hedges in a consequent modify the activation degree; fuzzylite applies them to a running
  degree, so a conclusion also receives the hedges of the conclusions before it in the same
  rule.  The reader stores that effective list on each :class:`Conclusion`, the writer
  undoes it, so the model states what fuzzylite computes.
* ``x is any`` holds with degree 1: an ``and`` drops it, an ``or`` becomes true, and a rule
  whose whole antecedent is ``any`` gets no condition.
* Duplicate term names: rules refer to the first (fuzzylite C++); later ones are renamed
  ``name_2``, ... with a warning (pyfuzzylite would take the last).
* Version 5 spellings: ``accumulation:`` for ``aggregation:``, ``activation: <TNorm>`` for
  ``implication:``, ``lock-valid`` for ``lock-previous``.

The writer lives in :mod:`fuzzyctl.formats.fll.writer`; what both use, in :mod:`.names`.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

from fuzzyctl import model as m
from fuzzyctl.formats import Loaded
from fuzzyctl.formats.common.basics import Reporter, parse_number
from fuzzyctl.formats.common.expr import ExprError, parse_function
from fuzzyctl.formats.common.terms import FLL_TS_TYPES, FLL_TYPES
from fuzzyctl.formats.fll.names import DEFUZZIFIERS, SNORMS_ACCU, SNORMS_OR, TNORMS
from fuzzyctl.formats.fll.rules import Lookup, RuleError, parse_rule

_LINE = re.compile(r"^(?P<indent>\s*)(?P<key>[A-Za-z][A-Za-z-]*)\s*:\s?(?P<value>.*)$")


@dataclass
class _Variable:
    kind: m.VarKind
    name: str
    line: int
    range: m.Range | None = None
    clamp: bool = False
    terms: list[m.Term] = field(default_factory=list)
    term_names: set[str] = field(default_factory=set)
    #: the next suffix to try for each duplicated term name (see _unique_term)
    next_suffix: dict[str, int] = field(default_factory=dict)
    accu: str | None = None
    method: str | None = None
    default: float = math.nan
    lock_previous: bool = False
    description: str | None = None


@dataclass
class _Block:
    name: str | None
    line: int
    enabled: bool = True
    and_op: str | None = None
    or_op: str | None = None
    act: str | None = None
    rule_activation: str | None = None
    rules: list[tuple[str, int]] = field(default_factory=list)


class _Reporter(Reporter):
    """A :class:`Reporter` making each whole-line span once: FLL places everything by line,
    and a variable's line is the place of its Variable, block and terms alike."""

    def __init__(self, path: str | None, lines: list[str]) -> None:
        super().__init__(path, lines)
        self.line_spans: dict[int, m.Span] = {}

    def span(self, line: int, column: int = 1, width: int = 0) -> m.Span:
        if column != 1 or width:
            return super().span(line, column, width)
        span = self.line_spans.get(line)
        if span is None:
            span = self.line_spans[line] = super().span(line)
        return span


def _bool(value: str, rep: Reporter, line: int, key: str) -> bool:
    lowered = value.strip().lower()
    if lowered in {"true", "1"}:
        return True
    if lowered in {"false", "0"}:
        return False
    raise rep.fail(f"{key} must be true or false, found {value.strip()!r}", line, code="fll-value")


def _numbers(words: list[str], rep: Reporter, line: int, what: str) -> list[float]:
    try:
        return [parse_number(w) for w in words]
    except ValueError:
        raise rep.fail(
            f"{what}: expected numbers, found {' '.join(words)!r}", line, code="fll-number"
        ) from None


def _term(
    value: str,
    rep: Reporter,
    line: int,
    var: _Variable,
    n_inputs: int,
    names: set[str],
    leaves: dict[str, m.Num | m.Name],
) -> m.Term:
    words = value.split()
    if len(words) < 2:
        raise rep.fail("term: expected 'name Class parameters'", line, code="fll-term")
    name, cls = words[0], words[1]
    rest = value.split(None, 2)[2] if len(words) > 2 else ""
    mf: m.MembershipFunction
    if cls == "Function":
        try:
            expr, reads = parse_function(rest, leaves)
        except ExprError as exc:
            raise rep.fail(f"Function {name!r}: {exc}", line, code="fll-function") from None
        argument = "x" if "x" in reads and "x" not in names else None
        mf = m.FunctionMF(expr, rest.strip(), argument)
    elif cls == "Constant":
        params = _numbers(words[2:], rep, line, f"term {name!r}")
        if len(params) != 1:
            raise rep.fail(f"Constant {name!r} takes one value, found {len(params)}", line, code="fll-term")
        mf = m.ShapeMF(FLL_TS_TYPES[cls], (params[0],))
    elif cls == "Linear":
        params = _numbers(words[2:], rep, line, f"term {name!r}")
        if len(params) == n_inputs:
            params.append(0.0)
        if len(params) != n_inputs + 1:
            raise rep.fail(
                f"Linear {name!r} needs {n_inputs} or {n_inputs + 1} coefficients (one per input variable "
                f"and a constant), found {len(params)}",
                line,
                code="fll-term",
            )
        mf = m.ShapeMF(FLL_TS_TYPES[cls], tuple(params))
    elif cls == "Discrete":
        params = _numbers(words[2:], rep, line, f"term {name!r}")
        height = params.pop() if len(params) % 2 == 1 else 1.0
        if len(params) < 2:
            raise rep.fail(f"Discrete {name!r} needs x y pairs", line, code="fll-term")
        xs, ys = params[0::2], params[1::2]
        # one pair is a constant degree (fuzzylite); the model says it with two points (5.2.2)
        xs, ys = (xs * 2, ys * 2) if len(xs) == 1 else (xs, ys)
        mf = m.PointsMF(tuple(m.Point(x, y * height) for x, y in zip(xs, ys, strict=True)))
    else:
        mapping = FLL_TYPES.get(cls)
        if mapping is None:
            known = ", ".join(sorted([*FLL_TYPES, "Constant", "Linear", "Discrete", "Function"]))
            raise rep.fail(f"unknown term class {cls!r} (known: {known})", line, code="fll-term")
        params = _numbers(words[2:], rep, line, f"term {name!r}")
        if len(params) not in (mapping.arity, mapping.arity + 1):
            raise rep.fail(
                f"{cls} {name!r} takes {mapping.arity} parameters (and an optional height), "
                f"found {len(params)}",
                line,
                code="fll-term",
            )
        height = params[mapping.arity] if len(params) > mapping.arity else 1.0
        mf = m.ShapeMF(mapping.kind, mapping.to_model(params), height)
    unique = _unique_term(name, var)
    if unique != name:
        rep.warning(
            f"duplicate term name {name!r} in {var.name!r}: rules use the first (as fuzzylite C++ does); "
            f"this one is renamed {unique!r}",
            line,
            code="duplicate-term",
        )
    return m.Term(unique, mf, rep.span(line))


def _unique_term(name: str, var: _Variable) -> str:
    """What :func:`unique_name` gives (``name``, else the first free ``name_2``, ...),
    without trying every taken suffix again for each duplicate: names are only ever added,
    so the first free suffix never goes down."""
    taken = var.term_names
    if name not in taken:
        taken.add(name)
        return name
    n = var.next_suffix.get(name, 2)
    while f"{name}_{n}" in taken:
        n += 1
    var.next_suffix[name] = n + 1
    unique = f"{name}_{n}"
    taken.add(unique)
    return unique


def read(text: str, path: str | None = None) -> Loaded:
    """Parse an FLL file into a one-block :class:`Document`."""
    lines = text.splitlines()
    rep = _Reporter(path, lines)
    engine_name: str | None = None
    engine_line = 1
    saw_engine = False
    variables: list[_Variable] = []
    blocks: list[_Block] = []
    current: _Variable | _Block | None = None
    pending_terms: list[tuple[_Variable, str, int]] = []
    for number, raw in enumerate(lines, start=1):
        line = raw.split("#", 1)[0].rstrip()
        if not line.strip():
            continue
        found = _LINE.match(line)
        if found is None:
            raise rep.fail("expected 'key: value'", number, code="fll-syntax")
        key, value = found.group("key"), found.group("value").strip()
        if key == "Engine":
            engine_name, engine_line, saw_engine, current = (value or None), number, True, None
        elif key in {"InputVariable", "OutputVariable"}:
            if not value:
                raise rep.fail(f"{key} needs a name", number, code="fll-syntax")
            kind = m.VarKind.INPUT if key == "InputVariable" else m.VarKind.OUTPUT
            current = _Variable(kind, value.split()[0], number)
            variables.append(current)
        elif key == "RuleBlock":
            current = _Block(value or None, number)
            blocks.append(current)
        elif key == "description":
            if isinstance(current, _Variable):
                current.description = value
        elif current is None:
            if not saw_engine:
                raise rep.fail(
                    f"'{key}:' before any Engine, InputVariable, OutputVariable or RuleBlock",
                    number,
                    code="fll-syntax",
                )
            raise rep.fail(f"'{key}:' does not belong to the Engine section", number, code="fll-syntax")
        elif isinstance(current, _Variable):
            _variable_key(current, key, value, rep, number, pending_terms)
        else:
            _block_key(current, key, value, rep, number)
    if not saw_engine and not variables:
        raise rep.fail(
            "no 'Engine:' and no variables: this is not an FLL file", 1 if lines else None, code="fll-syntax"
        )
    names = {v.name for v in variables}
    if len(names) != len(variables):
        seen: set[str] = set()
        for v in variables:
            if v.name in seen:
                raise rep.fail(f"two variables are called {v.name!r}", v.line, code="duplicate-variable")
            seen.add(v.name)
    n_inputs = sum(1 for v in variables if v.kind is m.VarKind.INPUT)
    leaves: dict[str, m.Num | m.Name] = {}  # the Function terms' numbers and names, one object each
    for var, value, number in pending_terms:
        var.terms.append(_term(value, rep, number, var, n_inputs, names, leaves))
    rule_blocks = _rule_blocks(blocks, variables, rep)
    rep.raise_if_errors()
    inputs = [v for v in variables if v.kind is m.VarKind.INPUT]
    outputs = [v for v in variables if v.kind is m.VarKind.OUTPUT]
    fb = m.FunctionBlock(
        name=engine_name,
        variables=tuple(
            m.Variable(
                v.name,
                v.kind,
                range=v.range,
                span=rep.span(v.line),
                comments=(v.description,) if v.description else (),
            )
            for v in variables
        ),
        fuzzify=tuple(
            m.FuzzifyBlock(v.name, tuple(v.terms), v.range, rep.span(v.line), clamp=v.clamp) for v in inputs
        ),
        defuzzify=tuple(
            m.DefuzzifyBlock(
                v.name,
                tuple(v.terms),
                v.range,
                v.method,
                m.Default(v.default, v.lock_previous),
                v.accu,
                rep.span(v.line),
                clamp=v.clamp,
            )
            for v in outputs
        ),
        rule_blocks=tuple(rule_blocks),
        span=rep.span(engine_line),
    )
    return Loaded(m.Document((fb,), path), rep.warnings)


def _rule_blocks(blocks: list[_Block], variables: list[_Variable], rep: Reporter) -> list[m.RuleBlock]:
    lookup: Lookup = {
        v.name: (v.name, v.kind is m.VarKind.OUTPUT, {t: t for t in v.term_names}) for v in variables
    }
    out: list[m.RuleBlock] = []
    for block in blocks:
        rules: list[m.Rule] = []
        for i, (text, number) in enumerate(block.rules, start=1):
            try:
                rules.append(parse_rule(text, str(i), rep.span(number), lookup))
            except RuleError as exc:
                raise rep.fail(f"rule: {exc}", number, code="fll-rule") from None
        out.append(
            m.RuleBlock(
                block.name,
                tuple(rules),
                block.and_op,
                block.or_op,
                block.act,
                None,
                rep.span(block.line),
                enabled=block.enabled,
                rule_activation=block.rule_activation,
            )
        )
    return out


def _variable_key(
    var: _Variable,
    key: str,
    value: str,
    rep: Reporter,
    number: int,
    pending_terms: list[tuple[_Variable, str, int]],
) -> None:
    output = var.kind is m.VarKind.OUTPUT
    if key == "enabled":
        if not _bool(value, rep, number, key):
            raise rep.fail(
                f"{var.name!r} is disabled: disabled variables are not supported",
                number,
                code="fll-unsupported",
            )
    elif key == "range":
        numbers = _numbers(value.split(), rep, number, "range")
        if len(numbers) != 2:
            raise rep.fail(f"range needs 2 numbers, found {len(numbers)}", number, code="fll-value")
        if numbers[0] > numbers[1]:
            raise rep.fail(
                f"range {numbers[0]:g} {numbers[1]:g} has its minimum above its maximum",
                number,
                code="fll-value",
            )
        var.range = m.Range(numbers[0], numbers[1], rep.span(number))
    elif key == "lock-range":
        var.clamp = _bool(value, rep, number, key)
    elif key == "term":
        pending_terms.append((var, value, number))  # after all variables: Linear needs the input count
    elif output and key in {"aggregation", "accumulation"}:
        if value != "none" and value not in SNORMS_ACCU:
            raise rep.fail(
                f"unknown {key} {value!r} (known: {', '.join(SNORMS_ACCU)}, none)", number, code="fll-value"
            )
        var.accu = SNORMS_ACCU.get(value)
    elif output and key == "defuzzifier":
        words = value.split()
        if not words or words[0] == "none":
            var.method = None
        elif words[0] not in DEFUZZIFIERS:
            raise rep.fail(
                f"unknown defuzzifier {words[0]!r} (known: {', '.join(DEFUZZIFIERS)})",
                number,
                code="fll-value",
            )
        else:
            var.method = DEFUZZIFIERS[words[0]]
    elif output and key == "default":
        var.default = _numbers([value], rep, number, "default")[0]
    elif output and key in {"lock-previous", "lock-valid"}:
        var.lock_previous = _bool(value, rep, number, key)
    else:
        raise rep.fail(
            f"unknown key '{key}:' in {'OutputVariable' if output else 'InputVariable'} {var.name!r}",
            number,
            code="fll-syntax",
        )


def _block_key(block: _Block, key: str, value: str, rep: Reporter, number: int) -> None:
    if key == "enabled":
        block.enabled = _bool(value, rep, number, key)
    elif key == "conjunction":
        block.and_op = _norm(value, TNORMS, rep, number, key)
    elif key == "disjunction":
        block.or_op = _norm(value, SNORMS_OR, rep, number, key)
    elif key == "implication":
        block.act = _norm(value, TNORMS, rep, number, key)
    elif key == "activation":
        words = value.split()
        if words and words[0] in TNORMS:  # fuzzylite 5: "activation" was the implication
            block.act = TNORMS[words[0]]
        elif not words or words[0] in {"General", "none"}:
            block.rule_activation = None
        else:
            block.rule_activation = value
    elif key == "rule":
        block.rules.append((value, number))
    else:
        raise rep.fail(f"unknown key '{key}:' in RuleBlock", number, code="fll-syntax")


def _norm(value: str, table: dict[str, str], rep: Reporter, number: int, key: str) -> str | None:
    if value in {"", "none"}:
        return None
    if value not in table:
        raise rep.fail(f"unknown {key} {value!r} (known: {', '.join(table)}, none)", number, code="fll-value")
    return table[value]
