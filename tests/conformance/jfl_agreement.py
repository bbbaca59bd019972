"""Agreement of the jfuzzylogic profile with the live jFuzzyLogic on random systems, per
behaviour (``python -m tests.conformance.jfl_agreement [SYSTEMS_PER_FAMILY] [SEED] [PROFILE] [LIBM]``
prints the table docs/engine.md shows; test_jfl_oracle.py asserts it)."""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field

import numpy as np

import fuzzyctl
from fuzzyctl.diagnostics import FuzzyctlError
from tests.conformance import jfl_oracle
from tests.conformance.jfl_oracle import Answer, Job
from tests.conformance.randfcl import FAMILIES, System, generate

#: Defuzzifiers that compare samples for equality (the maximum's plateau, COA's running
#: sums): there one ulp of difference in a sample can move the result by a sample step.
TIE_METHODS = frozenset({"MOM", "LM", "RM", "COA"})
ONE_STEP = 1.0 / 1000 + 1e-12  # of the range: one of jFuzzyLogic's 1000 sample steps


@dataclass
class Stats:
    """Samples compared for one family: within 1e-9 and 1e-3 of the output's range (of the
    value, at least 1, for discrete outputs), and the worst such error.  ``ties``: samples of
    a tie-comparing defuzzifier off by at most one sample step (against a JVM whose
    ``Math.exp``, ``cos``, ``pow`` are HotSpot's intrinsics rather than fdlibm: one ulp there
    decides a tie; docs/engine.md)."""

    systems: int = 0
    samples: int = 0
    within_1e9: int = 0
    within_1e3: int = 0
    worst: float = 0.0
    both_refuse: int = 0
    ties: int = 0
    failures: list[str] = field(default_factory=list)

    def add(self, err: float, where: str, method: str | None = None) -> None:
        self.samples += 1
        self.within_1e9 += err <= 1e-9
        self.within_1e3 += err <= 1e-3
        if err > self.worst:
            self.worst = err
        if err > 1e-9 and method in TIE_METHODS and err <= ONE_STEP:
            self.ties += 1
        elif err > 1e-9 and len(self.failures) < 5:
            self.failures.append(f"{where}: error {err:.3g}")

    @property
    def unexplained(self) -> int:
        """Samples beyond 1e-9 that are not one-step ties."""
        return self.samples - self.within_1e9 - self.ties


def ours(
    system: System, compat: str = "jfuzzylogic"
) -> tuple[dict[str, np.ndarray] | None, dict[str, tuple[float, str]], str]:
    """Our outputs on the system's rows (successive evaluations, as the oracle does), the
    scale of each output's error and its method, and why we refuse it if we do."""
    try:
        c = fuzzyctl.compile(fuzzyctl.load(system.text, compat=compat), compat=compat)
    except FuzzyctlError as exc:
        return None, {}, str(exc).splitlines()[0]
    got = c.evaluate_batch({name: [r[name] for r in system.rows] for name in c.inputs})
    scale = {
        o.name: (max(1.0, (o.high - o.low) if o.low is not None and o.high is not None else 1.0), o.method)
        for o in c.plan.outputs
    }
    if compat == "jfuzzylogic":  # the scalar path is the same arithmetic: the very same numbers
        c.reset()
        for i, row in enumerate(system.rows[:8]):
            for k, v in c.evaluate(row).items():
                same = v == got[k][i] or (math.isnan(v) and math.isnan(got[k][i]))
                assert same, (system.family, system.seed, k, i)
    return got, scale, ""


def compare(systems: list[System], compat: str = "jfuzzylogic", libm: str = "fdlibm") -> dict[str, Stats]:
    """Per family: how our ``compat`` profile agrees with the live jFuzzyLogic (``libm``: the
    JVM's math, jfl_oracle.LIBM)."""
    answers = jfl_oracle.run([Job(s.text, s.rows, s.outputs) for s in systems], libm=libm)
    stats: dict[str, Stats] = {}
    for system, answer in zip(systems, answers, strict=True):
        st = stats.setdefault(system.family, Stats())
        st.systems += 1
        _compare(system, answer, st, compat)
    return stats


def _compare(system: System, answer: Answer, st: Stats, compat: str) -> None:
    where = f"{system.family}/{system.seed}"
    got, scale, refused = ours(system, compat)
    jfl_refuses = answer.load_error is not None or answer.syntax_errors > 0
    if got is None or jfl_refuses:
        if got is None and jfl_refuses:
            st.both_refuse += 1
            return
        st.failures.append(f"{where}: ours {'refuses: ' + refused if got is None else 'runs'}; "
                           f"jFuzzyLogic {answer.load_error or answer.syntax_errors or 'runs'}")  # fmt: skip
        st.samples += len(system.rows)
        st.worst = math.inf
        return
    for k, name in enumerate(answer.outputs):
        for i, row in enumerate(answer.rows):
            want = row[k]
            mine = float(got[name][i])
            if isinstance(want, str):
                err = math.inf
            elif math.isnan(want) or math.isnan(mine):
                err = 0.0 if math.isnan(want) and math.isnan(mine) else math.inf
            else:
                err = abs(mine - want) / scale[name][0]
            st.add(err, f"{where} {name} row {i} ours {mine!r} jfl {want!r}", scale[name][1])


def table(stats: dict[str, Stats]) -> str:
    lines = [
        "| behaviour | systems | samples | within 1e-9 | within 1e-3 | worst | one-step ties |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for fam, st in stats.items():
        lines.append(
            f"| {FAMILIES[fam]} | {st.systems} | {st.samples} | {_pct(st.within_1e9, st.samples)} "
            f"| {_pct(st.within_1e3, st.samples)} | {st.worst:.1e} | {st.ties} |"
        )
    return "\n".join(lines)


def _pct(k: int, n: int) -> str:
    return f"{100.0 * k / n:.1f}%" if n else "-"


def systems(per_family: int, seed: int) -> list[System]:
    return [generate(fam, seed + k) for fam in FAMILIES for k in range(per_family)]


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    seed = int(sys.argv[2]) if len(sys.argv) > 2 else 0
    profile = sys.argv[3] if len(sys.argv) > 3 else "jfuzzylogic"
    java_math = sys.argv[4] if len(sys.argv) > 4 else "fdlibm"
    result = compare(systems(n, seed), profile, java_math)
    print(table(result))
    for st in result.values():
        for f in st.failures[: 2 if profile != "jfuzzylogic" else 5]:
            print(f)
