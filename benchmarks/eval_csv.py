"""Wall time and peak memory of ``fuzzyctl eval --data`` on a large CSV (issue 13: a 1M-row
CSV in under 3 s and 250 MB).

Writes a CSV of N rows (a timestamp column that passes through, and figure 7's two inputs),
then runs the command in a fresh process R times (median wall time, peak RSS of the child)
and checks the output's row count.  Prints the load average: on a shared machine the wall
time moves with it, the peak memory does not.

    python benchmarks/eval_csv.py [--rows 1000000] [--repeat 3] [--to csv|parquet]
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent


def write_csv(path: Path, rows: int) -> None:
    rng = np.random.default_rng(1)
    temp = rng.uniform(0, 30, rows)
    pressure = rng.uniform(0, 100, rows)
    start = np.datetime64("2026-01-01T00:00:00")
    stamps = (start + np.arange(rows) * np.timedelta64(100, "ms")).astype(str)
    with path.open("w") as out:
        out.write("time,temp,pressure\n")
        for chunk in range(0, rows, 100_000):
            block = zip(
                stamps[chunk : chunk + 100_000],
                temp[chunk : chunk + 100_000],
                pressure[chunk : chunk + 100_000],
                strict=True,
            )
            out.write("".join(f"{s},{t:.4f},{p:.4f}\n" for s, t, p in block))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--rows", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--to", choices=("csv", "parquet"), default="csv")
    args = ap.parse_args()
    fuzzyctl = Path(sys.executable).parent / "fuzzyctl"
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "log.csv"
        write_csv(src, args.rows)
        out = Path(tmp) / f"out.{args.to}"
        command = [
            str(fuzzyctl),
            "eval",
            str(ROOT / "examples" / "figure7.fcl"),
            "--data",
            str(src),
            "-o",
            str(out),
        ]
        times = []
        for _ in range(args.repeat):
            start = time.perf_counter()
            subprocess.run(command, check=True)
            times.append(time.perf_counter() - start)
        peak_mb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
        if args.to == "csv":
            with out.open() as fh:
                lines = sum(1 for _ in fh)
            assert lines == args.rows + 1, lines
        size = src.stat().st_size / 1e6
    load = os.getloadavg()[0]
    median = statistics.median(times)
    print(
        f"eval --data: {args.rows:,} rows ({size:.0f} MB CSV) -> {args.to}: median {median:.2f} s "
        f"(min {min(times):.2f} s) wall, peak RSS {peak_mb:.0f} MB; "
        f"load average {load:.1f} on {os.cpu_count()} cores"
    )


if __name__ == "__main__":
    main()
