"""A guard against plan changes: the generator refuses plan fields it does not implement.

The plan is the contract between the engine and the code generators.  When the engine grows a
new semantic switch (a new field with a default that keeps the old behaviour), plans that use
it must not be generated as if the switch were off: the generator names the field instead."""

from __future__ import annotations

import dataclasses

from fuzzyctl.codegen.context import Gen

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
    "InputPlan": {"name", "default", "degree"},
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
    },
    "RulePlan": {"label", "block", "condition", "act", "conclusions"},
    "Slot": {"index"},
    "TermPlan": {"name", "kind", "params", "height", "expr", "pwl"},
}


def check_known_fields(g: Gen, obj: object, where: str = "plan") -> None:
    if isinstance(obj, tuple | list):
        for item in obj:
            check_known_fields(g, item, where)
        return
    if not dataclasses.is_dataclass(obj) or isinstance(obj, type):
        return
    known = _KNOWN_FIELDS.get(type(obj).__name__)
    if known is None:
        raise g.refuse(f"{where}: {type(obj).__name__}", "a plan element this generator does not know")
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        if f.name not in known:
            default = f.default if f.default is not dataclasses.MISSING else None
            if value != default and value not in ((), None, False, 0, 0.0):
                raise g.refuse(
                    f"{where}: {type(obj).__name__}.{f.name} = {value!r}",
                    "a semantic switch this generator does not implement",
                )
            continue
        if f.name != "grid":  # the grid is data, derived from the terms
            check_known_fields(
                g,
                value,
                getattr(obj, "name", where) if isinstance(getattr(obj, "name", None), str) else where,
            )
