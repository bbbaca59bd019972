"""Random small systems that sweep every activation x accumulation pair (one output per pair),
every AND/OR norm (rotated over the rule blocks) and a defuzzification method, for the
operator sweep tests (tests/codegen/test_native_operators.py)."""

from __future__ import annotations

import numpy as np

from fuzzyctl import model as m
from fuzzyctl.engine.semantics.operators import ACCU_NAMES, SNORMS, TNORMS

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


def all_pairs() -> list[tuple[str, str]]:
    return [(act, accu) for act in ACTS for accu in ACCUS]


def some_pairs(seed: int) -> list[tuple[str, str]]:
    """Nine pairs in which every activation and every accumulation appears."""
    return [(ACTS[(i + seed) % len(ACTS)], ACCUS[i]) for i in range(len(ACCUS))]


def system(
    seed: int, smooth: bool, pairs: list[tuple[str, str]], methods: tuple[str, ...] = ("COG",)
) -> m.FunctionBlock:
    """Two inputs (three PWL terms each) and one output ``y_<act>_<accu>`` per pair, each with
    three terms (PWL, or with ``smooth`` Gaussian/bell ones too), four random rules in a block
    of its own with that activation and AND/OR norms rotated by ``seed``, and a method from
    ``methods`` in turn."""
    rng = np.random.default_rng(seed)
    ins = ("x1", "x2")
    variables = [m.Variable(n, m.VarKind.INPUT) for n in ins]
    fuzzify = tuple(
        m.FuzzifyBlock(n, tuple(m.Term(f"t{j}", _pwl(rng)) for j in range(3)), m.Range(LO, HI)) for n in ins
    )
    defuzz, blocks = [], []
    ands, ors = sorted(TNORMS), sorted(SNORMS)
    for k, (act, accu) in enumerate(pairs):
        out = f"y_{act}_{accu}".lower()
        variables.append(m.Variable(out, m.VarKind.OUTPUT))
        # DMIN keeps a set only where the term is exactly 1: for a smooth peak that is the
        # stretch where it rounds to 1.0 (ill-posed), so DMIN sweeps PWL terms only
        smooth_here = smooth and act != "DMIN"
        terms = tuple(
            m.Term(f"o{j}", _smooth(rng) if smooth_here and j != 1 else _pwl(rng)) for j in range(3)
        )
        method = methods[k % len(methods)]
        defuzz.append(m.DefuzzifyBlock(out, terms, m.Range(LO, HI), method, m.Default(-1.0), accu=accu))
        rules = []
        for r in range(4):
            parts: list[m.Condition] = [
                m.Is(ins[i], f"t{int(rng.integers(3))}") for i in range(int(rng.integers(1, 3)))
            ]
            cond: m.Condition = parts[0] if len(parts) == 1 else (m.And if r % 2 else m.Or)(tuple(parts))
            w = None if r else float(np.round(rng.uniform(0.3, 1.0), 2))
            rules.append(m.Rule(f"{r + 1}", cond, (m.Conclusion(out, f"o{r % 3}", w),)))
        # DMIN jumps where the rule degree is exactly 1: its block keeps MIN/MAX, whose degrees
        # are the terms' own (1 + b - b may round to either side of 1 under ASUM)
        if act == "DMIN":
            and_op, or_op = "MIN", "MAX"
        else:
            and_op, or_op = ands[(k + seed) % len(ands)], ors[(k + 2 * seed) % len(ors)]
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
