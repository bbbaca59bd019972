"""Hypothesis strategies for random *valid* FCL models (reusable by other test suites)."""

from __future__ import annotations

from hypothesis import strategies as st

from fuzzyctl.model import (
    And,
    Conclusion,
    Condition,
    Default,
    DefuzzifyBlock,
    Document,
    FunctionBlock,
    FuzzifyBlock,
    Is,
    Not,
    Or,
    Point,
    PointsMF,
    Range,
    Rule,
    RuleBlock,
    ShapeMF,
    SingletonMF,
    Term,
    Variable,
    VarKind,
)

KEYWORDS = {
    "and",
    "or",
    "not",
    "is",
    "if",
    "then",
    "with",
    "var",
    "term",
    "rule",
    "range",
    "nc",
    "nan",
    "inf",
    "function",
    "method",
    "default",
    "accu",
    "act",
    "options",
    "option",
    "fuzzify",
    "defuzzify",
    "ruleblock",
    "singletons",
    "end_var",
    "any",
    "infinity",
}
names = st.from_regex(r"[A-Za-z][A-Za-z0-9_]{0,8}", fullmatch=True).filter(
    lambda s: s.lower() not in KEYWORDS
)
numbers = st.floats(-1e6, 1e6, allow_nan=False).map(lambda x: round(x, 3))
degrees = st.sampled_from([0.0, 0.25, 0.5, 1.0])


@st.composite
def points_mf(draw: st.DrawFn) -> PointsMF:
    xs = sorted(draw(st.lists(numbers, min_size=1, max_size=6)))
    return PointsMF(tuple(Point(x, draw(degrees)) for x in xs))


@st.composite
def shape_mf(draw: st.DrawFn) -> ShapeMF:
    kind = draw(
        st.sampled_from(
            [
                "triangle",
                "trapezoid",
                "gaussian",
                "bell",
                "sigmoid",
                "cosine",
                "ramp",
                "pishape",
                "dsigmoid",
                "psigmoid",
                "gaussian2",
                "spike",
                "concave",
            ]
        )
    )
    n = {"triangle": 3, "trapezoid": 4, "pishape": 4, "dsigmoid": 4, "psigmoid": 4, "gaussian2": 4}.get(
        kind, 2
    )
    if kind == "bell":
        n = 3
    params = sorted(draw(st.lists(numbers, min_size=n, max_size=n)))
    height = draw(st.sampled_from([1.0, 0.5]))
    return ShapeMF(kind, tuple(params), height)


@st.composite
def conditions(draw: st.DrawFn, atoms: list[Is], depth: int = 2) -> Condition:
    if depth == 0 or draw(st.booleans()):
        atom = draw(st.sampled_from(atoms))
        return Is(atom.variable, atom.term, draw(st.booleans()))
    kind = draw(st.sampled_from(["and", "or", "not"]))
    if kind == "not":
        return Not(draw(conditions(atoms, depth - 1)))
    operands = tuple(draw(st.lists(conditions(atoms, depth - 1), min_size=2, max_size=3)))
    # A chain never directly holds its own kind: the parser flattens unparenthesised chains.
    return And(operands) if kind == "and" else Or(operands)


@st.composite
def function_blocks(draw: st.DrawFn) -> FunctionBlock:
    var_names = draw(st.lists(names, min_size=2, max_size=5, unique_by=str.lower))
    n_in = draw(st.integers(1, len(var_names) - 1))
    inputs = var_names[:n_in]
    outputs = var_names[n_in:]
    variables = [Variable(n, VarKind.INPUT) for n in inputs] + [Variable(n, VarKind.OUTPUT) for n in outputs]
    fuzzify = []
    atoms: list[Is] = []
    for v in inputs:
        terms = draw(st.lists(names, min_size=1, max_size=3, unique=True))
        fuzzify.append(
            FuzzifyBlock(v, tuple(Term(t, draw(st.one_of(points_mf(), shape_mf()))) for t in terms))
        )
        atoms.extend(Is(v, t) for t in terms)
    defuzzify = []
    heads: list[tuple[str, str]] = []
    for v in outputs:
        terms = draw(st.lists(names, min_size=1, max_size=3, unique=True))
        defuzzify.append(
            DefuzzifyBlock(
                v,
                tuple(Term(t, SingletonMF(draw(numbers))) for t in terms),
                draw(st.one_of(st.none(), st.just(Range(-10.0, 10.0)))),
                draw(st.sampled_from(["COGS", "COG", None])),
                draw(st.sampled_from([Default(0.0), Default(None, True), None])),
            )
        )
        heads.extend((v, t) for t in terms)
    rules = []
    for i in range(draw(st.integers(1, 4))):
        head = draw(st.lists(st.sampled_from(heads), min_size=1, max_size=2))
        weight = draw(st.sampled_from([None, 0.5, 1.0]))
        conclusions = tuple(Conclusion(v, t, weight) for v, t in head)
        rules.append(Rule(str(i + 1), draw(conditions(atoms)), conclusions))
    block = RuleBlock(
        draw(st.one_of(st.none(), names)),
        tuple(rules),
        "MIN",
        draw(st.sampled_from(["MAX", None])),
        draw(st.sampled_from(["MIN", "PROD", None])),
        "MAX",
    )
    return FunctionBlock(
        draw(st.one_of(st.none(), names)), tuple(variables), tuple(fuzzify), tuple(defuzzify), (block,)
    )


documents = st.lists(function_blocks(), min_size=1, max_size=2).map(lambda fbs: Document(tuple(fbs)))
