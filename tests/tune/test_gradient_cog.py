"""The closed-form gradient of COG on Mamdani outputs: its values are the engine's to 1e-12,
its derivatives are central differences of the engine's outputs wherever the engine's output
is smooth within the step (forward and backward differences agree), and `tune --optimizer
lsq` uses it on a Mamdani system and lowers the loss."""

from __future__ import annotations

import re

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.engine.batch import BatchEvaluator
from fuzzyctl.engine.compile import COMPAT_PROFILES
from fuzzyctl.engine.lowering.lower import lower
from fuzzyctl.fcl import load_text
from fuzzyctl.model import FunctionBlock
from fuzzyctl.tune import gradient
from fuzzyctl.tune.space import Space, build_space

# excluded entries (a kink of the engine's output within the step) per case, filled by the
# test and reported in docs/tune.md
EXCLUDED: dict[int, float] = {}
#: of which the closed form and the difference estimate disagree
DISAGREE: dict[int, float] = {}


def _system(
    rng: np.random.Generator, and_op: str, act: str, accu: str, n_rules: int = 12, method: str = "CoG"
) -> str:
    c = np.sort(rng.uniform(-10, 10, 5))
    e = np.sort(rng.uniform(-5, 5, 4))
    p = np.sort(rng.uniform(-18, 18, 7))
    rules = []
    for r in range(n_rules):
        a, b = ["lo", "mid", "hi"][r % 3], ["n", "g", "p"][(r // 3) % 3]
        w = f" WITH {rng.uniform(0.3, 1.0):.3f}" if r % 2 else ""
        rules.append(f"RULE {r + 1} : IF x IS {a} AND y IS {b} THEN z IS o{r % 5}{w};")
    f = [f"{v:.4f}" for v in p]
    return f"""
FUNCTION_BLOCK g
VAR_INPUT x : REAL; y : REAL; END_VAR
VAR_OUTPUT z : REAL; END_VAR
FUZZIFY x
  RANGE(-10..10);
  TERM lo := ({c[0]:.4f}, 1) ({c[1]:.4f}, 0);
  TERM mid := TRIAN {c[0]:.4f} {c[2]:.4f} {c[4]:.4f};
  TERM hi := ({c[2]:.4f}, 0) ({c[3]:.4f}, 0.8) ({c[4]:.4f}, 1);
END_FUZZIFY
FUZZIFY y
  TERM n := ({e[0]:.4f}, 1) ({e[2]:.4f}, 0);
  TERM g := GAUSS {e[1]:.4f} 2.5;
  TERM p := ({e[1]:.4f}, 0) ({e[3]:.4f}, 1);
END_FUZZIFY
DEFUZZIFY z
  RANGE(-20..20);
  TERM o0 := ({f[0]}, 1) ({f[1]}, 0);
  TERM o1 := TRIAN {f[0]} {f[2]} {f[4]};
  TERM o2 := TRAPE {f[1]} {f[2]} {f[3]} {f[5]};
  TERM o3 := ({f[3]}, 0) ({f[4]}, 0.7) ({f[5]}, 0.4) ({f[6]}, 0);
  TERM o4 := ({f[5]}, 0) ({f[6]}, 1);
  METHOD : {method};
  ACCU : {accu};
  DEFAULT := 0;
END_DEFUZZIFY
RULEBLOCK r
  AND : {and_op};
  ACT : {act};
  {chr(10).join(rules)}
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


CASES = [
    (0, "MIN", "MIN", "MAX", "iec", "CoG"),
    (1, "PROD", "PROD", "SUM", "iec", "CoG"),
    (2, "MIN", "MIN", "BSUM", "iec", "CoG"),
    (3, "PROD", "MIN", "MAX", "pyfuzzylite", "CoG"),  # WITH before activation
    (4, "MIN", "PROD", "MAX", "iec", "CoG"),
    (5, "PROD", "MIN", "SUM", "iec", "CoG"),
    (6, "MIN", "MIN", "MAX", "iec", "CoA"),
    (7, "PROD", "PROD", "BSUM", "iec", "CoA"),
]


def _jacobian(
    space: Space, smap: dict[tuple[object, ...], gradient.PSlot], grad: gradient.Grad, u: np.ndarray, n: int
) -> np.ndarray:
    J = np.zeros((n, space.size))
    for key, (j, d) in space.derivative(u).items():
        ps = smap[key]
        if ps in grad:
            J[:, j] += grad[ps] * d
    return J


@pytest.mark.parametrize(("seed", "and_op", "act", "accu", "compat", "method"), CASES)
def test_area_closed_form_matches_engine_and_finite_differences(
    seed: int, and_op: str, act: str, accu: str, compat: str, method: str
) -> None:
    rng = np.random.default_rng(100 + seed)
    fb = load_text(_system(rng, and_op, act, accu, method=method)).raise_for_errors().main
    space = build_space(fb, "all,weights")
    u = np.clip(space.initial() + rng.normal(0, 0.02, space.size), 0.0, 1.0)
    cand = space.decode(u)
    plan, _ = lower(cand, COMPAT_PROFILES[compat])
    assert plan is not None
    assert gradient.unsupported(plan, ["z"]) is None
    n = 200
    x, y = rng.uniform(-11, 11, n), rng.uniform(-6, 6, n)

    def engine(block: FunctionBlock) -> np.ndarray:
        # the engine's numpy evaluator on the lowered block (what fuzzyctl.compile runs for
        # evaluate_batch, without building a scalar evaluator per candidate)
        p, _d = lower(block, COMPAT_PROFILES[compat])
        assert p is not None
        return BatchEvaluator(p).run([x, y], [None])[0]

    value, grad = gradient.forward(plan, [x, y], ["z"])["z"]
    y0 = engine(cand)
    fired = ~np.isnan(value)
    assert fired.mean() > 0.5
    full = fuzzyctl.compile(cand, compat=compat).evaluate_batch({"x": x, "y": y})["z"]
    assert np.allclose(value[fired], full[fired], rtol=1e-12, atol=1e-12)
    assert np.array_equal(full, y0)

    smap = gradient.slot_map(cand, plan)
    assert smap is not None
    J = _jacobian(space, smap, grad, u, n)
    # slopes on the two steps next to u (inside the box: u-h..u..u+h; at a bound the two
    # steps inside it), the derivative at u extrapolated to second order from them
    h = 1e-6
    s1, s2, est = np.empty_like(J), np.empty_like(J), np.empty_like(J)
    for j in range(space.size):
        side = -1.0 if u[j] + h > 1.0 else (1.0 if u[j] - h < 0.0 else 0.0)
        steps = [-1.0, 0.0, 1.0] if side == 0.0 else [side * k for k in (0.0, 1.0, 2.0)]
        ys = []
        for k in steps:
            v = u.copy()
            v[j] = u[j] + k * h
            ys.append(y0 if k == 0.0 else engine(space.decode(v)))
        if side < 0.0:
            ys, steps = ys[::-1], steps[::-1]
        a, b = (ys[1] - ys[0]) / h, (ys[2] - ys[1]) / h
        s1[:, j], s2[:, j] = a, b
        at = steps.index(0.0)
        est[:, j] = 0.5 * (a + b) if at == 1 else (a - 0.5 * (b - a) if at == 0 else b + 0.5 * (b - a))

    def tol(d: np.ndarray) -> np.ndarray:
        return 1e-4 * np.maximum(1.0, np.abs(d))

    # a kink of the engine's output within the steps: the two slopes differ
    kink = np.abs(s2 - s1) > tol(est)
    bad = (np.abs(J - est) > tol(est)) & ~kink
    EXCLUDED[seed] = float(kink.mean())
    DISAGREE[seed] = float((kink & (np.abs(J - est) > tol(est))).mean())
    assert DISAGREE[seed] < 0.002  # even at the kinks the two mostly agree
    assert not bad.any(), f"{bad.sum()} of {bad.size} derivatives differ outside kinks"
    assert kink.mean() < 0.02, f"{kink.mean():.2%} of the entries are at kinks"
    # every kind of parameter has a nonzero derivative somewhere: output points, WITH, inputs
    kinds = {k[0] for k, (j, _d) in space.derivative(u).items() if np.abs(J[:, j]).max() > 0.0}
    assert kinds >= {"term", "with"}
    out_cols = [j for k, (j, _d) in space.derivative(u).items() if k[0] == "term" and k[1] == "z"]
    assert np.abs(J[:, out_cols]).max() > 0.0


def test_where_the_cog_closed_form_does_not_hold() -> None:
    rng = np.random.default_rng(7)
    text = _system(rng, "MIN", "MIN", "MAX")
    for old, new, reason in [
        ("METHOD : CoG;", "METHOD : LM;", "LM"),
        ("ACCU : MAX;", "ACCU : PROBOR;", "PROBOR"),
        (re.search(r"TERM o4 := \(\S+, 0\)", text)[0], "", "vertical edge"),  # type: ignore[index]
        ("TERM o1 := TRIAN", "TERM o1 := GAUSS 0 3; TERM o9 := TRIAN", "shape gaussian"),
    ]:
        if reason == "vertical edge":
            x0 = old.split("(")[1].split(",")[0]
            new = f"TERM o4 := ({x0}, 0) ({x0}, 0.5)"
        assert old in text
        plan = fuzzyctl.compile(load_text(text.replace(old, new, 1)).raise_for_errors()).plan
        why = gradient.unsupported(plan, ["z"])
        assert why is not None and reason in why, (reason, why)


@pytest.mark.parametrize(("method", "optimizer"), [("CoG", "lsq"), ("CoA", "lsq"), ("CoG", "lbfgsb")])
def test_tuning_a_mamdani_system_uses_the_closed_form(method: str, optimizer: str) -> None:
    rng = np.random.default_rng(11)
    truth = load_text(_system(rng, "MIN", "MIN", "MAX", n_rules=9, method=method)).raise_for_errors().main
    x, y = rng.uniform(-10, 10, 300), rng.uniform(-5, 5, 300)
    z = fuzzyctl.compile(truth).evaluate_batch({"x": x, "y": y})["z"]
    space = build_space(truth, "z")
    moved = space.decode(np.clip(space.initial() + rng.normal(0, 0.05, space.size), 0, 1), digits=6)
    data = {"x": x, "y": y, "z": z}
    r = fuzzyctl.tune(moved, data=data, free="z", optimizer=optimizer, workers=0, budget=25)
    assert "gradient: closed form" in r.notes
    assert not any("finite differences" in note for note in r.notes)
    assert r.before > 0.1
    if optimizer == "lbfgsb":
        assert r.after < 0.05 * r.before
        return
    # the known optimum, in a handful of evaluations (forward differences need ~50 here)
    assert r.after < 1e-6 and r.evaluations <= 12
    assert r.block.defuzzify[0].terms == truth.defuzzify[0].terms  # type: ignore[attr-defined]
