"""One peer library on one benchmark system, run inside the peers' own virtual environment
(``.venv-peers``: pyfuzzylite, scikit-fuzzy and simpful pin numpy<2, the project keeps numpy 2).
bench_engine.py starts this script and reads one JSON line from it.

usage: python peer_driver.py LIB SYSTEM SAMPLES.npy [--budget SECONDS]
  LIB     pyfuzzylite | skfuzzy | simpful
  SYSTEM  tipper | grid49 | gauss343 | grid343 | grid2401 | rules10k
  SAMPLES an (n, inputs) array of inputs; the outputs on its first 300 rows are reported

Reports: build_s (construct the engine / import the FLL), single_s (mean seconds per call of
the single-sample API, best of 3), batch_per_s (the vectorised path where the library has
one, else a loop; extrapolated from a prefix when slow), outputs.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
warnings.simplefilter("ignore")


def _shared_models() -> Any:
    import importlib.util
    import os

    shared = Path(os.environ.get("FUZZYCTL_SHARED", HERE.parent.parent / "shared"))
    spec = importlib.util.spec_from_file_location("peer_models", shared / "bench" / "peers" / "models.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def build(lib: str, system: str) -> tuple[Any, Any]:
    """(single, batch) callables taking one row / an (n, k) array."""
    import systems as S

    models = _shared_models()
    if lib == "pyfuzzylite":
        import fuzzylite as fl

        if system in ("tipper", "grid49"):
            text = models.tipper_fll() if system == "tipper" else models.grid49_fll()
        else:
            text = S.fll(S.SYSTEMS[system])
        engine = fl.FllImporter().from_string(text)
        ins, out = engine.input_variables, engine.output_variables[0]

        def single(row: Any) -> float:
            for v, x in zip(ins, row, strict=True):
                v.value = float(x)
            engine.process()
            return float(out.value)

        def batch(rows: Any) -> Any:
            for k, v in enumerate(ins):
                v.value = rows[:, k]
            engine.process()
            return np.asarray(out.value, dtype=float)

        return single, batch
    if lib == "skfuzzy" and system in ("tipper", "grid49"):
        # one simulation each: after array inputs scikit-fuzzy refuses a single sample
        # ("All antecedents must have input values!")
        s, _b, _ = models.build_skfuzzy(system, out_points=1201)
        _s, b, _ = models.build_skfuzzy(system, out_points=1201)
        return (lambda r: s(float(r[0]), float(r[1]))), (lambda rows: b(rows[:, 0], rows[:, 1]))
    if lib == "simpful" and system in ("tipper", "grid49"):
        s, _b, _ = models.build_simpful(system, subdivisions=1000)
        return (lambda r: s(float(r[0]), float(r[1]))), None
    raise SystemExit(f"{lib} on {system}: not built by this driver")


def measure(single: Any, batch: Any, x: Any, budget: float) -> dict[str, float]:
    for i in range(min(20, len(x))):
        single(x[i])
    t0 = time.perf_counter()
    single(x[0])
    est = max(time.perf_counter() - t0, 1e-7)
    n = int(min(2000, max(5, budget / 3 / est)))
    best = float("inf")
    for r in range(3):
        rows = x[(r * n) % len(x) : (r * n) % len(x) + n]
        t0 = time.perf_counter()
        for row in rows:
            single(row)
        best = min(best, (time.perf_counter() - t0) / max(1, len(rows)))
    out: dict[str, float] = {"single_s": best}
    if batch is not None:
        t0 = time.perf_counter()
        batch(x[:100])
        est = (time.perf_counter() - t0) / 100
        m = int(min(len(x), max(100, budget / est)))
        t0 = time.perf_counter()
        for s in range(0, m, 10_000):
            batch(x[s : min(m, s + 10_000)])
        out["batch_per_s"] = m / (time.perf_counter() - t0)
    else:
        m = int(min(len(x), max(20, budget / best)))
        t0 = time.perf_counter()
        for row in x[:m]:
            single(row)
        out["batch_per_s"] = m / (time.perf_counter() - t0)
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("lib")
    ap.add_argument("system")
    ap.add_argument("samples", type=Path)
    ap.add_argument("--budget", type=float, default=2.0)
    args = ap.parse_args()
    x = np.load(args.samples)
    t0 = time.perf_counter()
    single, batch = build(args.lib, args.system)
    res: dict[str, Any] = {"build_s": time.perf_counter() - t0}
    res.update(measure(single, batch, x, args.budget))
    res["outputs"] = [single(row) for row in x[: min(300, len(x)) if res["single_s"] < 0.01 else 30]]
    print(json.dumps(res))


if __name__ == "__main__":
    main()
