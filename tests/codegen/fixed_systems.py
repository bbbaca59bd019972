"""Seeded random systems for the integer code generators: 1-3 inputs whose piecewise-linear
terms cover their RANGE (shoulders, triangles, trapezoids, vertical edges, odd breakpoints),
a full or partial grid of rules with AND/OR/NOT and weights, and a singleton (COGS) or
Takagi-Sugeno (constant or linear, WTAVER or WTSUM) output.  Written as FCL text, so the
engine reads them as any user's file."""

from __future__ import annotations

import re

import numpy as np

AND_OR = [("MIN", "MAX"), ("PROD", "ASUM"), ("BDIF", "BSUM")]


def _terms(rng: np.random.Generator, lo: float, hi: float) -> list[str]:
    """2-5 terms whose supports overlap and cover [lo, hi] (every input fires a term)."""
    n = int(rng.integers(2, 6))
    cuts = np.sort(rng.uniform(lo, hi, n - 2)) if n > 2 else np.array([])
    peaks = [lo, *cuts.round(3).tolist(), hi]
    out = []
    for k, c in enumerate(peaks):
        left = peaks[k - 1] if k > 0 else None
        right = peaks[k + 1] if k + 1 < len(peaks) else None
        pts = []
        if left is None:
            pts.append((c, 1.0))
        else:
            pts += [(left, 0.0)]
            if rng.random() < 0.3:  # a plateau: trapezoid
                pts.append((round((left + c) / 2, 4), 1.0))
            pts.append((c, 1.0))
        if right is not None:
            if rng.random() < 0.15:  # a vertical edge at the right end of the plateau
                mid = round((c + right) / 2, 4)
                pts += [(mid, 1.0), (mid, 0.5)]
            pts.append((right, 0.0))
        out.append(" ".join(f"({x!r}, {y!r})" for x, y in pts))
    return out


def random_fcl(seed: int) -> str:
    rng = np.random.default_rng(seed)
    n_in = int(rng.integers(1, 4))
    names = [f"in{k}" for k in range(n_in)]
    ranges = []
    lines = ["FUNCTION_BLOCK rnd", "VAR_INPUT"] + [f"    {n} : REAL;" for n in names]
    lines += ["END_VAR", "VAR_OUTPUT", "    out : REAL;", "END_VAR"]
    terms: list[list[str]] = []
    for n in names:
        lo = float(rng.choice([0.0, -1.0, -50.0, 3.7, -0.25]))
        hi = lo + float(rng.choice([1.0, 10.0, 100.0, 2.5, 1000.0]))
        ranges.append((lo, hi))
        ts = _terms(rng, lo, hi)
        terms.append([f"t{k}" for k in range(len(ts))])
        lines += [f"FUZZIFY {n}", f"    RANGE := ({lo!r} .. {hi!r});"]
        lines += [f"    TERM t{k} := {t};" for k, t in enumerate(ts)]
        lines.append("END_FUZZIFY")
    kind = rng.choice(["singleton", "constant", "linear"])
    n_out = int(rng.integers(2, 6))
    lines += ["DEFUZZIFY out"]
    out_lo, out_hi = float(rng.choice([-100.0, 0.0, 20.0])), 0.0
    out_hi = out_lo + float(rng.choice([1.0, 200.0, 5000.0]))
    for k in range(n_out):
        v = round(float(rng.uniform(out_lo, out_hi)), 3)
        if kind == "singleton":
            lines.append(f"    TERM o{k} := {v!r};")
        elif kind == "constant":
            lines.append(f"    TERM o{k} := Constant {v!r};")
        else:
            cs = [round(float(rng.normal(0, (out_hi - out_lo) / (hi - lo) / 4)), 4) for lo, hi in ranges]
            lines.append(f"    TERM o{k} := Linear {' '.join(repr(c) for c in cs)} {v!r};")
    method = "COGS" if kind == "singleton" else str(rng.choice(["WTAVER", "WTSUM"]))
    lines += [f"    METHOD : {method};", "    DEFAULT := 0;"]
    if kind == "singleton" or rng.random() < 0.5:
        lines.append(f"    ACCU : {rng.choice(['MAX', 'SUM'])};")
    lines += ["END_DEFUZZIFY", "RULEBLOCK rb"]
    and_op, or_op = AND_OR[int(rng.integers(0, 3))]
    lines += [f"    AND : {and_op};", f"    OR : {or_op};"]
    grid = np.array(np.meshgrid(*[range(len(t)) for t in terms])).reshape(n_in, -1).T
    k = 0
    for cell in grid:
        k += 1
        parts = [f"{names[i]} IS {terms[i][j]}" for i, j in enumerate(cell)]
        if n_in > 1 and rng.random() < 0.1:
            cond = f"{parts[0]} OR {' AND '.join(parts[1:])}"
        else:
            cond = " AND ".join(parts)
        weight = f" WITH {round(float(rng.uniform(0.2, 1.0)), 3)!r}" if rng.random() < 0.2 else ""
        concl = f"o{int(rng.integers(0, n_out))}"
        lines.append(f"    RULE {k} : IF {cond} THEN out IS {concl}{weight};")
    if rng.random() < 0.3:  # a negated extra rule
        k += 1
        lines.append(f"    RULE {k} : IF {names[0]} IS NOT {terms[0][0]} THEN out IS o0;")
    lines += ["END_RULEBLOCK", "END_FUNCTION_BLOCK"]
    return "\n".join(lines) + "\n"


def random_mamdani_fcl(seed: int, method: str = "COG") -> str:
    """A random system as :func:`random_fcl` draws its inputs and rules, with a Mamdani
    output: 2-5 piecewise-linear terms covering its RANGE, ACCU MAX or SUM, ACT MIN or PROD."""
    rng = np.random.default_rng(10_000 + seed)
    text = random_fcl(seed)
    head, _sep, tail = text.partition("DEFUZZIFY out")
    _old, _sep, rest = tail.partition("END_DEFUZZIFY")
    out_lo = float(rng.choice([-100.0, 0.0, 20.0, -0.5]))
    out_hi = out_lo + float(rng.choice([1.0, 200.0, 5000.0, 7.5]))
    terms = _terms(rng, out_lo, out_hi)
    used = sorted({int(t) for t in re.findall(r"THEN out IS o(\d+)", rest)})
    lines = ["DEFUZZIFY out", f"    RANGE := ({out_lo!r} .. {out_hi!r});"]
    for k in range(max(used) + 1):
        lines.append(f"    TERM o{k} := {terms[k % len(terms)]};")
    lines += [f"    METHOD : {method};", "    DEFAULT := 0;", f"    ACCU : {rng.choice(['MAX', 'SUM'])};", ""]
    act = "PROD" if rng.random() < 0.25 else "MIN"
    rest = rest.replace("RULEBLOCK rb\n", f"RULEBLOCK rb\n    ACT : {act};\n")
    return head + "\n".join(lines) + "END_DEFUZZIFY" + rest


def mamdani_variant(text: str, half_width: float = 50.0, low: float = -150.0, high: float = 150.0) -> str:
    """A singleton (COGS) system turned Mamdani: each singleton ``v`` becomes the triangle
    ``(v - half_width, 0) (v, 1) (v + half_width, 0)``, CoG over ``RANGE (low .. high)``; the
    block is renamed ``<name>_m``."""

    def triangle(m: re.Match[str]) -> str:
        v = float(m.group(2))
        return f"TERM {m.group(1)} := ({v - half_width!r}, 0) ({v!r}, 1) ({v + half_width!r}, 0);"

    text = re.sub(r"TERM (\w+) := (-?[\d.]+);", triangle, text)
    text = re.sub(r"METHOD\s*:\s*CoGS;", f"METHOD : CoG; RANGE := ({low!r} .. {high!r});", text, flags=re.I)
    return re.sub(r"FUNCTION_BLOCK (\w+)", r"FUNCTION_BLOCK \1_m", text, count=1)


def smooth_fcl(seed: int) -> str:
    """A random system as :func:`random_fcl` draws it, each input term replaced by a smooth
    one at the same peak: a sigmoid at the range's ends, a Gaussian or a generalised bell
    (drawn) between, each as wide as the gap to its neighbours."""
    rng = np.random.default_rng(20_000 + seed)
    text = random_fcl(seed).replace("FUNCTION_BLOCK rnd", f"FUNCTION_BLOCK rnds{seed}")
    out: list[str] = []
    peaks: list[float] = []
    for line in text.splitlines():
        m = re.match(r"\s*TERM (t\d+) := (\(.*\));", line)
        if m:
            pts = [tuple(float(v) for v in p.split(",")) for p in re.findall(r"\(([^)]*)\)", m.group(2))]
            peaks.append(next(x for x, y in pts if y == 1.0))
            out.append(f"@{m.group(1)}")
            continue
        if line.startswith("END_FUZZIFY"):
            out = _smooth_terms(out, peaks, rng)
            peaks = []
        out.append(line)
    return "\n".join(out) + "\n"


def _smooth_terms(lines: list[str], peaks: list[float], rng: np.random.Generator) -> list[str]:
    n = len(peaks)
    res = []
    for line in lines:
        if not line.startswith("@"):
            res.append(line)
            continue
        k = int(line[2:])
        c = peaks[k]
        gap = max(peaks[k + 1] - c if k + 1 < n else 0.0, c - peaks[k - 1] if k > 0 else 0.0)
        if k == 0 or k == n - 1:  # a shoulder: a sigmoid half way to the neighbour
            other = peaks[1] if k == 0 else peaks[-2]
            slope = (8.0 if k == n - 1 else -8.0) / abs(other - c)
            shape = f"SIGM {round(slope, 6)!r} {round((c + other) / 2, 6)!r}"
        elif rng.random() < 0.5:
            shape = f"GAUSS {c!r} {round(gap * float(rng.uniform(0.4, 0.7)), 6)!r}"
        else:
            shape = f"GBELL {round(gap * 0.6, 6)!r} {round(float(rng.uniform(1.0, 3.0)), 3)!r} {c!r}"
        res.append(f"    TERM t{k} := {shape};")
    return res
