"""Hypothesis strategies for whole models (used by the JSON round trip)."""

from __future__ import annotations

from hypothesis import strategies as st

from fuzzyctl import model as m

names = st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,6}", fullmatch=True)
# NaN only where the model keeps one NaN object (Default); elsewhere NaN != NaN breaks ==.
numbers = st.floats(allow_nan=False, allow_infinity=True) | st.integers(-5, 5).map(float)
spans = st.none() | st.builds(
    m.Span,
    st.integers(1, 99),
    st.integers(1, 80),
    st.none() | st.integers(1, 99),
    st.none() | st.integers(1, 80),
)
params = numbers | st.builds(m.Ref, names, spans)
points = st.lists(st.builds(m.Point, params, params, spans), min_size=1, max_size=4).map(tuple)
exprs = st.recursive(
    st.builds(m.Num, numbers) | st.builds(m.Name, names),
    lambda inner: (
        st.builds(m.Unary, st.sampled_from(["-", "+"]), inner)
        | st.builds(m.Binary, st.sampled_from(["+", "-", "*", "/", "^", "%"]), inner, inner)
        | st.builds(m.Call, st.sampled_from(["sin", "exp", "lt"]), st.lists(inner, max_size=2).map(tuple))
    ),
    max_leaves=6,
)
mfs = st.one_of(
    st.builds(m.PointsMF, points),
    st.builds(m.SingletonMF, params),
    st.builds(m.SingletonsMF, points),
    st.builds(m.ShapeMF, st.sampled_from(sorted(m.SHAPES)), st.lists(params, max_size=4).map(tuple), params),
    st.builds(m.FunctionMF, exprs, st.text(max_size=5), st.none() | names),
)
comments = st.lists(st.text(max_size=8), max_size=2).map(tuple)
terms = st.builds(m.Term, names, mfs, spans, comments)
ranges = st.none() | st.builds(m.Range, numbers, numbers, spans)
hedges = st.lists(st.sampled_from(["very", "somewhat", "extremely", "pow:3"]), max_size=2).map(tuple)
conditions = st.recursive(
    st.builds(m.Is, names, names, st.booleans(), hedges, spans) | st.builds(m.Degree, names, spans),
    lambda inner: (
        st.builds(m.Not, inner, spans)
        | st.builds(m.And, st.lists(inner, min_size=2, max_size=3).map(tuple), spans)
        | st.builds(m.Or, st.lists(inner, min_size=2, max_size=3).map(tuple), spans)
    ),
    max_leaves=5,
)
conclusions = st.builds(m.Conclusion, names, st.none() | names, st.none() | params, spans, hedges)
rules = st.builds(
    m.Rule,
    names,
    st.none() | conditions,
    st.lists(conclusions, min_size=1, max_size=2).map(tuple),
    spans,
    comments,
    st.none() | params,
)
item_spans = st.lists(
    st.tuples(
        st.sampled_from(["act", "accu", "method"]), st.builds(m.Span, st.integers(1, 9), st.integers(1, 9))
    ),
    max_size=2,
).map(tuple)
ops = st.none() | st.sampled_from(["MIN", "PROD", "MAX", "EINSTEIN"])
rule_blocks = st.builds(
    m.RuleBlock,
    st.none() | names,
    st.lists(rules, max_size=3).map(tuple),
    ops,
    ops,
    ops,
    ops,
    spans,
    comments,
    st.booleans(),
    st.none() | st.just("Highest 2"),
    item_spans,
)
initials = st.none() | st.booleans() | numbers | st.text(max_size=4)
variables = st.builds(
    m.Variable,
    names,
    st.sampled_from(list(m.VarKind)),
    st.sampled_from(["REAL", "INT"]),
    initials,
    ranges,
    spans,
    comments,
)
defaults = st.none() | st.builds(m.Default, st.none() | numbers | st.just(float("nan")), st.booleans(), spans)
fuzzify = st.builds(
    m.FuzzifyBlock, names, st.lists(terms, max_size=3).map(tuple), ranges, spans, comments, st.booleans()
)
defuzzify = st.builds(
    m.DefuzzifyBlock,
    names,
    st.lists(terms, max_size=3).map(tuple),
    ranges,
    st.none() | st.just("COG"),
    defaults,
    ops,
    spans,
    comments,
    st.booleans(),
    item_spans,
)
options = st.builds(m.OptionsBlock, st.text(max_size=10), st.sampled_from(["OPTIONS", "OPTION"]), spans)
blocks = st.builds(
    m.FunctionBlock,
    st.none() | names,
    st.lists(variables, max_size=3).map(tuple),
    st.lists(fuzzify, max_size=2).map(tuple),
    st.lists(defuzzify, max_size=2).map(tuple),
    st.lists(rule_blocks, max_size=2).map(tuple),
    st.lists(options, max_size=1).map(tuple),
    spans,
    comments,
)
documents = st.builds(m.Document, st.lists(blocks, min_size=1, max_size=2).map(tuple), st.none(), comments)
