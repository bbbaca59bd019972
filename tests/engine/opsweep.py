"""Random small systems that sweep every activation x accumulation pair (one output per pair),
every AND/OR norm (rotated over the rule blocks) and a defuzzification method, for the
operator sweep tests (tests/codegen/test_native_operators.py)."""

from __future__ import annotations

import numpy as np

from fuzzyctl import model as m
from fuzzyctl.engine.operators import ACCU_NAMES, SNORMS, TNORMS

ACTS = sorted(TNORMS)
ACCUS = sorted(ACCU_NAMES)
LO, HI = 0.0, 10.0


def _pwl(rng: np.random.Generator) -> m.MembershipFunction:
    kind = rng.choice(["triangle", "trapezoid", "points"])
    if kind == "triangle":
        a, b, c = np.sort(np.round(rng.uniform(LO, HI, 3), 3))
        return m.ShapeMF("triangle", (float(a), float(b), float(max(c, a + 0.5))))
    if kind == "trapezoid":
        a, b, c, d = np.sort(np.round(rng.uniform(LO, HI, 4), 3))
        return m.ShapeMF("trapezoid", (float(a), float(b), float(c), float(max(d, a + 0.5))))
    xs = np.unique(np.round(rng.uniform(LO, HI, 4), 3))
    ys = [0.0, *(float(v) for v in rng.choice([0.3, 0.7, 1.0], len(xs) - 2)), 0.0]
    return m.PointsMF(tuple(m.Point(float(x), y) for x, y in zip(xs, ys, strict=True)))


def _smooth(rng: np.random.Generator) -> m.MembershipFunction:
    c = float(np.round(rng.uniform(LO + 1, HI - 1), 3))
    if rng.uniform() < 0.5:
        return m.ShapeMF("gaussian", (c, float(np.round(rng.uniform(0.4, 2.0), 3))))
    return m.ShapeMF(
        "bell", (c, float(np.round(rng.uniform(0.5, 2.0), 3)), float(rng.choice([1.0, 2.0, 4.0])))
    )


def system(seed: int, smooth: bool, method: str = "COG") -> m.FunctionBlock:
    """Two inputs (three PWL terms each), one output ``y_<act>_<accu>`` per pair, each with
    three terms (PWL, or with ``smooth`` Gaussian/bell ones too) and four random rules; rule
    block k uses activation k and the AND/OR norms rotated by ``seed``."""
    rng = np.random.default_rng(seed)
    ins = ("x1", "x2")
    variables = [m.Variable(n, m.VarKind.INPUT) for n in ins]
    fuzzify = tuple(
        m.FuzzifyBlock(n, tuple(m.Term(f"t{j}", _pwl(rng)) for j in range(3)), m.Range(LO, HI)) for n in ins
    )
    defuzz, blocks = [], []
    ands, ors = sorted(TNORMS), sorted(SNORMS)
    for k, act in enumerate(ACTS):
        rules = []
        for accu in ACCUS:
            out = f"y_{act}_{accu}".lower()
            variables.append(m.Variable(out, m.VarKind.OUTPUT))
            # DMIN keeps a set only where the term is exactly 1: for a smooth peak that is the
            # stretch where it rounds to 1.0 (ill-posed), so DMIN sweeps PWL terms only
            smooth_here = smooth and act != "DMIN"
            terms = tuple(
                m.Term(f"o{j}", _smooth(rng) if smooth_here and j != 1 else _pwl(rng)) for j in range(3)
            )
            defuzz.append(m.DefuzzifyBlock(out, terms, m.Range(LO, HI), method, m.Default(-1.0), accu=accu))
            for r in range(4):
                parts: list[m.Condition] = [
                    m.Is(ins[i], f"t{int(rng.integers(3))}") for i in range(int(rng.integers(1, 3)))
                ]
                cond: m.Condition = parts[0] if len(parts) == 1 else (m.And if r % 2 else m.Or)(tuple(parts))
                w = None if r else float(np.round(rng.uniform(0.3, 1.0), 2))
                rules.append(m.Rule(f"{len(rules) + 1}", cond, (m.Conclusion(out, f"o{r % 3}", w),)))
        # DMIN jumps where the rule degree is exactly 1: its block keeps MIN/MAX, whose degrees
        # are the terms' own (1 + b - b may round to either side of 1 under ASUM)
        and_op, or_op = (
            ("MIN", "MAX")
            if act == "DMIN"
            else (ands[(k + seed) % len(ands)], ors[(k + 2 * seed) % len(ors)])
        )
        blocks.append(m.RuleBlock(f"b{k}", tuple(rules), and_op, or_op, act))
    return m.FunctionBlock(
        "sweep",
        variables=tuple(variables),
        fuzzify=fuzzify,
        defuzzify=tuple(defuzz),
        rule_blocks=tuple(blocks),
    )


def inputs(seed: int, n: int) -> list[dict[str, float]]:
    rng = np.random.default_rng(seed + 1000)
    return [{"x1": float(a), "x2": float(b)} for a, b in rng.uniform(LO, HI, (n, 2))]
