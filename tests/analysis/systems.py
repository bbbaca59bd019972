"""Random small rule bases written as FCL text, for the analysis tests: a well-formed grid
(Ruspini triangle partitions, a "sum" rule table) with defects planted at known places."""

from __future__ import annotations

import random
from dataclasses import dataclass, field


@dataclass
class Planted:
    """What was planted, by rule label."""

    gaps: list[dict[str, float]] = field(default_factory=list)  # the point only the removed rule covered
    duplicates: list[tuple[str, str]] = field(default_factory=list)  # (copy, original)
    subsumed: list[tuple[str, str]] = field(default_factory=list)  # (narrow rule, general rule)
    dead: list[str] = field(default_factory=list)
    conflicts: list[tuple[str, str]] = field(default_factory=list)


def peaks(rng: random.Random, k: int, lo: float, hi: float) -> list[float]:
    inner = sorted(round(rng.uniform(lo, hi), 3) for _ in range(k - 2))
    xs = [lo, *inner, hi]
    for i in range(1, len(xs)):  # distinct, increasing
        xs[i] = max(xs[i], xs[i - 1] + 0.25)
    return xs


def partition(ps: list[float]) -> list[str]:
    """Ruspini triangles (shoulders at the ends) peaking at ``ps``, as FCL point lists."""
    out = []
    for m, p in enumerate(ps):
        if m == 0:
            out.append(f"({p}, 1) ({ps[1]}, 0)")
        elif m == len(ps) - 1:
            out.append(f"({ps[m - 1]}, 0) ({p}, 1)")
        else:
            out.append(f"({ps[m - 1]}, 0) ({p}, 1) ({ps[m + 1]}, 0)")
    return out


def grid_system(seed: int, plant: bool = True, and_op: str | None = None) -> tuple[str, Planted]:
    rng = random.Random(seed)
    k1, k2 = rng.randint(3, 5), rng.randint(3, 5)
    p1, p2 = peaks(rng, k1, 0.0, 10.0), peaks(rng, k2, -5.0, 5.0)
    n_out = k1 + k2 - 1
    singleton = rng.random() < 0.5
    and_op = and_op or rng.choice(["MIN", "PROD"])
    planted = Planted()
    rules: list[tuple[str, str]] = []  # (label, text)
    removed = None
    if plant:
        removed = (rng.randint(1, k1 - 2), rng.randint(0, k2 - 1))
        planted.gaps.append({"x": p1[removed[0]], "y": p2[removed[1]], "z": 0.5})
    for i in range(k1):
        for j in range(k2):
            if (i, j) != removed:
                rules.append((f"{len(rules) + 1}", f"IF x IS a{i} AND y IS b{j} THEN out IS o{i + j}"))
    if plant:
        by_text = {t: lab for lab, t in rules}
        # a duplicate of one rule, a narrower copy of another (an extra leaf on z), a conflict
        # (the premise of a third concluding a term two steps away), two dead rules
        picks = rng.sample([lab for lab, _t in rules], 3)
        texts = dict(rules)
        n = len(rules)
        rules.append((f"{n + 1}", texts[picks[0]]))
        planted.duplicates.append((f"{n + 1}", by_text[texts[picks[0]]]))
        narrow = texts[picks[1]].replace(" THEN", " AND z IS zall THEN")
        rules.append((f"{n + 2}", narrow))
        planted.subsumed.append((f"{n + 2}", picks[1]))
        cond, concl = texts[picks[2]].split(" THEN out IS o")
        far = int(concl) + 2 if int(concl) + 2 < n_out else int(concl) - 2
        rules.append((f"{n + 3}", f"{cond} THEN out IS o{far}"))
        planted.conflicts.append((picks[2], f"{n + 3}"))
        rules.append((f"{n + 4}", "IF x IS a0 AND x IS a2 THEN out IS o0"))
        rules.append((f"{n + 5}", "IF y IS b0 AND x IS outside THEN out IS o1"))
        planted.dead += [f"{n + 4}", f"{n + 5}"]
    if singleton:
        outs = [f"TERM o{m} := {m * 10.0 / (n_out - 1)};" for m in range(n_out)]
        defuzz = "METHOD : CoGS;"
    else:
        po = [m * 10.0 / (n_out - 1) for m in range(n_out)]
        outs = [f"TERM o{m} := {pts};" for m, pts in enumerate(partition(po))]
        defuzz = "METHOD : CoG;\n        RANGE := (0.0 .. 10.0);"
    xs = "\n        ".join(f"TERM a{m} := {pts};" for m, pts in enumerate(partition(p1)))
    ys = "\n        ".join(f"TERM b{m} := {pts};" for m, pts in enumerate(partition(p2)))
    extra_x = "\n        TERM outside := (20, 0) (21, 1) (22, 0);" if plant else ""
    z = (
        "\n    FUZZIFY z\n        TERM zall := (0, 1) (1, 1);\n        RANGE := (0.0 .. 1.0);"
        "\n    END_FUZZIFY"
        if plant
        else ""
    )
    zvar = "\n        z : REAL;" if plant else ""
    body = "\n        ".join(f"RULE {lab} : {t};" for lab, t in rules)
    text = f"""FUNCTION_BLOCK planted
    VAR_INPUT
        x : REAL;
        y : REAL;{zvar}
    END_VAR
    VAR_OUTPUT
        out : REAL;
    END_VAR
    FUZZIFY x
        {xs}{extra_x}
        RANGE := (0.0 .. 10.0);
    END_FUZZIFY
    FUZZIFY y
        {ys}
        RANGE := (-5.0 .. 5.0);
    END_FUZZIFY{z}
    DEFUZZIFY out
        {chr(10).join(outs)}
        {defuzz}
        DEFAULT := -1;
    END_DEFUZZIFY
    RULEBLOCK rules
        AND : {and_op};
        ACCU : MAX;
        {body}
    END_RULEBLOCK
END_FUNCTION_BLOCK
"""
    return text, planted


SMOOTH = ["GAUSS {m} {s}", "GBELL {s} 2 {m}", "SIGM 2 {m}"]


def random_system(seed: int) -> str:
    """Random terms (triangles, trapezoids, Gaussians, bells, sigmoids), random rules with
    AND, OR, NOT and weights: for the brute-force comparison of gaps."""
    rng = random.Random(seed)
    ops = rng.choice([("MIN", "MAX"), ("PROD", "ASUM"), ("MIN", "MAX")])
    blocks = []
    terms: dict[str, list[str]] = {}
    for v in ("x", "y"):
        ts = []
        for m in range(rng.randint(2, 4)):
            c = round(rng.uniform(0, 10), 2)
            w = round(rng.uniform(0.5, 3), 2)
            kind = rng.random()
            if kind < 0.4:
                spec = f"TRIAN {c - w} {c} {c + w}"
            elif kind < 0.6:
                spec = f"TRAPE {c - w} {c - w / 3} {c + w / 3} {c + w}"
            else:
                spec = rng.choice(SMOOTH).format(m=c, s=round(w / 2, 2))
            ts.append(f"TERM {v}{m} := {spec};")
        terms[v] = [t.split()[1] for t in ts]
        blocks.append(
            f"    FUZZIFY {v}\n        "
            + "\n        ".join(ts)
            + "\n        RANGE := (0.0 .. 10.0);\n    END_FUZZIFY"
        )
    rules = []
    for r in range(rng.randint(2, 6)):
        a = f"x IS {'NOT ' if rng.random() < 0.15 else ''}{rng.choice(terms['x'])}"
        b = f"y IS {rng.choice(terms['y'])}"
        cond = rng.choice([a, b, f"{a} AND {b}", f"{a} AND {b}", f"({a}) OR {b}"])
        weight = f" WITH {rng.choice([0.5, 1.0])}" if rng.random() < 0.3 else ""
        rules.append(f"RULE {r + 1} : IF {cond} THEN out IS {rng.choice(['lo', 'hi'])}{weight};")
    return f"""FUNCTION_BLOCK rnd
    VAR_INPUT
        x : REAL;
        y : REAL;
    END_VAR
    VAR_OUTPUT
        out : REAL;
    END_VAR
{chr(10).join(blocks)}
    DEFUZZIFY out
        TERM lo := 0;
        TERM hi := 10;
        METHOD : CoGS;
        DEFAULT := -1;
    END_DEFUZZIFY
    RULEBLOCK rules
        AND : {ops[0]};
        OR : {ops[1]};
        ACCU : MAX;
        {chr(10).join("        " + r for r in rules).strip()}
    END_RULEBLOCK
END_FUNCTION_BLOCK
"""
