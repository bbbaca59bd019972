"""Seeded random fuzzy systems for the differential fuzzer (issue 25, point 2).

The operators, methods and shapes are read from the engine's own tables - the AND/OR norms
(:data:`fuzzyctl.engine.semantics.operators.TNORMS` / ``SNORMS``, every t-norm also being an
activation), the accumulations (``ACCU_NAMES``), the defuzzification methods
(:data:`fuzzyctl.model.DEFUZZ_METHODS`), the shapes (:data:`fuzzyctl.model.SHAPES` with
their parameter names, plus IEC points and singletons) and the hedges - so that a kind
added to a table is drawn without touching this file.  System ``k`` takes entry ``k`` (mod
the table's length, in a seeded order) of every table, so any ``len(table)`` consecutive
systems walk all of it; the rest is drawn.

Parameters are ordinary (sorted inside the universe) most of the time and otherwise
degenerate or extreme: zero width (all parameters equal), equal points, negated (negative
slopes and widths), a huge centre (1e300), subnormals (5e-324, 1e-310), plateaus (flat
tops, equal degrees), singletons at the range ends.  Input vectors are chosen by
:func:`tests.fuzz.differential.vectors` (breakpoints, range ends, outside the range)."""

from __future__ import annotations

import math
import random
from typing import Any

from fuzzyctl import model as m
from fuzzyctl.engine.semantics import operators as ops
from fuzzyctl.engine.semantics.shapes import TS_KINDS

LO, HI = 0.0, 10.0
EXTREMES = (1e300, -1e300, 5e-324, -5e-324, 1e-310, 0.0, 1e-12, 1e12)
#: methods whose output terms are singletons or Takagi-Sugeno terms
SINGLETON_METHODS = frozenset({"COGS", "WTAVER", "WTSUM", "COGF"})


def _tables(seed: int) -> dict[str, list[str]]:
    """Every table, each in its own seeded order."""
    rng = random.Random(seed)
    tables = {
        "and": sorted(ops.TNORMS),
        "or": sorted(ops.SNORMS),
        "act": sorted(ops.TNORMS),
        "accu": sorted(ops.ACCU_NAMES),
        "method": sorted(m.DEFUZZ_METHODS),
        "shape": [
            *sorted(k for k, s in m.SHAPES.items() if k not in TS_KINDS and not s.variadic),
            "points",
            "singleton",
        ],
        "hedge": sorted(m.HEDGES),
    }
    for v in tables.values():
        rng.shuffle(v)
    return tables


def _ordinary(rng: random.Random, n: int, lo: float, hi: float) -> list[float]:
    return sorted(round(lo + rng.random() * (hi - lo), rng.choice([1, 3, 12])) for _ in range(n))


def params(rng: random.Random, kind: str, lo: float = LO, hi: float = HI) -> tuple[float, ...]:
    """Parameters for shape ``kind`` (by the number its :data:`SHAPES` entry names)."""
    n = len(m.SHAPES[kind].params)
    mode = rng.choices(["ordinary", "zero", "negate", "extreme", "equal2"], [16, 1, 1, 1, 1])[0]
    p = _ordinary(rng, n, lo, hi)
    if kind not in (
        "triangle",
        "trapezoid",
        "rectangle",
        "ramp",
        "sshape",
        "zshape",
        "pishape",
        "arc",
        "semiellipse",
        "binary",
        "concave",
    ):  # (centre, width/slope, ...) kinds
        p = [x if k % 2 == 0 else rng.choice([0.5, 1.0, 2.0, 0.05, 4.0]) for k, x in enumerate(p)]
    if mode == "zero":
        p = [p[0]] * n
    elif mode == "negate":
        k = rng.randrange(n)
        p[k] = -p[k] if p[k] else -1.0
    elif mode == "extreme":
        p[rng.randrange(n)] = rng.choice(EXTREMES)
    elif mode == "equal2" and n >= 2:
        k = rng.randrange(n - 1)
        p[k + 1] = p[k]
    return tuple(p)


def term(rng: random.Random, kind: str, lo: float = LO, hi: float = HI) -> m.MembershipFunction:
    if kind == "singleton":
        return m.SingletonMF(rng.choice([lo, hi, round(lo + rng.random() * (hi - lo), 3)]))
    if kind == "points":
        k = rng.randint(2, 5)
        xs = _ordinary(rng, k, lo, hi)
        if rng.random() < 0.2:
            xs[rng.randrange(k - 1)] = xs[-1]  # equal points: a vertical edge
            xs.sort()
        ys = [rng.choice([0.0, 0.0, 0.3, 0.5, 1.0, 1.0]) for _ in xs]
        if rng.random() < 0.3:
            ys = [ys[0]] * k  # a plateau
        return m.PointsMF(tuple(m.Point(x, y) for x, y in zip(xs, ys, strict=True)))
    return m.ShapeMF(kind, params(rng, kind, lo, hi))


def _condition(
    rng: random.Random, inputs: dict[str, list[str]], hedges: list[str], depth: int = 0
) -> m.Condition:
    choice = rng.randint(0, 5 if depth < 2 else 1)
    if choice <= 1:
        var = rng.choice(sorted(inputs))
        hs = (rng.choice(hedges),) if hedges and rng.random() < 0.15 else ()
        return m.Is(var, rng.choice(inputs[var]), negated=choice == 1 and rng.random() < 0.5, hedges=hs)
    if choice == 2:
        return m.Not(_condition(rng, inputs, hedges, depth + 1))
    kids = tuple(_condition(rng, inputs, hedges, depth + 1) for _ in range(rng.randint(2, 3)))
    return m.And(kids) if choice in (3, 4) else m.Or(kids)


def _output_terms(
    rng: random.Random, method: str, shape: str, names: list[str]
) -> list[m.MembershipFunction]:
    if method in SINGLETON_METHODS:
        out: list[m.MembershipFunction] = []
        for _ in names:
            r = rng.random()
            if method in ("WTAVER", "WTSUM") and r < 0.3:
                out.append(m.ShapeMF("constant", (round(rng.uniform(LO, HI), 3),)))
            else:
                out.append(m.SingletonMF(rng.choice([LO, HI, round(rng.uniform(LO, HI), 3)])))
        return out
    if shape == "singleton":  # singletons are not mixed with sets in one output
        return [term(rng, "singleton") for _ in names]
    kinds = [shape] + [rng.choice(["triangle", "trapezoid", "points", shape]) for _ in names[1:]]
    return [term(rng, k) for k in kinds]


def system(k: int, seed: int) -> m.FunctionBlock:
    """Random system ``k`` of the sequence ``seed``: the same for the same arguments."""
    t = _tables(seed)
    rng = random.Random(f"{seed}:{k}")

    def pick(name: str, salt: int = 0) -> str:
        table = t[name]
        return table[(k + salt) % len(table)]

    inputs: dict[str, list[str]] = {}
    fuzz = []
    for i in range(rng.randint(1, 2)):
        name = f"x{i}"
        names = [f"t{j}" for j in range(rng.randint(2, 3))]
        inputs[name] = names
        kinds = [pick("shape", 3 * i + j) if j == 0 else rng.choice(t["shape"]) for j in range(len(names))]
        rng_ = m.Range(LO, HI) if rng.random() < 0.7 else None
        fuzz.append(
            m.FuzzifyBlock(
                name, tuple(m.Term(n, term(rng, kk)) for n, kk in zip(names, kinds, strict=True)), rng_
            )
        )
    method = pick("method")
    out_names = [f"o{j}" for j in range(rng.randint(2, 4))]
    out_mfs = _output_terms(rng, method, pick("shape", 7), out_names)
    rules = []
    for r in range(rng.randint(1, 5)):
        w = rng.choice([None, None, 0.5, 0.0, 1.0, round(rng.random(), 3)])
        rules.append(
            m.Rule(
                str(r + 1),
                _condition(rng, inputs, t["hedge"]),
                (m.Conclusion("y", rng.choice(out_names), w),),
            )
        )
    default = rng.choice([m.Default(-1.0), m.Default(math.nan), m.Default(no_change=True), m.Default(LO)])
    and_op = pick("and")
    or_op = pick("or") if rng.random() < 0.5 else None
    if or_op is not None and rng.random() < 0.5:
        or_op = ops.AND_TO_OR[and_op]  # mostly consistent pairs, sometimes mixed
    out_range = m.Range(LO, HI) if rng.random() < 0.9 else None
    return m.FunctionBlock(
        f"rnd{k}",
        variables=(*(m.Variable(v, m.VarKind.INPUT) for v in inputs), m.Variable("y", m.VarKind.OUTPUT)),
        fuzzify=tuple(fuzz),
        defuzzify=(
            m.DefuzzifyBlock(
                "y",
                tuple(m.Term(n, mf) for n, mf in zip(out_names, out_mfs, strict=True)),
                out_range,
                method,
                default,
            ),
        ),
        rule_blocks=(m.RuleBlock("rb", tuple(rules), and_op, or_op, pick("act", 1), pick("accu", 2)),),
    )


def describe(fb: m.FunctionBlock) -> dict[str, Any]:
    """The tables' entries system ``fb`` uses (for coverage counts)."""
    rb, d = fb.rule_blocks[0], fb.defuzzify[0]
    shapes = {
        type(t.mf).__name__ if not isinstance(t.mf, m.ShapeMF) else t.mf.kind
        for t in (*(t for f in fb.fuzzify for t in f.terms), *(t for d in fb.defuzzify for t in d.terms))
    }
    return {
        "and": rb.and_op,
        "or": rb.or_op,
        "act": rb.act,
        "accu": rb.accu,
        "method": d.method,
        "shapes": shapes,
    }
