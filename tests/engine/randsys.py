"""Hypothesis strategies for random fuzzy systems (models built in Python)."""

from __future__ import annotations

from typing import Any

from hypothesis import strategies as st

from fuzzyctl import model as m

LO, HI = 0.0, 10.0


@st.composite
def sorted_floats(draw: Any, n: int, lo: float = LO, hi: float = HI) -> list[float]:
    xs = draw(st.lists(st.floats(lo, hi, allow_nan=False, width=32), min_size=n, max_size=n))
    return sorted(round(float(x), 3) for x in xs)


@st.composite
def pwl_term(draw: Any, lo: float = LO, hi: float = HI) -> m.MembershipFunction:
    kind = draw(st.sampled_from(["triangle", "trapezoid", "points", "rectangle"]))
    if kind == "triangle":
        a, b, c = draw(sorted_floats(3, lo, hi))
        if c - a < 0.05:
            c = a + 0.5
        return m.ShapeMF("triangle", (a, b, c))
    if kind == "trapezoid":
        a, b, c, d = draw(sorted_floats(4, lo, hi))
        if d - a < 0.05:
            d = a + 0.5
        return m.ShapeMF("trapezoid", (a, b, c, d))
    if kind == "rectangle":
        a, b = draw(sorted_floats(2, lo, hi))
        if b - a < 0.05:
            b = a + 0.5
        return m.ShapeMF("rectangle", (a, b))
    n = draw(st.integers(2, 5))
    xs = draw(sorted_floats(n, lo, hi))
    ys = draw(st.lists(st.sampled_from([0.0, 0.25, 0.5, 0.8, 1.0]), min_size=n, max_size=n))
    ys[0] = ys[-1] = 0.0  # bounded support for the output universe hull
    if max(ys) == 0.0:
        ys[len(ys) // 2] = 1.0
    return m.PointsMF(tuple(m.Point(x, y) for x, y in zip(xs, ys, strict=True)))


@st.composite
def input_term(draw: Any) -> m.MembershipFunction:
    kind = draw(st.sampled_from(["pwl", "pwl", "gaussian", "bell", "sigmoid"]))
    if kind == "pwl":
        return draw(pwl_term())  # type: ignore[no-any-return]
    c = round(draw(st.floats(LO, HI)), 3)
    if kind == "gaussian":
        return m.ShapeMF("gaussian", (c, round(draw(st.floats(0.3, 4.0)), 3)))
    if kind == "bell":
        return m.ShapeMF(
            "bell", (c, round(draw(st.floats(0.5, 4.0)), 3), round(draw(st.floats(0.5, 4.0)), 3))
        )
    return m.ShapeMF("sigmoid", (c, round(draw(st.floats(-4.0, 4.0).filter(lambda s: abs(s) > 0.2)), 3)))


@st.composite
def condition(draw: Any, inputs: dict[str, list[str]], depth: int = 0) -> m.Condition:
    choice = draw(st.integers(0, 5 if depth < 2 else 1))
    if choice <= 1:
        var = draw(st.sampled_from(sorted(inputs)))
        return m.Is(var, draw(st.sampled_from(inputs[var])), negated=draw(st.booleans()) and choice == 1)
    if choice == 2:
        return m.Not(draw(condition(inputs, depth + 1)))
    kids = tuple(draw(st.lists(condition(inputs, depth + 1), min_size=2, max_size=3)))
    return m.And(kids) if choice in (3, 4) else m.Or(kids)


@st.composite
def system(
    draw: Any,
    *,
    methods: tuple[str, ...] = ("COG", "COA", "LM", "RM", "MOM"),
    accus: tuple[str, ...] = ("MAX", "BSUM", "SUM", "NSUM", "PROBOR"),
    ands: tuple[str, ...] = ("MIN", "PROD", "BDIF"),
    acts: tuple[str, ...] = ("MIN", "PROD"),
    smooth_output: bool = False,
    weights: bool = True,
) -> m.FunctionBlock:
    n_in = draw(st.integers(1, 2))
    inputs: dict[str, list[str]] = {}
    fuzz = []
    for i in range(n_in):
        name = f"x{i}"
        k = draw(st.integers(2, 3))
        names = [f"t{j}" for j in range(k)]
        inputs[name] = names
        fuzz.append(m.FuzzifyBlock(name, tuple(m.Term(t, draw(input_term())) for t in names)))
    k_out = draw(st.integers(2, 4))
    out_names = [f"o{j}" for j in range(k_out)]
    if smooth_output:
        out_mfs = [
            m.ShapeMF("gaussian", (round(draw(st.floats(1, 9)), 3), round(draw(st.floats(0.3, 2.5)), 3)))
            for _ in out_names
        ]
    else:
        out_mfs = [draw(pwl_term()) for _ in out_names]
    rules = []
    for r in range(draw(st.integers(1, 5))):
        w = round(draw(st.floats(0.1, 1.0)), 2) if weights and draw(st.booleans()) else None
        rules.append(
            m.Rule(
                str(r + 1), draw(condition(inputs)), (m.Conclusion("y", draw(st.sampled_from(out_names)), w),)
            )
        )
    return m.FunctionBlock(
        "random",
        variables=(*tuple(m.Variable(v, m.VarKind.INPUT) for v in inputs), m.Variable("y", m.VarKind.OUTPUT)),
        fuzzify=tuple(fuzz),
        defuzzify=(
            m.DefuzzifyBlock(
                "y",
                tuple(m.Term(n, mf) for n, mf in zip(out_names, out_mfs, strict=True)),
                m.Range(LO, HI),
                draw(st.sampled_from(methods)),
                m.Default(-1.0),
            ),
        ),
        rule_blocks=(
            m.RuleBlock(
                "rb",
                tuple(rules),
                draw(st.sampled_from(ands)),
                None,
                draw(st.sampled_from(acts)),
                draw(st.sampled_from(accus)),
            ),
        ),
    )


def input_values(draw: Any, fb: m.FunctionBlock, n: int) -> list[dict[str, float]]:
    return [{v.name: round(draw(st.floats(LO - 1, HI + 1)), 4) for v in fb.inputs} for _ in range(n)]


def describe(fb: m.FunctionBlock) -> str:
    """A compact text of a random system (for assertion messages)."""

    def mf(x: m.MembershipFunction) -> str:
        if isinstance(x, m.ShapeMF):
            return f"{x.kind}{x.params}"
        if isinstance(x, m.PointsMF):
            return "pts" + "".join(f"({p.x},{p.y})" for p in x.points)
        return repr(x)

    def cond(c: m.Condition) -> str:
        if isinstance(c, m.Is):
            return f"{c.variable} IS {'NOT ' if c.negated else ''}{c.term}"
        if isinstance(c, m.Not):
            return f"NOT ({cond(c.operand)})"
        if isinstance(c, m.Degree):
            return c.variable
        j = " AND " if isinstance(c, m.And) else " OR "
        return "(" + j.join(cond(o) for o in c.operands) + ")"

    lines = []
    for f in fb.fuzzify:
        lines.append(f"{f.variable}: " + ", ".join(f"{t.name}={mf(t.mf)}" for t in f.terms))
    for d in fb.defuzzify:
        lines.append(f"{d.variable} {d.method}: " + ", ".join(f"{t.name}={mf(t.mf)}" for t in d.terms))
    for rb in fb.rule_blocks:
        lines.append(f"AND {rb.and_op} ACT {rb.act} ACCU {rb.accu}")
        for r in rb.rules:
            lines.append(
                f"  {r.label}: IF {cond(r.condition) if r.condition else ''} THEN "
                + ", ".join(f"{c.variable} IS {c.term} WITH {c.weight}" for c in r.conclusions)
            )
    return "\n".join(lines)
