"""Tune the container crane controller in closed loop, and the speed-up of Dask workers.

    python benchmarks/tune_crane.py [--budget 100] [--seed 0] [--workers 1,2] [--out build/tune_crane]

examples/crane.fcl against examples/crane_tune.toml (four transports; cost = settling time
+ integrated sway, see docs/tune.md) with CMA-ES.  The same tuning runs once per worker
count on a LocalCluster on this machine; the results must be identical (same seed), the
times give the speed-up.  Prints the before/after table per scenario (settling time, sway
integral, largest sway) and the timing table; writes the tuned FCL and the report."""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--budget", type=int, default=100)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--workers", default="1,2", help="worker counts to compare, comma-separated")
    ap.add_argument("--out", type=Path, default=ROOT / "build" / "tune_crane")
    args = ap.parse_args()

    import fuzzyctl
    from fuzzyctl.tune import plant
    from fuzzyctl.tune.parallel import local_cluster

    fcl = ROOT / "examples" / "crane.fcl"
    toml = ROOT / "examples" / "crane_tune.toml"
    results = {}
    for n in (int(w) for w in args.workers.split(",")):
        t0 = time.perf_counter()
        client, cluster = local_cluster(n)
        started = time.perf_counter() - t0
        try:
            r = fuzzyctl.tune(fcl, plant_config=toml, budget=args.budget, seed=args.seed, client=client)
        finally:
            client.close()
            cluster.close()
        results[n] = (r, started)
        print(
            f"{n} worker(s): {r.evaluations} evaluations in {r.seconds:.1f} s "
            f"(cluster start {started:.1f} s)",
            flush=True,
        )
    runs = list(results.values())
    first = runs[0][0]
    for r, _ in runs[1:]:
        assert r.history == first.history and r.document == first.document, (
            "results differ between worker counts"
        )

    scenarios, _ = plant.load_scenarios(toml)
    before_traces, after_traces = first.traces
    print(f"\nCMA-ES, seed {args.seed}, budget {args.budget}: cost {first.before:.2f} -> {first.after:.2f}")
    print(
        "\n| transport | settling s before | after | sway integral deg s before | after "
        "| largest sway deg before | after |"
    )
    print("|---|---|---|---|---|---|---|")
    for sc, tb, ta in zip(scenarios, before_traces, after_traces, strict=True):
        mb = plant.metrics(sc, tb, ["settling_time", "iae:angle", "max:angle"])
        ma = plant.metrics(sc, ta, ["settling_time", "iae:angle", "max:angle"])
        print(
            f"| {sc.name} | {mb['settling_time']:.2f} | {ma['settling_time']:.2f} | {mb['iae:angle']:.2f} | "
            f"{ma['iae:angle']:.2f} | {mb['max:angle']:.2f} | {ma['max:angle']:.2f} |"
        )
    print("\n| parameter | before | after |\n|---|---|---|")
    for name, b, a in first.changes:
        print(f"| {name} | {b:g} | {a:g} |")
    base = runs[0][0].seconds
    print(f"\nmachine: {os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.1f} (1 min) at the end")
    print("| workers | tuning time s | speed-up | cluster start s |\n|---|---|---|---|")
    for n, (r, started) in results.items():
        print(f"| {n} | {r.seconds:.1f} | {base / r.seconds:.2f} | {started:.1f} |")
    args.out.mkdir(parents=True, exist_ok=True)
    first.write_fcl(args.out / "crane_tuned.fcl")
    first.write_report(args.out / "report")
    print(f"\nwrote {args.out / 'crane_tuned.fcl'} and {args.out / 'report'}/")
    return 0


if __name__ == "__main__":
    sys.exit(main())
