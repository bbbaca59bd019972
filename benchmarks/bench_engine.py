"""Speed and accuracy of the fuzzyctl engine against pyfuzzylite, scikit-fuzzy and simpful,
all measured in ONE run on the two controllers of ../shared/bench/peers/models.py (tipper and
the 49-rule grid), which tipper.fcl and grid49.fcl beside this script restate in FCL.

usage: python benchmarks/bench_engine.py [--quick] [--json results.json]
peers: pip install -e '.[bench]'   (pyfuzzylite, scikit-fuzzy, simpful)

single  = mean latency of one evaluation through each library's public single-sample API
          (fuzzyctl: Controller.evaluate(dict) -> dict, inputs checked), best of 3 repeats
batch   = throughput over 100,000 random samples through the library's vectorised path
          (pyfuzzylite: numpy arrays as input values, best chunk size; scikit-fuzzy: array
          inputs; simpful has none: a loop), best of 3 repeats (slow peers: one, extrapolated)
|err|   = largest difference from the exact centroid (fuzzyctl numpy) over 1,000 samples
fuzzyctl rows: python = the specialised scalar path (its batch: a loop of evaluate), numpy =
          evaluate_batch (its single: a one-row batch), native = compile(backend="native"),
          generated C built into a cached shared library (ctypes; one call per batch)
Ratios are against pyfuzzylite, measured in this run.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import platform
import sys
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import fuzzyctl

HERE = Path(__file__).resolve().parent
SHARED = Path(os.environ.get("FUZZYCTL_SHARED", HERE.parent.parent / "shared"))
N_BATCH = 100_000
RANGES = {"tipper": (0.0, 10.0), "grid49": (-1.0, 1.0)}
warnings.simplefilter("ignore")


def _peers() -> Any:
    path = SHARED / "bench" / "peers" / "models.py"
    spec = importlib.util.spec_from_file_location("peer_models", path)
    if spec is None or spec.loader is None:
        raise SystemExit(f"cannot find the peer models at {path} (set FUZZYCTL_SHARED)")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def samples(model: str, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    lo, hi = RANGES[model]
    rng = np.random.default_rng(seed)
    return rng.uniform(lo, hi, n), rng.uniform(lo, hi, n)


def latency(single: Callable[[float, float], float], model: str, budget: float) -> float:
    """Best-of-3 mean seconds per call; each repeat runs up to 2000 calls or ``budget`` s."""
    x1, x2 = samples(model, 6000, 2)
    for i in range(50):
        single(float(x1[i]), float(x2[i]))
    t0 = time.perf_counter()
    single(float(x1[0]), float(x2[0]))
    est = max(time.perf_counter() - t0, 1e-7)
    n = int(min(2000, max(20, budget / est)))
    best = float("inf")
    for r in range(3):
        a, b = x1[r * n : (r + 1) * n].tolist(), x2[r * n : (r + 1) * n].tolist()
        t0 = time.perf_counter()
        for u, v in zip(a, b, strict=True):
            single(u, v)
        best = min(best, (time.perf_counter() - t0) / n)
    return best


def throughput(
    batch: Callable[[np.ndarray, np.ndarray], Any],
    model: str,
    budget: float,
    chunks: tuple[int, ...] = (N_BATCH,),
) -> float:
    x1, x2 = samples(model, N_BATCH, 3)
    t0 = time.perf_counter()
    batch(x1[:200], x2[:200])
    est = (time.perf_counter() - t0) / 200
    if est * N_BATCH > budget:  # a slow peer: time a prefix once and extrapolate
        n = max(200, int(budget / est))
        t0 = time.perf_counter()
        batch(x1[:n], x2[:n])
        return n / (time.perf_counter() - t0)
    best = 0.0
    for chunk in chunks:
        for _ in range(3):
            t0 = time.perf_counter()
            for s in range(0, N_BATCH, chunk):
                batch(x1[s : s + chunk], x2[s : s + chunk])
            best = max(best, N_BATCH / (time.perf_counter() - t0))
    return best


def ours(model: str) -> dict[str, tuple[Callable[..., float], Callable[..., Any]]]:
    """fuzzyctl's three paths: the specialised Python of ``evaluate``, the numpy path of
    ``evaluate_batch`` and the native backend (generated C in a shared library); each as
    (single, batch).  The Python path's batch is a loop of ``evaluate``, the numpy path's
    single evaluation a one-row batch."""
    doc = fuzzyctl.load(HERE / f"{model}.fcl")
    py = fuzzyctl.compile(doc)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no silent fallback: a missing compiler must show
        native = fuzzyctl.compile(doc, backend="native")
    a, b = py.inputs
    out = py.outputs[0]

    def single_of(ctl: Any) -> Callable[[float, float], float]:
        evaluate = ctl.evaluate
        return lambda x1, x2: evaluate({a: x1, b: x2})[out]

    def batch_of(ctl: Any) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
        return lambda x1, x2: ctl.evaluate_batch({a: x1, b: x2})[out]

    py_single = single_of(py)
    return {
        "fuzzyctl python (specialised)": (
            py_single,
            lambda x1, x2: [py_single(u, v) for u, v in zip(x1.tolist(), x2.tolist(), strict=True)],
        ),
        "fuzzyctl numpy": (
            lambda x1, x2: float(batch_of(py)(np.array([x1]), np.array([x2]))[0]),
            batch_of(py),
        ),
        "fuzzyctl native (C)": (single_of(native), batch_of(native)),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="smaller time budgets (rougher numbers)")
    ap.add_argument("--json", type=Path, help="also write the numbers as JSON")
    args = ap.parse_args()
    budget = 0.5 if args.quick else 2.0
    peers = _peers()
    libs: dict[str, Callable[[str], tuple[Callable[..., float], Any]]] = {}
    try:
        import fuzzylite  # noqa: F401

        libs["pyfuzzylite 1000"] = lambda m: peers.build_pyfuzzylite(m, resolution=1000)[:2]
    except ImportError:
        print("pyfuzzylite missing: pip install -e '.[bench]'", file=sys.stderr)
    try:
        import skfuzzy  # noqa: F401

        libs["scikit-fuzzy 1201 pts"] = lambda m: peers.build_skfuzzy(m, out_points=1201)[:2]
    except ImportError:
        print("scikit-fuzzy missing: pip install -e '.[bench]'", file=sys.stderr)
    try:
        import simpful  # noqa: F401

        libs["simpful 1000"] = lambda m: peers.build_simpful(m, subdivisions=1000)[:2]
    except ImportError:
        print("simpful missing: pip install -e '.[bench]'", file=sys.stderr)

    results: dict[str, dict[str, dict[str, float]]] = {}
    for model in ("tipper", "grid49"):
        variants = ours(model)
        x1, x2 = samples(model, 1000, 7)
        exact = variants["fuzzyctl numpy"][1](x1, x2)
        for name, (single, batch) in variants.items():
            got = np.asarray(batch(x1, x2), dtype=np.float64)
            slow = name.startswith("fuzzyctl python")
            results.setdefault(name, {})[model] = {
                "single_s": latency(single, model, budget),
                "batch_per_s": throughput(
                    batch, model, (5 if slow else 10) * budget, (10_000,) if slow else (4096, 16384, N_BATCH)
                ),
                "max_err": float(np.max(np.abs(got - exact))),
            }
        for name, build in libs.items():
            p_single, p_batch = build(model)
            errs = [
                abs(p_single(float(a), float(b)) - e)
                for a, b, e in list(zip(x1, x2, exact, strict=True))[:300]
            ]
            rec = {"single_s": latency(p_single, model, budget), "max_err": float(max(errs))}
            if p_batch is not None:
                chunks = (1_000, 10_000, N_BATCH) if name.startswith("pyfuzzylite") else (10_000,)
                rec["batch_per_s"] = throughput(p_batch, model, 10 * budget, chunks)
            else:
                rec["batch_per_s"] = throughput(
                    lambda a, b, f=p_single: [f(u, v) for u, v in zip(a, b, strict=True)], model, 5 * budget
                )
            results.setdefault(name, {})[model] = rec
        # our exactness against a fine reference: pyfuzzylite's midpoint rule at resolution 200,000
        if "pyfuzzylite 1000" in libs:
            ref_single = peers.build_pyfuzzylite(model, resolution=200_000)[0]
            diff = max(
                abs(ref_single(float(a), float(b)) - e)
                for a, b, e in list(zip(x1, x2, exact, strict=True))[:100]
            )
            results["fuzzyctl numpy"][model]["vs_pyfuzzylite_200k"] = float(diff)

    base = results.get("pyfuzzylite 1000")
    print(
        f"python {platform.python_version()} on {platform.machine()}, {os.cpu_count()} cores; "
        f"numpy {np.__version__}"
    )
    head = (
        "| engine | tipper single | x pyfl | grid49 single | x pyfl | tipper batch/s | x pyfl "
        "| grid49 batch/s | x pyfl | tipper max err | grid49 max err |"
    )
    print(head)
    print("|" + "---|" * (head.count("|") - 1))
    for name, per in results.items():
        cells = [name]
        for key, fmt in (("single_s", "us"), ("batch_per_s", "rate")):
            for model in ("tipper", "grid49"):
                v = per[model][key]
                cells.append(f"{v * 1e6:,.1f} us" if fmt == "us" else f"{v:,.0f}")
                if base:
                    b = base[model][key]
                    ratio = b / v if fmt == "us" else v / b
                    cells.append(f"{ratio:,.1f}x")
                else:
                    cells.append("-")
        cells += [f"{per['tipper']['max_err']:.2g}", f"{per['grid49']['max_err']:.2g}"]
        print("| " + " | ".join(cells) + " |")
    exact_row = results["fuzzyctl numpy"]
    if "vs_pyfuzzylite_200k" in exact_row["tipper"]:
        print(
            "fuzzyctl vs pyfuzzylite at resolution 200,000: tipper "
            f"{exact_row['tipper']['vs_pyfuzzylite_200k']:.2g}, grid49 "
            f"{exact_row['grid49']['vs_pyfuzzylite_200k']:.2g} "
            "(max |difference|, 100 samples)"
        )
    nat = results["fuzzyctl native (C)"]
    print("native (C) against the other paths (how many times faster):")
    for name, per in results.items():
        if name == "fuzzyctl native (C)":
            continue
        cells = []
        for model in ("tipper", "grid49"):
            cells.append(
                f"{model}: single {per[model]['single_s'] / nat[model]['single_s']:,.1f}x, "
                f"batch {nat[model]['batch_per_s'] / per[model]['batch_per_s']:,.1f}x"
            )
        print(f"  {name}: " + "; ".join(cells))
    if args.json:
        args.json.write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
