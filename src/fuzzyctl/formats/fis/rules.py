"""The numbers and the [Rules] section of a FIS file (split from :mod:`fuzzyctl.formats.fis`).

A rule base within the size limit can have hundreds of thousands of lines, so the common
rule line - whole term numbers, a weight, a connection of 1 or 2 - is read by one regular
expression and built without further calls; every other line takes the general path, which
gives the same rules and the same diagnostics.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Protocol

from fuzzyctl.diagnostics import warning
from fuzzyctl.formats.common.basics import Reporter, parse_number, power_hedge
from fuzzyctl.formats.common.expr import eval_constant, parse_expr
from fuzzyctl.formats.common.terms import TS_KINDS as TS_SHAPE_KINDS
from fuzzyctl.formats.fis.names import FUZZYLITE_HEDGE_CODES
from fuzzyctl.limits import shorten
from fuzzyctl.model import (
    And,
    Conclusion,
    Condition,
    FunctionMF,
    Is,
    MembershipFunction,
    Or,
    Rule,
    ShapeMF,
    Span,
    Term,
)

ANY_CODE = 99
TS_KINDS = TS_SHAPE_KINDS


def is_ts_term(mf: MembershipFunction) -> bool:
    """A Takagi-Sugeno output term: constant, linear, or a function of the variables."""
    return (isinstance(mf, ShapeMF) and mf.kind in TS_KINDS) or (
        isinstance(mf, FunctionMF) and mf.argument is None
    )


_SEPARATORS = re.compile(r"[\s,;]+")


@lru_cache(maxsize=4096)
def _entry(part: str) -> float | str:
    """The value of one entry of a number list, or why it is not a number (a file may
    repeat the same expression on every line: it is parsed once)."""
    try:
        return parse_number(part)
    except ValueError:
        try:  # MATLAB evaluates entries such as -pi/4
            return eval_constant(parse_expr(part))
        except (ValueError, ZeroDivisionError) as exc:
            return str(exc)


def numbers(text: str, rep: Reporter, line: int, what: str) -> list[float]:
    """The numbers of a MATLAB vector or rule field (separated by blanks, commas or
    semicolons), or a diagnostic naming the entry that is not one."""
    parts = _SEPARATORS.split(text.strip())
    try:  # the common case, at once: plain finite numbers
        values = [float(p) for p in parts if p]
    except ValueError:
        pass
    else:
        if math.inf not in values and -math.inf not in values:
            return values
    out: list[float] = []
    for part in parts:
        if not part:
            continue
        value = _entry(part)
        if isinstance(value, str):
            # the entry, shortened (it may be 5001 digits or 1000 parentheses), and why
            shown = shorten(part, 40, 30)
            raise rep.fail(f"{what}: expected numbers, found {shown!r} ({value})", line, code="fis-number")
        out.append(value)
    return out


def hedges_of(code: float, dialect: str, rep: Reporter, line: int) -> tuple[int, tuple[str, ...], bool]:
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


class _Var(Protocol):
    @property
    def name(self) -> str: ...
    @property
    def terms(self) -> Sequence[Term]: ...


@dataclass(frozen=True)
class _Side:
    """What the rules need of the variables of one side: names, term names, whether every
    term is Takagi-Sugeno."""

    names: list[str]
    terms: list[list[str]]
    sugeno: list[bool]


def _side(variables: Sequence[_Var]) -> _Side:
    return _Side(
        [v.name for v in variables],
        [[t.name for t in v.terms] for v in variables],
        [all(is_ts_term(t.mf) for t in v.terms) for v in variables],
    )


_RULE = re.compile(r"^(?P<ante>[^,]*),(?P<cons>[^(]*)\((?P<w>[^)]*)\)\s*:\s*(?P<conn>\S+)\s*$")
# "1 -2, 1 (1) : 1": whole term numbers (under 1e9, so never a hedge nor out of range of
# hedges_of) and a plain weight; the general path reads such a line to the same values.
_PLAIN_RULE = re.compile(
    r"(-?[0-9]{1,9}(?:[ \t]+-?[0-9]{1,9})*)[ \t]*,[ \t]*(-?[0-9]{1,9}(?:[ \t]+-?[0-9]{1,9})*)"
    r"[ \t]*\(([0-9]{1,20}(?:\.[0-9]{0,20})?)\)[ \t]*:[ \t]*([12])"
)

# Version 1.0's "1 -2 1 1 1" of whole numbers under 1e9 (the last two: weight and connection).
_PLAIN_V1 = re.compile(r"-?[0-9]{1,9}(?:[ \t]+-?[0-9]{1,9})*")

_Fields = tuple[list[float] | list[int], list[float] | list[int], float, float]


def _fields(text: str, rep: Reporter, line: int, n_in: int, n_out: int) -> _Fields:
    """Antecedent codes, consequent codes, weight and connection of any rule line."""
    m = _RULE.match(text)
    if m is None:
        # Version 1.0 writes "i1 i2 o1 w c" without punctuation.
        values = numbers(text.replace("(", " ").replace(")", " ").replace(":", " "), rep, line, "rule")
        if len(values) != n_in + n_out + 2:
            raise rep.fail(
                f"rule: expected '{' '.join(['i'] * n_in)}, {' '.join(['o'] * n_out)} (weight) : 1|2'",
                line,
                code="fis-rule-syntax",
            )
        return values[:n_in], values[n_in : n_in + n_out], values[-2], values[-1]
    ante = numbers(m.group("ante"), rep, line, "rule antecedent")
    cons = numbers(m.group("cons"), rep, line, "rule consequent")
    weight_list = numbers(m.group("w"), rep, line, "rule weight")
    conn_list = numbers(m.group("conn"), rep, line, "rule connection")
    if len(weight_list) != 1 or len(conn_list) != 1:
        raise rep.fail("rule: weight and connection must be single numbers", line, code="fis-rule-syntax")
    return ante, cons, weight_list[0], conn_list[0]


def rules(
    lines: list[tuple[str, int]],
    inputs: Sequence[_Var],
    outputs: Sequence[_Var],
    rep: Reporter,
    dialect: str,
) -> list[Rule]:
    """The rules of the [Rules] section's ``(text, line number)`` lines."""
    out: list[Rule] = []
    n_in, n_out = len(inputs), len(outputs)
    ins, outs = _side(inputs), _side(outputs)
    plain_match, plain_v1 = _PLAIN_RULE.fullmatch, _PLAIN_V1.fullmatch
    source = rep.lines
    for text, line in lines:
        plain = plain_match(text)
        if plain is not None:
            ante_text, cons_text, weight_text, conn_text = plain.groups()
            ante: list[float] | list[int] = list(map(int, ante_text.split()))
            cons: list[float] | list[int] = list(map(int, cons_text.split()))
            weight_value, conn_value = float(weight_text), float(conn_text)
        elif plain_v1(text) is not None and len(values := text.split()) == n_in + n_out + 2:
            ante = list(map(int, values[:n_in]))
            cons = list(map(int, values[n_in : n_in + n_out]))
            weight_value, conn_value = float(values[-2]), float(values[-1])
        else:
            ante, cons, weight_value, conn_value = _fields(text, rep, line, n_in, n_out)
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
        # rep.span(line), once for the rule, all its parts and a warning about it
        raw = source[line - 1]
        body = raw.lstrip()
        column = len(raw) - len(body) + 1
        span = Span(line, column, line, column + (len(body.rstrip()) or 1))
        if not 0.0 <= weight_value <= 1.0:
            rep.items.append(
                warning(
                    f"rule weight {weight_value:g} is outside [0, 1]", span, code="fis-weight", file=rep.path
                )
            )
        rule = _rule(ante, cons, weight_value, conn_value, ins, outs, rep, dialect, line, span, len(out) + 1)
        if rule is not None:
            out.append(rule)
    return out


def _rule(
    ante: list[float] | list[int],
    cons: list[float] | list[int],
    weight_value: float,
    conn_value: float,
    ins: _Side,
    outs: _Side,
    rep: Reporter,
    dialect: str,
    line: int,
    span: Span,
    number: int,
) -> Rule | None:
    """One rule from its codes (None, with a warning, for a rule that is dropped)."""
    operands: list[Condition] = []
    always = False
    hedges: tuple[str, ...]
    for name, terms, code in zip(ins.names, ins.terms, ante, strict=True):
        if code == 0:
            continue
        if isinstance(code, int):
            index, hedges, negated = abs(code), (), code < 0
        else:
            index, hedges, negated = hedges_of(code, dialect, rep, line)
        if hedges == ("any",):
            # fuzzylite's "x is any" holds with degree 1
            if negated:
                raise rep.fail("'not any' (never true) in a rule is not supported", line, code="fis-hedge")
            always = True
            continue
        operands.append(Is(name, _term(terms, index, f"{name!r}", rep, line), negated, hedges, span))
    condition: Condition | None
    if not operands:
        if conn_value == 2.0 and not always:
            rep.warning(
                "rule has no antecedent and connection OR: it never fires (MATLAB); dropped",
                line,
                code="fis-empty-rule",
            )
            return None
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
        condition = And(tuple(operands), span)
    else:
        condition = Or(tuple(operands), span)
    if always and conn_value == 2.0:
        condition = None  # "x is any OR ..." is 1
    conclusions = _conclusions(cons, outs, rep, dialect, line, span)
    if not conclusions:
        rep.warning("rule concludes nothing (all consequents 0); dropped", line, code="fis-empty-rule")
        return None
    weight = None if weight_value == 1.0 else weight_value
    return Rule(str(number), condition, conclusions, span, weight=weight)


def _term(terms: Sequence[str], index: int, what: str, rep: Reporter, line: int) -> str:
    """The name of MF ``index`` (1-based) of a variable, or the error a rule naming an MF the
    variable does not have gets."""
    if not 1 <= index <= len(terms):
        raise rep.fail(
            f"rule refers to MF{index} of {what}, which has {len(terms)}", line, code="fis-rule-index"
        )
    return terms[index - 1]


def _conclusions(
    cons: list[float] | list[int], outs: _Side, rep: Reporter, dialect: str, line: int, span: Span
) -> tuple[Conclusion, ...]:
    conclusions: list[Conclusion] = []
    running: tuple[str, ...] = ()
    hedges: tuple[str, ...]
    for name, terms, sugeno, code in zip(outs.names, outs.terms, outs.sugeno, cons, strict=True):
        if code == 0:
            continue
        if code < 0:
            raise rep.fail(
                f"negated consequent (-{abs(code):g}) for {name!r} is not supported",
                line,
                code="fis-unsupported",
            )
        if isinstance(code, int):
            index, hedges = code, ()
        else:
            index, hedges, _ = hedges_of(code, dialect, rep, line)
        if dialect == "fuzzylite":
            # fuzzylite reads the FIS as rule text and hedges a running degree (see fll.py):
            # a conclusion without hedges of its own still gets the earlier ones
            hedges = running = (*hedges, *running)
        elif hedges:
            if not sugeno:
                raise rep.fail(
                    f"a hedge on the Mamdani consequent of {name!r} is not supported",
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
        conclusions.append(
            Conclusion(name, _term(terms, index, f"output {name!r}", rep, line), None, span, hedges)
        )
    return tuple(conclusions)
