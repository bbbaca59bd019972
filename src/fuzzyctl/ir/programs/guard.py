"""A guard against plan changes: the generator refuses plan fields it does not implement.

The plan is the contract between the engine and the code generators.  When the engine grows a
new semantic switch (a new field with a default that keeps the old behaviour), plans that use
it must not be generated as if the switch were off: the generator names the field instead."""

from __future__ import annotations

import dataclasses

from fuzzyctl.ir.state import Gen

#: The plan fields this generator implements.  A field added to the plan later (a new
#: semantic switch) with a non-default value is refused rather than silently ignored.
_KNOWN_FIELDS: dict[str, set[str]] = {
    "CAnd": {"op", "operands"},
    "CChained": {"var", "term", "hedges", "negated"},
    "CDegree": {"slot", "chained"},
    "CNot": {"operand"},
    "COr": {"op", "operands"},
    "CTerm": {"var", "term", "hedges", "negated"},
    "CTrue": set(),
    "ChainedPlan": {"name", "terms", "accu"},
    "ConclusionPlan": {"outputs", "chained", "term", "weight", "hedges"},
    "Contribution": {"rule", "conclusion", "term", "act", "weight"},
    "EBinary": {"op", "left", "right"},
    "ECall": {"function", "args"},
    "EInput": {"slot"},
    "ENum": {"value"},
    "EOutput": {"output"},
    "EUnary": {"op", "operand"},
    "EX": set(),
    "FuzzyInputPlan": {"name", "slot", "terms"},
    "GridPlan": {"xs", "left", "right", "point", "active", "shared", "solo", "min_bands", "full"},
    "InputPlan": {"name", "default", "degree", "clamp"},
    "Options": {
        "weight_before_activation",
        "firing_threshold",
        "ts_default_accu",
        "singleton_default_accu",
        "hedges_carry_over",
        "weight_whole_rule",
        "quad_rtol",
        # lowering decisions only (errors, the universe): nothing for the generator to do
        "strict",
        "span_universe",
        "ignore_declared_range",
    },
    "OutputPlan": {
        "name",
        "kind",
        "method",
        "accu",
        "terms",
        "contributions",
        "default",
        "no_change",
        "low",
        "high",
        "exact",
        "grid",
        "is_output",
        "clamp",
    },
    "Plan": {
        "name",
        "inputs",
        "fuzzy_inputs",
        "chained",
        "rules",
        "order",
        "outputs",
        "output_order",
        "options",
        "selections",
    },
    "RulePlan": {"label", "block", "condition", "act", "conclusions", "weight", "selection"},
    "SelectionPlan": {"method", "rules", "count", "threshold", "comparison"},
    "Slot": {"index"},
    "TermPlan": {"name", "kind", "params", "height", "expr", "pwl"},
}


#: How the plan's elements are called in messages (never the class names).
_ELEMENT = {
    "Plan": "function block",
    "InputPlan": "input",
    "FuzzyInputPlan": "input",
    "OutputPlan": "output",
    "TermPlan": "term",
    "RulePlan": "rule",
    "ConclusionPlan": "rule conclusion",
    "Contribution": "rule conclusion",
    "Options": "engine option",
    "ChainedPlan": "variable",
    "SelectionPlan": "rule block activation",
}


def _element(obj: object, where: str) -> str:
    kind = _ELEMENT.get(type(obj).__name__, "element")
    label = getattr(obj, "name", None) or getattr(obj, "label", None)
    return f"{kind} {label}" if isinstance(label, str) else f"{kind} of {where}"


def check_known_fields(g: Gen, obj: object, where: str = "plan") -> None:
    if isinstance(obj, tuple | list):
        for item in obj:
            check_known_fields(g, item, where)
        return
    if not dataclasses.is_dataclass(obj) or isinstance(obj, type):
        return
    known = _KNOWN_FIELDS.get(type(obj).__name__)
    if known is None:
        raise g.refuse(
            _element(obj, where),
            "a feature this version of the generator does not know; evaluate the system with "
            "fuzzyctl eval / the Python API, or update fuzzyctl",
        )
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        if f.name not in known:
            default = f.default if f.default is not dataclasses.MISSING else None
            if value != default and value not in ((), None, False, 0, 0.0):
                raise g.refuse(
                    f"{_element(obj, where)}: {f.name.replace('_', ' ')} = {value!r}",
                    "a setting this version of the generator does not implement; evaluate the "
                    "system with fuzzyctl eval / the Python API, or update fuzzyctl",
                )
            continue
        if f.name != "grid":  # the grid is data, derived from the terms
            check_known_fields(
                g,
                value,
                getattr(obj, "name", where) if isinstance(getattr(obj, "name", None), str) else where,
            )
