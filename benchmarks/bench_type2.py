"""Interval type-2 against type-1 on the same rule base: batch cost per row (ns/row, one
call over the batch, one thread) of the native backend and of the numpy path, and of the
type-2 Python engine's exact centroid (one row at a time) for scale.

The type-1 system is the type-2 one with each term's upper function
(``fuzzyctl convert --type1``); the type-2 IR program samples each Mamdani output at
``--samples`` points (default 101, MATLAB's OutputSampleNumber; 1001 too with ``--both``).

usage: python benchmarks/bench_type2.py [FILE ...] [--rows N] [--samples N] [--both]
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

import fuzzyctl
from fuzzyctl.formats.common.type2 import drop_type2

ROOT = Path(__file__).resolve().parent.parent
FILES = [ROOT / "examples" / "tipper_type2.fis"]


def _per_row(fn: object, data: dict[str, np.ndarray], repeats: int = 3) -> float:
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn(data)  # type: ignore[operator]
        best = min(best, time.perf_counter() - t0)
    return best / len(next(iter(data.values()))) * 1e9


def _row(label: str, t1: float, t2: float) -> str:
    return f"| {label} | {t1:,.0f} | {t2:,.0f} | {t2 / t1:.1f}x |"


def bench(path: Path, rows: int, samples: int) -> list[str]:
    os.environ.setdefault("FUZZYCTL_QUIET", "1")
    doc = fuzzyctl.load(path)
    type1, _ = drop_type2(doc, "type-1")
    rng = np.random.default_rng(1)
    fb = doc.main
    data: dict[str, np.ndarray] = {}
    for f in fb.fuzzify:
        lo, hi = (f.range.low, f.range.high) if f.range else (0.0, 1.0)
        data[f.variable] = rng.uniform(lo, hi, rows)
    out = [f"{path.name}, {rows:,} rows, type-2 Mamdani outputs sampled at {samples} points", ""]
    out += ["| path | type-1 ns/row | type-2 ns/row | type-2 / type-1 |", "|---|---|---|---|"]
    for backend, label in (("native", "native"), ("python", "numpy")):
        c1 = fuzzyctl.compile(type1, backend=backend)
        c2 = fuzzyctl.compile(doc, backend=backend, samples=samples)
        c1.evaluate_batch(data)
        c2.evaluate_batch(data)
        t1 = _per_row(lambda d, c=c1: c.evaluate_batch(d, out_of_range="ignore"), data)
        t2 = _per_row(lambda d, c=c2: c.evaluate_batch(d, out_of_range="ignore"), data)
        out.append(_row(label, t1, t2))
    exact = fuzzyctl.compile(doc, backend="python")
    few = {k: v[: max(1, rows // 100)] for k, v in data.items()}
    te = _per_row(lambda d: exact.evaluate_batch(d, out_of_range="ignore"), few, 1)
    out.append(f"\ntype-2 Python engine, exact centroid, a row at a time: {te:,.0f} ns/row")
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("files", nargs="*", type=Path, default=FILES)
    ap.add_argument("--rows", type=int, default=100_000)
    ap.add_argument("--samples", type=int, default=101)
    ap.add_argument("--both", action="store_true", help="also 1001 samples")
    args = ap.parse_args()
    print(f"load average: {os.getloadavg()[0]:.2f}")
    for path in args.files:
        for n in (args.samples, 1001) if args.both else (args.samples,):
            print("\n".join(bench(path, args.rows, n)))
            print()
    print(f"load average: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
