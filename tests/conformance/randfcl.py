"""Random FCL systems in the dialect jFuzzyLogic 3.3 and fuzzyctl both read, for the live
oracle (tests/conformance/test_jfl_oracle.py).

Every feature the two share appears: POINT lists (with vertical edges), TRIAN, TRAPE, GAUSS,
GAUSS2, GBELL, SIGM, DSIGM, COSINE, singleton and FUNCTION terms (not SINGLETONS, which
jFuzzyLogic 3.3 fails to parse), term
parameters given by variables, METHOD COG/COA/LM/RM/MM/COGS/COGF, DEFAULT values and NC,
RANGE in DEFUZZIFY and on the declaration line, AND/OR of every jFuzzyLogic pair declared in
either order, ACT MIN/PROD, ACCU MAX/BSUM/NSUM/PROBOR/SUM or none, NOT, IS NOT, parentheses,
AND and OR mixed without them, several conclusions, WITH, several rule blocks, outputs read
in conditions.  A *family* leans on one of jFuzzyLogic's behaviours (``FAMILIES``) so that the
agreement table can be given per behaviour; ``mixed`` draws everything.

Only what jFuzzyLogic would load is produced (identifiers that are not its keywords, numbers
with digits on both sides of the point, binary function operators in parentheses), and
nothing both tools refuse.  Inputs (``System.rows``) are random and on the terms' corners.
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field

#: family -> the jFuzzyLogic behaviour it exercises (docs/engine.md's agreement table)
FAMILIES: dict[str, str] = {
    "mixed": "every shared feature at random",
    "span_universe": "no RANGE: the span of the terms as universe (issue 15.1)",
    "var_range": "a RANGE on the VAR declaration line is ignored",
    "singletons_merged": "singletons (and COGF functions) at one position merged under the ACCU",
    "output_in_condition": "an output in a condition is read by its crisp value",
    "last_and_or": "the last AND/OR declaration sets both operators",
    "per_block_accu": "each rule block applies its own ACCU",
    "nc_nan": "NC starts at NaN",
    "vertical_edges": "at a vertical edge, jFuzzyLogic's side",
    "riemann": "the 1000-point sums of COG, COA, LM, RM, MM",
    "accu_default": "ACCU SUM when absent",
    "nsum": "NSUM as BSUM",
    "precedence": "AND and OR of equal precedence, left to right",
    "with": "WITH scaling every conclusion of its rule",
}

_AND = ["MIN", "PROD", "BDIF", "DMIN", "NIPMIN", "HAMACHER"]
_OR = ["MAX", "ASUM", "BSUM", "DMAX", "NIPMAX", "EINSTEIN"]
_ACCU = ["MAX", "BSUM", "NSUM", "PROBOR", "SUM"]
_CONTINUOUS_METHODS = ["COG", "COA", "LM", "RM", "MM"]
_BLOCK_NAMES = ["No1", "No2", "first", "second", "zeta", "alpha", "rules", "fast", "slow", "B7", "main"]


def num(v: float) -> str:
    """A number as both grammars read it: digits on both sides of '.', no exponent."""
    text = f"{v:.6f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


@dataclass
class Var:
    name: str
    lo: float
    hi: float
    terms: list[str] = field(default_factory=list)
    corners: list[float] = field(default_factory=list)  # term parameters: edge inputs


@dataclass
class System:
    family: str
    seed: int
    text: str
    inputs: list[Var]
    outputs: list[str]
    rows: list[dict[str, float]]


class _Gen:
    def __init__(self, family: str, seed: int) -> None:
        self.family = family
        self.seed = seed
        self.r = random.Random(f"{family}/{seed}")

    def flag(self, p: float) -> bool:
        return self.r.random() < p

    def val(self, lo: float, hi: float, grid: float | None = None) -> float:
        v = self.r.uniform(lo, hi)
        step = grid if grid is not None else self.r.choice([0.5, 0.25, 0.1, 0.001])
        return round(v / step) * step

    # ------------------------------------------------------------------ terms

    def continuous_term(self, lo: float, hi: float, refs: list[str], edges: bool) -> tuple[str, list[float]]:
        """A continuous membership function over about [lo, hi] and its corners."""
        r = self.r
        w = hi - lo
        kinds = ["points", "trian", "trape", "gauss", "gauss2", "gbell", "sigm", "dsigm", "cosine"]
        weights = [6, 3, 3, 2, 1, 1, 1, 1, 1] if not edges else [8, 3, 3, 0, 0, 0, 0, 0, 0]
        if self.family == "nc_nan" and not edges:
            weights = [0, 3, 3, 0, 0, 0, 0, 0, 1]  # 0 outside a finite interval: rows can fire nothing
        kind = r.choices(kinds, weights)[0]
        xs = sorted(self.val(lo, hi, 0.5 if edges else None) for _ in range(4))
        if kind == "points":
            k = r.randint(1, 5)
            pts = sorted(self.val(lo, hi, 0.5 if edges else None) for _ in range(k))
            if edges and k > 1 and self.flag(0.7):  # a vertical edge
                i = r.randrange(1, k)
                pts[i] = pts[i - 1]
            ys = [r.choice([0.0, 1.0, round(r.random(), 3)]) for _ in pts]
            return " ".join(f"({num(x)}, {num(y)})" for x, y in zip(pts, ys, strict=True)), pts
        if kind == "trian":
            a, b, c = sorted(xs[:3])
            if edges and self.flag(0.5):
                b = a if self.flag(0.5) else c
            params = [num(a), num(b), num(c)]
            if refs and self.flag(0.2):
                params[1] = r.choice(refs)  # a corner given by an input
            return "TRIAN " + " ".join(params), [a, b, c]
        if kind == "trape":
            a, b, c, d = xs
            if edges and self.flag(0.5):
                b = a
            if edges and self.flag(0.5):
                d = c
            return f"TRAPE {num(a)} {num(b)} {num(c)} {num(d)}", [a, b, c, d]
        if kind == "gauss":
            m, s = self.val(lo, hi), round(r.uniform(0.05, 0.4) * w, 3) or 0.1
            return f"GAUSS {num(m)} {num(s)}", [m]
        if kind == "gauss2":
            m1, m2 = sorted((self.val(lo, hi), self.val(lo, hi)))
            s1, s2 = (round(r.uniform(0.05, 0.3) * w, 3) or 0.1 for _ in range(2))
            return f"GAUSS2 {num(m1)} {num(s1)} {num(m2)} {num(s2)}", [m1, m2]
        if kind == "gbell":
            a = round(r.uniform(0.05, 0.4) * w, 3) or 0.1
            b = r.choice([1, 2, 3, 0.5])
            m = self.val(lo, hi)
            return f"GBELL {num(a)} {num(b)} {num(m)}", [m]
        if kind == "sigm":
            gain = round(r.choice([-1, 1]) * r.uniform(0.5, 10) / w, 4) or 1.0
            t0 = self.val(lo, hi)
            return f"SIGM {num(gain)} {num(t0)}", [t0]
        if kind == "dsigm":
            a1, a2 = (round(r.uniform(0.5, 10) / w, 4) or 1.0 for _ in range(2))
            c1, c2 = sorted((self.val(lo, hi), self.val(lo, hi)))
            return f"DSIGM {num(a1)} {num(c1)} {num(a2)} {num(c2)}", [c1, c2]
        net = round(r.uniform(0.05, 0.5) * w, 3) or 0.1
        off = self.val(lo, hi)
        return f"COSINE {num(net)} {num(off)}", [off - net, off, off + net]

    def discrete_term(self, lo: float, hi: float, inputs: list[Var], positions: list[float]) -> str:
        """A singleton, SINGLETONS or FUNCTION term; ``positions`` collects the positions used
        (the singletons_merged family reuses them)."""
        r = self.r
        # (no SINGLETONS: jFuzzyLogic 3.3's parser fails on every SINGLETONS term)
        kind = r.choices(["singleton", "function"], [5, 2])[0]
        merge = self.family == "singletons_merged" and positions and self.flag(0.7)

        def pos() -> float:
            x = r.choice(positions) if merge else self.val(lo, hi)
            positions.append(x)
            return x

        if kind == "singleton":
            return num(pos())
        v = r.choice(inputs)
        a = round(r.uniform(-1, 1), 2)
        b = pos()
        expr = r.choice(
            [
                f"{v.name} * {num(a)} + {num(b)}",
                f"({v.name} + {num(b)}) / 2",
                f"abs({v.name} - {num(b)})",
                f"{num(b)} + (({v.name} % 3) * {num(a)})",
                f"{num(b)} + (log(abs({v.name}) + 1) * {num(a)})",
            ]
        )
        if merge and self.flag(0.5):
            expr = num(b)  # a constant FUNCTION at a shared position
        return "FUNCTION " + expr

    # ------------------------------------------------------------------ the system

    def system(self) -> System:
        r, fam = self.r, self.family
        n_in = r.randint(1, 3)
        inputs = []
        for i in range(n_in):
            lo = self.val(-20, 10, 1.0)
            inputs.append(Var(f"in{i + 1}", lo, lo + r.choice([1.0, 5.0, 10.0, 40.0])))
        edges = fam == "vertical_edges" or (fam == "mixed" and self.flag(0.3))
        parts = ["FUNCTION_BLOCK sys", "VAR_INPUT"]
        for v in inputs:
            line = f"    {v.name} : REAL;"
            if fam == "var_range" and self.flag(0.7):
                line += f" RANGE := ({num(v.lo)} .. {num(v.hi)});"
            parts.append(line)
        parts.append("END_VAR")
        n_out = r.randint(1, 2)
        outputs = [f"out{j + 1}" for j in range(n_out)]
        parts.append("VAR_OUTPUT")
        var_ranges = {}
        for o in outputs:
            line = f"    {o} : REAL;"
            if fam == "var_range":
                lo = self.val(-10, 0, 1.0)
                var_ranges[o] = (lo, lo + r.choice([5.0, 20.0, 100.0]))
                line += f" RANGE := ({num(var_ranges[o][0])} .. {num(var_ranges[o][1])});"
            parts.append(line)
        parts.append("END_VAR")
        # ---- inputs
        defined: list[str] = []
        for v in inputs:
            parts.append(f"FUZZIFY {v.name}")
            for k in range(r.randint(1, 4)):
                if self.flag(0.08):
                    text = self.discrete_term(v.lo, v.hi, [x for x in inputs if x.name in defined] or [v], [])
                    if text.startswith("FUNCTION") and not defined:
                        text = num(self.val(v.lo, v.hi))
                    corners: list[float] = []
                else:
                    text, corners = self.continuous_term(v.lo, v.hi, defined, edges)
                name = f"{v.name[:1]}{v.name[-1]}t{k}"
                v.terms.append(name)
                v.corners.extend(corners)
                parts.append(f"    TERM {name} := {text};")
            parts.append("END_FUZZIFY")
            defined.append(v.name)
        # ---- outputs
        out_terms: dict[str, list[str]] = {}
        discrete_out: dict[str, bool] = {}
        for o in outputs:
            parts.append(f"DEFUZZIFY {o}")
            discrete = fam == "singletons_merged" or self.flag(0.3 if fam == "mixed" else 0.15)
            discrete_out[o] = discrete
            lo = self.val(-10, 10, 1.0)
            hi = lo + r.choice([1.0, 10.0, 50.0])
            positions: list[float] = []
            names = []
            needs_range = False
            for k in range(r.randint(2, 4)):
                if discrete:
                    text = self.discrete_term(lo, hi, inputs, positions)
                else:
                    text, _c = self.continuous_term(lo, hi, [], edges)
                    if fam != "span_universe" and self.flag(0.1):
                        text = f"TRIAN {num(lo)} {inputs[0].name} {num(hi)}"  # a corner given by an input
                        needs_range = True  # (jFuzzyLogic re-estimates such a universe; we need one)
                names.append(f"o{o[-1]}s{k}")
                parts.append(f"    TERM {names[-1]} := {text};")
            if self.flag(0.1):  # a term defined twice: jFuzzyLogic keeps the last
                again = (
                    self.discrete_term(lo, hi, inputs, positions)
                    if discrete
                    else self.continuous_term(lo, hi, [], edges)[0]
                )
                parts.append(f"    TERM {names[0]} := {again};")
            out_terms[o] = names
            method = r.choice(["COGS", "COGF"]) if discrete else r.choice(_CONTINUOUS_METHODS)
            if fam == "riemann":
                method = r.choice(_CONTINUOUS_METHODS) if not discrete else method
            parts.append(f"    METHOD : {method};")
            default = r.random()
            if fam in ("nc_nan", "output_in_condition") and self.flag(0.6):
                parts.append("    DEFAULT := NC;" if self.flag(0.5) else "")
            elif default < 0.7:
                parts.append(f"    DEFAULT := {num(self.val(lo, hi))};")
            elif default < 0.85:
                parts.append("    DEFAULT := NC;")
            optional = fam not in ("span_universe", "var_range") and self.flag(0.5)
            if not discrete and (needs_range or optional):
                parts.append(f"    RANGE := ({num(lo)} .. {num(hi)});")
            parts.append("END_DEFUZZIFY")
        parts.extend(self.rule_blocks(inputs, outputs, out_terms))
        parts.append("END_FUNCTION_BLOCK")
        if self.flag(0.05):  # a second function block: both tools run the first
            parts += ["", "FUNCTION_BLOCK other", "VAR_INPUT z : REAL; END_VAR", "END_FUNCTION_BLOCK"]
        text = "\n".join(p for p in parts if p) + "\n"
        return System(fam, self.seed, text, inputs, outputs, self.rows(inputs))

    def rule_blocks(
        self, inputs: list[Var], outputs: list[str], out_terms: dict[str, list[str]]
    ) -> list[str]:
        r, fam = self.r, self.family
        n_blocks = r.randint(2, 3) if fam == "per_block_accu" else r.choice([1, 1, 1, 2])
        parts = []
        readable = outputs if fam == "output_in_condition" or (fam == "mixed" and self.flag(0.2)) else []
        names = r.sample(_BLOCK_NAMES, n_blocks) if fam in ("per_block_accu", "mixed") else []
        for b in range(n_blocks):
            # jFuzzyLogic runs rule blocks in java.util.HashMap order of their names
            parts.append(f"RULEBLOCK {names[b] if names else f'rb{b + 1}'}")
            decl = []
            if self.flag(0.7) or fam == "last_and_or":
                decl.append(f"    AND : {r.choice(_AND)};")
            if self.flag(0.4) or fam == "last_and_or":
                decl.append(f"    OR : {r.choice(_OR)};")
            r.shuffle(decl)
            parts += decl
            if self.flag(0.6):
                parts.append(f"    ACT : {r.choice(['MIN', 'PROD'])};")
            if fam == "nsum":
                parts.append("    ACCU : NSUM;")
            elif fam == "singletons_merged":  # merging shows unless the values are just added
                parts.append(f"    ACCU : {r.choice(['MAX', 'BSUM', 'PROBOR', 'NSUM'])};")
            elif fam != "accu_default" and self.flag(0.75 if fam != "per_block_accu" else 0.9):
                parts.append(f"    ACCU : {r.choice(_ACCU)};")
            for k in range(r.randint(1, 6)):
                parts.append(f"    RULE {k + 1} : IF {self.condition(inputs, readable, out_terms)} THEN "
                             f"{self.conclusions(outputs, out_terms)};")  # fmt: skip
            parts.append("END_RULEBLOCK")
        return parts

    def subcondition(self, inputs: list[Var], readable: list[str], out_terms: dict[str, list[str]]) -> str:
        r = self.r
        if readable and self.flag(0.35):
            o = r.choice(readable)
            var, term = o, r.choice(out_terms[o])
        else:
            v = r.choice(inputs)
            var, term = v.name, r.choice(v.terms)
        negate = 0.0 if self.family == "nc_nan" else 0.15  # (NOT of nothing fires)
        text = f"{var} IS {'NOT ' if self.flag(negate) else ''}{term}"
        return f"NOT {text}" if self.flag(negate * 0.7) else text

    def condition(
        self, inputs: list[Var], readable: list[str], out_terms: dict[str, list[str]], depth: int = 0
    ) -> str:
        r, fam = self.r, self.family
        n = r.choice([1, 2, 2, 3, 4]) if fam != "precedence" else r.randint(3, 5)
        items = []
        for _ in range(n):
            if depth < 1 and self.flag(0.15):
                inner = self.condition(inputs, readable, out_terms, depth + 1)
                items.append(f"{'NOT ' if self.flag(0.3) else ''}({inner})")
            else:
                items.append(self.subcondition(inputs, readable, out_terms))
        text = items[0]
        for item in items[1:]:
            text += f" {r.choice(['AND', 'OR'])} {item}"
        return text

    def conclusions(self, outputs: list[str], out_terms: dict[str, list[str]]) -> str:
        r, fam = self.r, self.family
        k = r.randint(1, len(outputs)) if fam != "with" else len(outputs)
        chosen = r.sample(outputs, k)
        if fam == "per_block_accu":
            chosen = outputs[:1]
        text = ", ".join(f"{o} IS {r.choice(out_terms[o])}" for o in chosen)
        if self.flag(0.8 if fam == "with" else 0.2):
            text += f" WITH {num(r.choice([round(r.uniform(0.05, 1.0), 2), 1.0, 0.5, 1.25]))}"
        return text

    def rows(self, inputs: list[Var]) -> list[dict[str, float]]:
        r = self.r
        out = []
        for _ in range(40):
            out.append({v.name: self.val(v.lo - 0.2 * (v.hi - v.lo), v.hi + 0.2 * (v.hi - v.lo), 0.001)
                        for v in inputs})  # fmt: skip
        for _ in range(12):  # on the corners of the terms: vertical edges, triangle tops
            out.append({v.name: (r.choice(v.corners) if v.corners else v.lo) for v in inputs})
        r.shuffle(out)
        if self.family == "nc_nan":  # first rows far from every term: no rule fires, NC shows
            out[:0] = [{v.name: v.hi + 3 * (v.hi - v.lo) + k for v in inputs} for k in range(3)]
        return out


def generate(family: str, seed: int) -> System:
    """One random system of ``family`` (deterministic in ``family`` and ``seed``)."""
    if family not in FAMILIES:
        raise ValueError(f"unknown family {family!r}")
    return _Gen(family, seed).system()
