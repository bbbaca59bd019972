"""Fit a Mamdani controller to logs of a plant under PID, and compare the closed loops.

    python benchmarks/fit_pid_logs.py [--budget 60] [--out build/fit_pid]

1. Log: a first-order-plus-dead-time plant (K = 1, tau = 20 s, L = 2 s) under a PI
   controller (Kp = 5, Ti = 16 s: the SIMC rule with tau_c = L), 0.25 s cycle, 20 minutes
   of random setpoint steps in [-2, 2] and load steps in [-1, 1].
2. Learn (``fuzzyctl.learn``): a Mamdani system with singleton outputs, 5 x 5 grid over the
   error e = w - y and its rate de = ddt(e), output the rate of the drive du (the fuzzy PI
   of IEC 61131-7 figure A.13b, velocity form), 7 output singletons.
3. Closed loop on a scenario that is not in the logs (step of the setpoint 0 -> 1 at 5 s, then a
   load step of -0.5 at 100 s), the learned controller in the fuzzy-PI structure against
   the PI itself: IAE, ISE, overshoot, settling time (2 % band).
4. Optionally the learned controller tuned in closed loop (``fuzzyctl.tune``, CMA-ES,
   cost IAE over two scenarios) - the same comparison.

Prints the tables quoted in docs/tune.md; writes the learned and tuned FCL."""

from __future__ import annotations

import argparse
import sys
import textwrap
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
DT = 0.25
KP, TI = 5.0, 16.0
PLANT = {"gain": 1.0, "time_constant": 20.0, "dead_time": 2.0}


def pid_loop(w: object, load: object) -> object:
    from fuzzyctl import sim

    pid = sim.PID(KP, ti=TI, low=-30.0, high=30.0)
    structure = sim.PIDLoop(pid, setpoint="w", measurement="y", drive="u")
    return sim.Loop(
        sim.make_plant("fopdt", PLANT), structure, period=DT, setpoints={"w": w}, disturbances={"load": load}
    )


def fuzzy_loop(doc: object, w: object, load: object) -> object:
    from fuzzyctl import sim

    fuzzy = sim.make_runtime(doc)  # type: ignore[arg-type]
    structure = sim.FuzzyPI(
        fuzzy, {"e": "w - y", "de": "ddt(e)"}, output="du", drive="u", low=-30.0, high=30.0
    )
    return sim.Loop(
        sim.make_plant("fopdt", PLANT), structure, period=DT, setpoints={"w": w}, disturbances={"load": load}
    )


def logs(seed: int = 0) -> dict[str, np.ndarray]:
    from fuzzyctl.sim import profiles

    rng = np.random.default_rng(seed)
    w = profiles.steps([(t, float(rng.uniform(-2, 2))) for t in np.arange(0.0, 1200.0, 60.0)])
    load = profiles.steps([(t, float(rng.uniform(-1, 1))) for t in np.arange(30.0, 1200.0, 90.0)], before=0.0)
    trace = pid_loop(w, load).run(1200.0)  # type: ignore[attr-defined]
    e = trace["w"] - trace["y"]
    de = np.concatenate([[0.0], np.diff(e) / DT])  # ddt(e): backward difference, 0 on the first call
    u = trace["u"]
    du = np.concatenate([[u[0] / DT], np.diff(u) / DT])  # what a velocity-form block outputs
    return {"e": e, "de": de, "du": du}


def quality(trace: object) -> dict[str, float]:
    from fuzzyctl.sim import quality as q

    qa = q(trace, "y", "w", band=0.02)  # type: ignore[arg-type]
    return {"IAE": qa.iae, "ISE": qa.ise, "overshoot": qa.overshoot, "settling s": qa.settling_time}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--budget", type=int, default=60, help="closed-loop tuning budget (0: skip)")
    ap.add_argument("--out", type=Path, default=ROOT / "build" / "fit_pid")
    args = ap.parse_args()

    import fuzzyctl
    from fuzzyctl.sim import profiles

    args.out.mkdir(parents=True, exist_ok=True)
    data = logs()
    learned = fuzzyctl.learn(
        data, inputs=["e", "de"], output="du", kind="mamdani", out_terms=25, name="fuzzy_pi"
    )
    learned.write_fcl(args.out / "fuzzy_pi_learned.fcl")
    n_out = len(learned.block.defuzzify[0].terms)
    print(f"logged rows: {len(data['e'])}; learned {learned.rules} rules, {n_out} output singletons")
    print(
        f"fit of du: training RMSE {learned.scores['training RMSE']:.4g}, validation RMSE "
        f"{learned.scores['validation RMSE']:.4g} (du spans {np.ptp(data['du']):.3g})"
    )

    w = profiles.steps([(5.0, 1.0)], before=0.0)
    load = profiles.steps([(100.0, -0.5)], before=0.0)
    rows = [("PI (Kp 5, Ti 16 s)", quality(pid_loop(w, load).run(200.0)))]  # type: ignore[attr-defined]
    rows.append(
        ("Mamdani fitted to the PI's logs", quality(fuzzy_loop(learned.document, w, load).run(200.0)))
    )  # type: ignore[attr-defined]

    if args.budget > 0:
        toml = args.out / "fuzzy_pi.toml"
        toml.write_text(
            textwrap.dedent(
                f"""\
                title = "fuzzy PI on a lag"
                duration = 200
                [plant]
                model = "fopdt"
                gain = {PLANT["gain"]}
                time_constant = {PLANT["time_constant"]}
                dead_time = {PLANT["dead_time"]}
                [controller]
                structure = "fuzzy_pi"
                file = "fuzzy_pi_learned.fcl"
                cycle = {DT}
                output = "du"
                drive = "u"
                low = -30
                high = 30
                inputs = {{ e = "w - y", de = "ddt(e)" }}
                [setpoints]
                w = {{ steps = [[5, 1.5]], before = 0 }}
                [disturbances]
                load = {{ steps = [[120, 0.8]], before = 0 }}
                [quality]
                signal = "y"
                setpoint = "w"
                band = 0.03
                [tune]
                cost = {{ iae = 1 }}
                [[tune.scenarios]]
                name = "setpoint 1.5, load +0.8"
                [[tune.scenarios]]
                name = "setpoint -1, load -0.5"
                setpoints = {{ w = {{ steps = [[5, -1]], before = 0 }} }}
                disturbances = {{ load = {{ steps = [[120, -0.5]], before = 0 }} }}
                """
            )
        )
        tuned = fuzzyctl.tune(learned.document, plant_config=toml, budget=args.budget, workers=0)
        tuned.write_fcl(args.out / "fuzzy_pi_tuned.fcl")
        rows.append(
            (
                f"the same, tuned in closed loop ({tuned.evaluations} ev.)",
                quality(fuzzy_loop(tuned.document, w, load).run(200.0)),
            )  # type: ignore[attr-defined]
        )
        print(f"closed-loop tuning on its own scenarios: IAE {tuned.before:.4g} -> {tuned.after:.4g}")

    print("\ntest scenario (not in the logs): setpoint 0 -> 1 at 5 s, load -0.5 at 100 s, 200 s")
    print("| controller | IAE | ISE | overshoot | settling s (2 %) |\n|---|---|---|---|---|")
    for name, q in rows:
        print(f"| {name} | {q['IAE']:.3f} | {q['ISE']:.3f} | {q['overshoot']:.3f} | {q['settling s']:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
