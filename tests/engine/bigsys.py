"""Random rule bases large enough for the table-driven rule section (above
``fastprog.TABLE_THRESHOLD`` rules), built from a seed: inputs with triangular partitions
(sparse evaluation applies) or Gaussian terms (it does not), random distinct rules with WITH
weights, and an output of a chosen kind."""

from __future__ import annotations

import random

from fuzzyctl import model as m

LO, HI = -1.0, 1.0
KINDS = ("mamdani", "mamdani_sum", "singleton", "ts", "smooth")


def _tri(c: float, d: float) -> m.MembershipFunction:
    return m.ShapeMF("triangle", (round(c - d, 6), round(c, 6), round(c + d, 6)))


def system(
    seed: int, output: str = "mamdani", gaussian_inputs: bool = False, n_rules: int = 210
) -> m.FunctionBlock:
    rng = random.Random(seed)
    n_in = 3
    n_terms = [rng.choice((6, 7)) for _ in range(n_in)]
    fuzz = []
    for i, k in enumerate(n_terms):
        d = (HI - LO) / (k - 1)
        terms = []
        for j in range(k):
            c = LO + j * d
            mf = m.ShapeMF("gaussian", (round(c, 6), round(d / 2, 6))) if gaussian_inputs else _tri(c, d)
            terms.append(m.Term(f"t{j}", mf))
        fuzz.append(m.FuzzifyBlock(f"x{i}", tuple(terms), m.Range(LO, HI)))
    k_out = 5
    d = (HI - LO) / (k_out - 1)
    if output in ("mamdani", "mamdani_sum"):
        out_terms = tuple(m.Term(f"o{j}", _tri(LO + j * d, d)) for j in range(k_out))
    elif output == "smooth":
        out_terms = tuple(
            m.Term(f"o{j}", m.ShapeMF("gaussian", (round(LO + j * d, 6), round(d / 2, 6))))
            for j in range(k_out)
        )
    elif output == "singleton":
        out_terms = tuple(m.Term(f"o{j}", m.SingletonMF(round(LO + j * d, 6))) for j in range(k_out))
    else:
        out_terms = tuple(
            m.Term(f"o{j}", m.ShapeMF("constant", (round(LO + j * d, 6),))) for j in range(k_out)
        )
    combos: set[tuple[int, ...]] = set()
    total = 1
    for k in n_terms:
        total *= k
    while len(combos) < min(n_rules, total):
        combos.add(tuple(rng.randrange(k) for k in n_terms))
    rules = []
    for r, combo in enumerate(sorted(combos)):
        cond = m.And(tuple(m.Is(f"x{i}", f"t{t}") for i, t in enumerate(combo)))
        w = round(rng.uniform(0.3, 1.0), 2) if rng.random() < 0.3 else None
        rules.append(m.Rule(str(r + 1), cond, (m.Conclusion("y", f"o{rng.randrange(k_out)}", w),)))
    method = {"singleton": "COGS", "ts": "WTAVER"}.get(output, "COG")
    act, accu = ("PROD", "SUM") if output == "mamdani_sum" else ("MIN", "MAX")
    return m.FunctionBlock(
        f"big{seed}",
        variables=(
            *(m.Variable(f"x{i}", m.VarKind.INPUT) for i in range(n_in)),
            m.Variable("y", m.VarKind.OUTPUT),
        ),
        fuzzify=tuple(fuzz),
        defuzzify=(m.DefuzzifyBlock("y", out_terms, m.Range(LO, HI), method, m.Default(-7.0)),),
        rule_blocks=(m.RuleBlock("rb", tuple(rules), rng.choice(("MIN", "PROD")), None, act, accu),),
    )
