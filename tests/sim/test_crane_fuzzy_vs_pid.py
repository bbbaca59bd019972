"""The crane under the Annex C fuzzy rules and under the tuned PID of
``examples/crane_pid.toml``: both meet the goal on every scenario; the table of quality
figures is printed (pytest -s; ``benchmarks/crane_fuzzy_vs_pid.py`` prints the same)."""

from __future__ import annotations

import dataclasses
import math

from fuzzyctl.sim import quality
from fuzzyctl.sim.config import build_loop, load_config
from tests.conftest import EXAMPLES

SCENARIOS = [  # target m, load kg, rope m, initial sway deg
    (30.0, 25000.0, 12.0, 0.0),
    (10.0, 25000.0, 12.0, 0.0),
    (40.0, 40000.0, 20.0, 0.0),
    (20.0, 5000.0, 6.0, 3.0),
    (15.0, 15000.0, 9.0, -4.0),
]


def test_fuzzy_and_pid_both_put_the_load_down_and_the_table_is_printed():
    configs = {"fuzzy": load_config(EXAMPLES / "crane.toml"), "PID": load_config(EXAMPLES / "crane_pid.toml")}
    head = "| controller | target | load t | rope | sway0 | settling s | ISE | overshoot m |"
    lines = [head, "|---" * 8 + "|"]
    for target, load, rope, sway in SCENARIOS:
        for name, cfg in configs.items():
            plant = {**cfg.plant_parameters, "load_mass": load, "rope_length": rope, "angle0": sway}
            run = dataclasses.replace(cfg, plant_parameters=plant, setpoints={"target": target})
            trace = build_loop(run).run(100.0)
            q = quality(trace, "load_position", "target", band=0.1, limits={"angle": 2.0})
            lines.append(
                f"| {name} | {target:g} | {load / 1000:g} | {rope:g} | {sway:g} | {q.settling_time:.1f} "
                f"| {q.ise:.0f} | {q.overshoot:.3f} |"
            )
            assert math.isfinite(q.settling_time) and q.settling_time <= 20.0 + 1.2 * target
            assert q.overshoot < 1.0
    print("\n" + "\n".join(lines))
