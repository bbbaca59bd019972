"""Random interval type-2 systems (seeded), shared by the engine tests and the PyIT2FLS
agreement tests: triangular and trapezoidal upper functions with MATLAB's scale/lag lower
functions, or explicit lower functions; Mamdani or Sugeno (constant and linear)."""

from __future__ import annotations

import dataclasses
import random

from fuzzyctl import model as m

LO, HI = 0.0, 10.0


def _triangle(rng: random.Random, lo: float, hi: float) -> tuple[float, float, float]:
    a, b, c = sorted(round(rng.uniform(lo - 3, hi + 3), 3) for _ in range(3))
    if c - a < 1.0:
        c = a + 1.0
    b = min(max(b, a + 0.1), c - 0.1)
    return a, b, c


def it2_term(rng: random.Random, name: str, lo: float, hi: float, explicit: bool) -> m.Term:
    a, b, c = _triangle(rng, lo, hi)
    upper = m.ShapeMF("triangle", (a, b, c))
    if explicit:  # a narrower triangle of the same apex, lower height
        w = rng.uniform(0.3, 0.9)
        h = round(rng.uniform(0.4, 1.0), 3)
        lower_mf = m.ShapeMF("triangle", (b - (b - a) * w, b, b + (c - b) * w), h)
        return m.Term(name, upper, lower=m.LowerMF(mf=lower_mf))
    scale = round(rng.uniform(0.5, 1.0), 3)
    lag = round(rng.uniform(0.0, 0.5), 3)
    return m.Term(name, upper, lower=m.LowerMF(scale=scale, lag=(lag,)))


def random_it2(
    seed: int, *, sugeno: bool = False, explicit: bool = False, n_inputs: int = 2
) -> m.FunctionBlock:
    rng = random.Random(seed)
    names = [f"x{i}" for i in range(n_inputs)]
    fuzzify = tuple(
        m.FuzzifyBlock(n, tuple(it2_term(rng, f"t{j}", LO, HI, explicit) for j in range(3)), m.Range(LO, HI))
        for n in names
    )
    if sugeno:
        terms = (
            *tuple(m.Term(f"o{j}", m.ShapeMF("constant", (round(rng.uniform(-5, 5), 3),))) for j in range(2)),
            m.Term(
                "lin", m.ShapeMF("linear", tuple(round(rng.uniform(-1, 1), 3) for _ in range(n_inputs + 1)))
            ),
        )
        out = m.DefuzzifyBlock("y", terms, None, "WTAVER", m.Default(0.0), type_reduction="KM")
    else:
        terms = tuple(it2_term(rng, f"o{j}", LO, HI, explicit) for j in range(3))
        out = m.DefuzzifyBlock("y", terms, m.Range(LO, HI), "COG", m.Default(5.0), type_reduction="KM")
    rules = []
    for r in range(6):
        conds = [m.Is(n, f"t{rng.randrange(3)}") for n in names]
        cond: m.Condition = m.And(tuple(conds)) if len(conds) > 1 else conds[0]
        concl = out.terms[rng.randrange(len(out.terms))].name
        rules.append(m.Rule(str(r + 1), cond, (m.Conclusion("y", concl),)))
    variables = (
        *tuple(m.Variable(n, m.VarKind.INPUT, range=m.Range(LO, HI)) for n in names),
        m.Variable("y", m.VarKind.OUTPUT, range=out.range),
    )
    block = m.RuleBlock("rules", tuple(rules), "MIN", "MAX", "MIN", None if sugeno else "MAX")
    return m.FunctionBlock(f"it2_{seed}", variables, fuzzify, (out,), (block,))


def with_lower_equal_upper(fb: m.FunctionBlock) -> m.FunctionBlock:
    """Every term's lower function made equal to its upper one (a degenerate type-2 system)."""

    def same(t: m.Term) -> m.Term:
        return t if t.lower is None else dataclasses.replace(t, lower=m.LowerMF(mf=t.mf))

    return dataclasses.replace(
        fb,
        fuzzify=tuple(dataclasses.replace(f, terms=tuple(same(t) for t in f.terms)) for f in fb.fuzzify),
        defuzzify=tuple(dataclasses.replace(d, terms=tuple(same(t) for t in d.terms)) for d in fb.defuzzify),
    )
