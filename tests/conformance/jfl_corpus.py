"""The corpus files both jFuzzyLogic and fuzzyctl load, run through both (the jfuzzylogic
profile against the live jFuzzyLogic): test_jfl_oracle.py asserts, docs/engine.md shows."""

from __future__ import annotations

import math
import random
from pathlib import Path

import fuzzyctl
from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.engine.plan import Slot
from fuzzyctl.engine.semantics import universe
from tests.conformance import jfl_oracle
from tests.conformance.jfl_agreement import Stats
from tests.conformance.jfl_oracle import Job
from tests.extras import extra_files, extra_path

ROWS = 20


def corpus_files() -> list[Path]:
    return extra_files("corpus", "corpus", "fcl", pattern="*.fcl")


def corpus_dir() -> Path:
    return extra_path("corpus", "corpus", "fcl")


def rows_for(ctl: fuzzyctl.engine.Controller, seed: str) -> list[dict[str, float]]:
    """Inputs over the span of each input's terms, widened by a fifth, on a 0.001 grid."""
    r = random.Random(seed)
    spans = {}
    for fi in ctl.plan.fuzzy_inputs:
        los, his = [], []
        for t in fi.terms:
            if t.constant and t.kind not in ("function",):
                lo, hi = universe.span(t.kind, [float(p) for p in t.params if not isinstance(p, Slot)])
                if math.isfinite(lo) and math.isfinite(hi):
                    los.append(lo)
                    his.append(hi)
        spans[fi.name] = (min(los), max(his)) if los else (0.0, 1.0)
    rows = []
    for _ in range(ROWS):
        row = {}
        for name in ctl.inputs:
            lo, hi = spans.get(name, (0.0, 1.0))
            pad = 0.2 * (hi - lo)
            row[name] = round(r.uniform(lo - pad, hi + pad), 3)
        rows.append(row)
    return rows


def compare_corpus(files: list[Path]) -> tuple[Stats, list[str], list[str]]:
    """Samples of the files both load and run; the files jFuzzyLogic loads cleanly but the
    profile refuses; the files jFuzzyLogic loads but throws on at every evaluation."""
    jobs, ctls, names = [], [], []
    ours_refuse = []
    for f in files:
        try:
            ctl = fuzzyctl.compile(fuzzyctl.load(f, compat="jfuzzylogic"), compat="jfuzzylogic")
        except FuzzyctlError:
            ours_refuse.append(f)
            continue
        rows = rows_for(ctl, f.name)
        # jFuzzyLogic only knows the variables of FUZZIFY and DEFUZZIFY blocks
        known = {fi.name for fi in ctl.plan.fuzzy_inputs}
        outs = [o.name for o in ctl.plan.outputs if o.is_output and o.kind != "degree"]
        jobs.append(Job(f, [{k: v for k, v in r.items() if k in known} for r in rows], outs))
        ctls.append((ctl, rows))
        names.append(f.name)
    answers = jfl_oracle.run(jobs + [Job(f) for f in ours_refuse], cache=True)
    cannot: list[str] = []
    st = Stats()
    for (ctl, rows), answer, name in zip(ctls, answers, names, strict=False):
        if not answer.clean:
            continue  # jFuzzyLogic does not load it (check --compat jfuzzylogic says why)
        cells = [v for row in answer.rows for v in row]
        if not cells:
            continue  # no output jFuzzyLogic knows of (a file of terms only)
        if all(isinstance(v, str) for v in cells):
            cannot.append(name)  # it throws at every evaluation (check --compat jfuzzylogic: jfl-fails)
            continue
        st.systems += 1
        got = ctl.evaluate_batch({n: [r[n] for r in rows] for n in ctl.inputs})
        scale = {
            o.name: max(1.0, o.high - o.low) if o.low is not None and o.high is not None else 1.0
            for o in ctl.plan.outputs
        }
        method = {o.name: o.method for o in ctl.plan.outputs}
        for k, out in enumerate(answer.outputs):
            for i, row in enumerate(answer.rows):
                want, mine = row[k], float(got[out][i])
                if isinstance(want, str):
                    err = math.inf
                elif math.isnan(want) or math.isnan(mine):
                    err = 0.0 if math.isnan(want) and math.isnan(mine) else math.inf
                else:
                    err = abs(mine - want) / scale[out]
                st.add(err, f"{name} {out} row {i} ours {mine!r} jfl {want!r}", method[out])
    refused_but_clean = [f.name for f, a in zip(ours_refuse, answers[len(ctls) :], strict=True) if a.clean]
    return st, refused_but_clean, cannot


if __name__ == "__main__":
    stats, refused, cannot = compare_corpus(corpus_files())
    print(f"{stats.systems} files, {stats.samples} samples: {stats.within_1e9} within 1e-9, "
          f"{stats.within_1e3} within 1e-3, worst {stats.worst:.3g}")  # fmt: skip
    print("we refuse, jFuzzyLogic loads:", refused)
    print("jFuzzyLogic loads but cannot evaluate:", cannot)
    for f in stats.failures:
        print(f)
