"""The closed-form gradient: its values are the engine's, its derivatives agree with finite
differences of the engine's outputs (except on the measure-zero boundaries of pieces), and
it says where it does not hold."""

from __future__ import annotations

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.engine.compile import COMPAT_PROFILES
from fuzzyctl.engine.lowering.lower import lower
from fuzzyctl.fcl import load_text
from fuzzyctl.tune import gradient
from fuzzyctl.tune.space import build_space
from tests.conftest import EXAMPLES


def _system(rng: np.random.Generator, and_op: str, accu: str, kind: str) -> str:
    c = np.sort(rng.uniform(-10, 10, 5))
    e = np.sort(rng.uniform(-5, 5, 4))
    if kind == "singleton":
        outs = "\n".join(f"TERM o{j} := {v:.4f};" for j, v in enumerate(np.sort(rng.uniform(-20, 20, 4))))
        method = "CoGS"
    else:
        outs = "\n".join(
            f"TERM o{j} := Linear {rng.uniform(-2, 2):.3f} {rng.uniform(-2, 2):.3f} {rng.uniform(-5, 5):.3f};"
            for j in range(4)
        )
        method = "WTAVER"
    rules = []
    for r in range(9):
        a, b = ["lo", "mid", "hi"][r % 3], ["n", "g", "p"][r // 3]
        w = f" WITH {rng.uniform(0.3, 1.0):.3f}" if r % 2 else ""
        rules.append(f"RULE {r + 1} : IF x IS {a} AND y IS {b} THEN z IS o{r % 4}{w};")
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
  {outs}
  METHOD : {method};
  DEFAULT := 0;
END_DEFUZZIFY
RULEBLOCK r
  AND : {and_op};
  ACCU : {accu};
  {chr(10).join(rules)}
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


CASES = [
    (0, "MIN", "MAX", "singleton"),
    (1, "PROD", "SUM", "singleton"),
    (2, "PROD", "BSUM", "singleton"),
    (3, "MIN", "MAX", "ts"),
    (4, "PROD", "SUM", "ts"),
]


@pytest.mark.parametrize(("seed", "and_op", "accu", "kind"), CASES)
def test_closed_form_matches_engine_and_finite_differences(
    seed: int, and_op: str, accu: str, kind: str
) -> None:
    rng = np.random.default_rng(seed)
    fb = load_text(_system(rng, and_op, accu, kind)).raise_for_errors().main
    space = build_space(fb, "all,weights")
    u = np.clip(space.initial() + rng.normal(0, 0.02, space.size), 0.0, 1.0)
    cand = space.decode(u)
    plan, _ = lower(cand, COMPAT_PROFILES["iec"])
    assert plan is not None
    assert gradient.unsupported(plan, ["z"]) is None
    n = 600
    x, y = rng.uniform(-11, 11, n), rng.uniform(-6, 6, n)
    value, grad = gradient.forward(plan, [x, y], ["z"])["z"]
    engine = fuzzyctl.compile(cand).evaluate_batch({"x": x, "y": y})["z"]
    fired = ~np.isnan(value)
    assert fired.mean() > 0.5
    assert np.allclose(value[fired], engine[fired], rtol=1e-12, atol=1e-12)

    smap = gradient.slot_map(cand, plan)
    assert smap is not None
    J = np.zeros((n, space.size))
    for key, (j, d) in space.derivative(u).items():
        ps = smap[key]
        if ps in grad:
            J[:, j] += grad[ps] * d
    h = 1e-6
    fd = np.empty_like(J)
    for j in range(space.size):
        up, um = u.copy(), u.copy()
        up[j] = min(1.0, u[j] + h)  # one-sided at the bounds of the box
        um[j] = max(0.0, u[j] - h)
        yp = fuzzyctl.compile(space.decode(up)).evaluate_batch({"x": x, "y": y})["z"]
        ym = fuzzyctl.compile(space.decode(um)).evaluate_batch({"x": x, "y": y})["z"]
        fd[:, j] = (yp - ym) / (up[j] - um[j])
    bad = np.abs(J - fd) > 1e-4 * np.maximum(1.0, np.abs(fd))
    # only samples within h of a breakpoint or a MIN/MAX switch may disagree
    assert bad.mean() < 0.005, f"{bad.sum()} of {bad.size} derivatives differ"
    assert np.abs(J).max() > 0.0


def test_crane_is_in_the_closed_form_class() -> None:
    plan = fuzzyctl.compile(fuzzyctl.load(EXAMPLES / "crane.fcl")).plan
    assert gradient.unsupported(plan, ["power"]) is None


@pytest.mark.parametrize(
    ("change", "reason"),
    [
        ("METHOD : CoGS;", "LM"),
        ("AND : MIN;", "OR"),
        ("ACCU : MAX;", "hedges"),
    ],
)
def test_says_where_it_does_not_hold(change: str, reason: str) -> None:
    text = (EXAMPLES / "crane.fcl").read_text(encoding="utf-8")
    if reason == "LM":
        text = text.replace("METHOD : CoGS;", "METHOD : LM;").replace(
            "TERM neg_high := -100;", "TERM neg_high := (-100, 1) (-50, 0);"
        )
        text = text.replace("TERM neg_medium := -50;", "TERM neg_medium := (-100, 0) (-50, 1) (0, 0);")
        text = text.replace("TERM zero := 0;", "TERM zero := (-50, 0) (0, 1) (50, 0);")
        text = text.replace("TERM pos_medium := 50;", "TERM pos_medium := (0, 0) (50, 1) (100, 0);")
        text = text.replace("TERM pos_high := 100;", "TERM pos_high := (50, 0) (100, 1);")
        text = text.replace("DEFAULT := 0;", "RANGE(-100..100); DEFAULT := 0;")
    elif reason == "OR":
        text = text.replace(
            "IF distance IS far AND angle IS neg_big", "IF distance IS far OR angle IS neg_big"
        )
    else:
        text = text.replace(
            "IF distance IS far AND angle IS neg_big", "IF distance IS very far AND angle IS neg_big"
        )
    plan = fuzzyctl.compile(load_text(text).raise_for_errors()).plan
    why = gradient.unsupported(plan, ["power"])
    assert why is not None and reason in why
