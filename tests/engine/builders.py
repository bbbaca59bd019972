"""Small helpers that build models in Python (the tests do not depend on the FCL parser)."""

from __future__ import annotations

from collections.abc import Sequence

from fuzzyctl import model as m


def pts(*xy: tuple[float, float]) -> m.PointsMF:
    return m.PointsMF(tuple(m.Point(x, y) for x, y in xy))


def shape(kind: str, *params: float, height: float = 1.0) -> m.ShapeMF:
    return m.ShapeMF(kind, tuple(params), height)


def single(v: float | m.Ref) -> m.SingletonMF:
    return m.SingletonMF(v)


def terms(**mfs: m.MembershipFunction) -> tuple[m.Term, ...]:
    return tuple(m.Term(name, mf) for name, mf in mfs.items())


def var_in(*names: str) -> tuple[m.Variable, ...]:
    return tuple(m.Variable(n, m.VarKind.INPUT) for n in names)


def var_out(*names: str) -> tuple[m.Variable, ...]:
    return tuple(m.Variable(n, m.VarKind.OUTPUT) for n in names)


def is_(var: str, term: str, *, negated: bool = False, hedges: Sequence[str] = ()) -> m.Is:
    return m.Is(var, term, negated, tuple(hedges))


def and_(*c: m.Condition) -> m.And:
    return m.And(tuple(c))


def or_(*c: m.Condition) -> m.Or:
    return m.Or(tuple(c))


def then(var: str, term: str | None = None, weight: float | m.Ref | None = None) -> m.Conclusion:
    return m.Conclusion(var, term, weight)


def rule(label: str, cond: m.Condition | None, *concl: m.Conclusion) -> m.Rule:
    return m.Rule(label, cond, tuple(concl))


def figure7() -> m.FunctionBlock:
    """IEC 61131-7 figure 7 (also examples/figure7.fcl)."""
    return m.FunctionBlock(
        "Fuzzy_FB",
        variables=var_in("temp", "pressure") + var_out("valve"),
        fuzzify=(
            m.FuzzifyBlock("temp", terms(cold=pts((3, 1), (27, 0)), hot=pts((3, 0), (27, 1)))),
            m.FuzzifyBlock("pressure", terms(low=pts((55, 1), (95, 0)), high=pts((55, 0), (95, 1)))),
        ),
        defuzzify=(
            m.DefuzzifyBlock(
                "valve",
                terms(drainage=single(-100.0), closed=single(0.0), inlet=single(100.0)),
                method="COGS",
                default=m.Default(0.0),
            ),
        ),
        rule_blocks=(
            m.RuleBlock(
                "No1",
                (
                    rule("1", and_(is_("temp", "cold"), is_("pressure", "low")), then("valve", "inlet")),
                    rule(
                        "2", and_(is_("temp", "cold"), is_("pressure", "high")), then("valve", "closed", 0.8)
                    ),
                    rule("3", and_(is_("temp", "hot"), is_("pressure", "low")), then("valve", "closed")),
                    rule("4", and_(is_("temp", "hot"), is_("pressure", "high")), then("valve", "drainage")),
                ),
                and_op="MIN",
                accu="MAX",
            ),
        ),
    )


def mamdani(
    in_terms: dict[str, dict[str, m.MembershipFunction]],
    out_terms: dict[str, m.MembershipFunction],
    rules: Sequence[m.Rule],
    *,
    out: str = "y",
    method: str = "COG",
    rng: tuple[float, float] | None = None,
    and_op: str | None = None,
    or_op: str | None = None,
    act: str | None = None,
    accu: str | None = None,
    default: m.Default | None = None,
) -> m.FunctionBlock:
    """A one-output Mamdani block."""
    return m.FunctionBlock(
        "test",
        variables=var_in(*in_terms) + var_out(out),
        fuzzify=tuple(m.FuzzifyBlock(v, terms(**ts)) for v, ts in in_terms.items()),
        defuzzify=(
            m.DefuzzifyBlock(out, terms(**out_terms), m.Range(*rng) if rng else None, method, default),
        ),
        rule_blocks=(m.RuleBlock("rb", tuple(rules), and_op, or_op, act, accu),),
    )
