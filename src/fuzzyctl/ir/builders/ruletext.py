"""A rule of a lowered plan as FCL-like text, for the comment above the code that evaluates it
(so a reader finds the rule in the generated block).  The text is the model's words: every
renderer passes it through its target's comment escaping."""

from __future__ import annotations

from fuzzyctl.engine.plan import (
    CAnd,
    CChained,
    CDegree,
    CNot,
    CondPlan,
    COr,
    CTerm,
    Plan,
    PParam,
    RulePlan,
    Slot,
)

# Binding strength as in FCL (OR 1, AND 2): a weaker operand is parenthesised.
_STRENGTH = {CAnd: 2, COr: 1}


def _param(plan: Plan, p: PParam) -> str:
    # a number is a tunable entry of the block (its value is in the parameter array)
    return plan.inputs[p.index].name if isinstance(p, Slot) else "a weight"


def condition_text(plan: Plan, c: CondPlan) -> str:
    if isinstance(c, CTerm | CChained):
        if isinstance(c, CTerm):
            fi = plan.fuzzy_inputs[c.var]
            var, term = fi.name, fi.terms[c.term].name
        else:
            var, term = plan.chained[c.var].name, plan.chained[c.var].terms[c.term]
        words = [var, "IS", *(["NOT"] if c.negated else []), *c.hedges, term]
        return " ".join(words)
    if isinstance(c, CDegree):
        if c.slot is not None:
            return plan.inputs[c.slot].name
        return plan.chained[c.chained or 0].name
    if isinstance(c, CNot):
        inner = condition_text(plan, c.operand)
        return f"NOT ({inner})" if isinstance(c.operand, CAnd | COr | CNot) else f"NOT {inner}"
    if isinstance(c, CAnd | COr):
        own = _STRENGTH[type(c)]
        parts = []
        for o in c.operands:
            text = condition_text(plan, o)
            if isinstance(o, CAnd | COr) and _STRENGTH[type(o)] <= own:
                text = f"({text})"
            parts.append(text)
        return (" AND " if isinstance(c, CAnd) else " OR ").join(parts)
    return "TRUE"


def rule_text(plan: Plan, rule: RulePlan) -> str:
    """``IF condition THEN conclusions`` of one rule (``WITH`` weights named, not printed)."""
    concl = []
    for cp in rule.conclusions:
        if cp.outputs:
            op = plan.outputs[cp.outputs[0]]
            var = op.name
            term = op.terms[cp.term].name if cp.term is not None else None
        else:
            ch = plan.chained[cp.chained[0]]
            var = ch.name
            term = ch.terms[cp.term] if cp.term is not None else None
        text = var if term is None else f"{var} IS {' '.join([*cp.hedges, term])}"
        if isinstance(cp.weight, Slot) or cp.weight != 1.0:
            text += f" WITH {_param(plan, cp.weight)}"  # numbers are tunable: named, not printed
        concl.append(text)
    weight = ""
    if isinstance(rule.weight, Slot) or rule.weight != 1.0:
        weight = f" (weighted by {_param(plan, rule.weight)})"
    return f"IF {condition_text(plan, rule.condition)} THEN {', '.join(concl)}{weight}"
