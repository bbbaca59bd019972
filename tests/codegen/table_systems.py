"""Seeded random systems for the lookup-table tests: 1 or 2 inputs whose triangle and
shoulder terms cover their RANGE (no vertical edge: the table bound needs a slope), a full
grid of rules, and a Takagi-Sugeno output (constant or linear terms, WTAVER or WTSUM, with or
without accumulation) or a Mamdani output under CoA, LM, RM or MoM whose surface has no jump
(terms positive across the whole range for CoA; one rising term for the maxima).  Written as
FCL text, so the engine reads them as any user's file."""

from __future__ import annotations

import numpy as np


def _terms(rng: np.random.Generator, lo: float, hi: float) -> list[str]:
    n = int(rng.integers(2, 5))
    peaks = [lo, *np.sort(rng.uniform(lo, hi, n - 2)).round(3).tolist(), hi]
    out = []
    for k, c in enumerate(peaks):
        pts = []
        if k:
            pts.append((peaks[k - 1], 0.0))
        pts.append((c, 1.0))
        if k + 1 < len(peaks):
            pts.append((peaks[k + 1], 0.0))
        out.append(" ".join(f"({x!r}, {y!r})" for x, y in pts))
    return out


def _head(
    rng: np.random.Generator, n_in: int
) -> tuple[list[str], list[str], list[list[str]], list[tuple[float, float]]]:
    names = [f"in{k}" for k in range(n_in)]
    lines = ["FUNCTION_BLOCK rnd", "VAR_INPUT"] + [f"    {n} : REAL;" for n in names]
    lines += ["END_VAR", "VAR_OUTPUT", "    out : REAL;", "END_VAR"]
    terms, ranges = [], []
    for n in names:
        lo = float(rng.choice([0.0, -1.0, -50.0, 3.7]))
        hi = lo + float(rng.choice([1.0, 10.0, 100.0, 2.5]))
        ranges.append((lo, hi))
        ts = _terms(rng, lo, hi)
        terms.append([f"t{k}" for k in range(len(ts))])
        lines += [f"FUZZIFY {n}", f"    RANGE := ({lo!r} .. {hi!r});"]
        lines += [f"    TERM t{k} := {t};" for k, t in enumerate(ts)]
        lines.append("END_FUZZIFY")
    return names, lines, terms, ranges


def _rules(rng: np.random.Generator, names: list[str], terms: list[list[str]], concl: list[str]) -> list[str]:
    and_op = str(rng.choice(["MIN", "PROD"]))
    lines = ["RULEBLOCK rb", f"    AND : {and_op};", f"    ACT : {rng.choice(['MIN', 'PROD'])};"]
    grid = np.array(np.meshgrid(*[range(len(t)) for t in terms])).reshape(len(names), -1).T
    for k, cell in enumerate(grid, 1):
        cond = " AND ".join(f"{names[i]} IS {terms[i][j]}" for i, j in enumerate(cell))
        weight = f" WITH {round(float(rng.uniform(0.2, 1.0)), 3)!r}" if rng.random() < 0.2 else ""
        lines.append(
            f"    RULE {k} : IF {cond} THEN out IS {concl[int(rng.integers(0, len(concl)))]}{weight};"
        )
    return [*lines, "END_RULEBLOCK", "END_FUNCTION_BLOCK"]


def ts_fcl(seed: int) -> str:
    """A Takagi-Sugeno system."""
    rng = np.random.default_rng(seed)
    names, lines, terms, ranges = _head(rng, int(rng.integers(1, 3)))
    linear = rng.random() < 0.6
    lines += ["DEFUZZIFY out", "    RANGE := (-100.0 .. 100.0);"]
    concl = []
    for k in range(int(rng.integers(2, 5))):
        v = round(float(rng.uniform(-60, 60)), 3)
        if linear:
            cs = [round(float(rng.normal(0, 20 / (hi - lo))), 4) for lo, hi in ranges]
            lines.append(f"    TERM o{k} := Linear {' '.join(repr(c) for c in cs)} {v!r};")
        else:
            lines.append(f"    TERM o{k} := Constant {v!r};")
        concl.append(f"o{k}")
    lines += [f"    METHOD : {rng.choice(['WTAVER', 'WTSUM'])};", "    DEFAULT := 0;"]
    if rng.random() < 0.5:
        lines.append(f"    ACCU : {rng.choice(['MAX', 'SUM'])};")
    lines.append("END_DEFUZZIFY")
    return "\n".join(lines + _rules(rng, names, terms, concl)) + "\n"


def mamdani_fcl(seed: int, method: str) -> str:
    """A Mamdani system under ``method`` (CoA, LM, RM or MoM) whose output has no jump."""
    rng = np.random.default_rng(seed)
    names, lines, terms, _ranges = _head(rng, int(rng.integers(1, 3)))
    lines += ["DEFUZZIFY out", "    RANGE := (-50.0 .. 90.0);"]
    if method.upper() == "COA":  # every term above 0 on the whole range: no gap to jump across
        lines += [
            "    TERM s0 := (-50.0, 1.0) (90.0, 0.1);",
            f"    TERM s1 := (-50.0, 0.1) ({round(float(rng.uniform(-30, 70)), 2)!r}, 1.0) (90.0, 0.1);",
            "    TERM s2 := (-50.0, 0.1) (90.0, 1.0);",
        ]
        concl = ["s0", "s1", "s2"]
    else:  # one rising term: the maximum's plateau moves with the highest degree
        lines.append(f"    TERM up := (-50.0, 0.0) ({round(float(rng.uniform(0, 90)), 2)!r}, 1.0);")
        concl = ["up"]
    lines += [f"    METHOD : {method};", "    DEFAULT := 0;", "END_DEFUZZIFY"]
    return "\n".join(lines + _rules(rng, names, terms, concl)) + "\n"
