"""The benchmark controllers built directly as models (the FCL files next to this script say
the same; this module lets the benchmark run before/without the FCL reader)."""

from __future__ import annotations

from fuzzyctl import model as m

TERMS7 = ["NB", "NM", "NS", "ZE", "PS", "PM", "PB"]
PEAKS7 = [-1.0 + k / 3.0 for k in range(7)]
THIRD = 1.0 / 3.0


def _t(name: str, kind: str, *p: float) -> m.Term:
    return m.Term(name, m.ShapeMF(kind, tuple(p)))


def tipper() -> m.FunctionBlock:
    return m.FunctionBlock(
        "tipper",
        variables=(
            m.Variable("service", m.VarKind.INPUT),
            m.Variable("food", m.VarKind.INPUT),
            m.Variable("tip", m.VarKind.OUTPUT),
        ),
        fuzzify=(
            m.FuzzifyBlock(
                "service",
                (
                    _t("poor", "gaussian", 0, 1.5),
                    _t("good", "gaussian", 5, 1.5),
                    _t("excellent", "gaussian", 10, 1.5),
                ),
                m.Range(0, 10),
            ),
            m.FuzzifyBlock(
                "food",
                (_t("rancid", "trapezoid", 0, 0, 1, 3), _t("delicious", "trapezoid", 7, 9, 10, 10)),
                m.Range(0, 10),
            ),
        ),
        defuzzify=(
            m.DefuzzifyBlock(
                "tip",
                (
                    _t("cheap", "triangle", 0, 5, 10),
                    _t("average", "triangle", 10, 15, 20),
                    _t("generous", "triangle", 20, 25, 30),
                ),
                m.Range(0, 30),
                "COG",
                m.Default(None, True),
            ),
        ),
        rule_blocks=(
            m.RuleBlock(
                "mamdani",
                (
                    m.Rule(
                        "1",
                        m.Or((m.Is("service", "poor"), m.Is("food", "rancid"))),
                        (m.Conclusion("tip", "cheap"),),
                    ),
                    m.Rule("2", m.Is("service", "good"), (m.Conclusion("tip", "average"),)),
                    m.Rule(
                        "3",
                        m.Or((m.Is("service", "excellent"), m.Is("food", "delicious"))),
                        (m.Conclusion("tip", "generous"),),
                    ),
                ),
                "MIN",
                None,
                "MIN",
                "MAX",
            ),
        ),
    )


def grid49() -> m.FunctionBlock:
    terms = tuple(_t(n, "triangle", c - THIRD, c, c + THIRD) for n, c in zip(TERMS7, PEAKS7, strict=True))
    rules = tuple(
        m.Rule(
            str(i * 7 + j + 1),
            m.And((m.Is("e", TERMS7[i]), m.Is("de", TERMS7[j]))),
            (m.Conclusion("u", TERMS7[min(max(i + j - 3, 0), 6)]),),
        )
        for i in range(7)
        for j in range(7)
    )
    return m.FunctionBlock(
        "grid49",
        variables=(
            m.Variable("e", m.VarKind.INPUT),
            m.Variable("de", m.VarKind.INPUT),
            m.Variable("u", m.VarKind.OUTPUT),
        ),
        fuzzify=(m.FuzzifyBlock("e", terms, m.Range(-1, 1)), m.FuzzifyBlock("de", terms, m.Range(-1, 1))),
        defuzzify=(m.DefuzzifyBlock("u", terms, m.Range(-1, 1), "COG", m.Default(None, True)),),
        rule_blocks=(m.RuleBlock("mamdani", rules, "MIN", None, "MIN", "MAX"),),
    )
