"""Jitter and overruns of the soft controller: N Siemens FUZZY instances (the manual's
FPLTEST controller) at a common period, all bound to the runtime's own Modbus server (so
the I/O loop exchanges 3N FLOAT32 values every poll while the cycles run), while a
Modbus master on loopback writes fresh inputs.  Prints jitter percentiles, execution
times and overruns; checks that every instance cycled and computed the engine's value.

    python benchmarks/runtime_jitter.py                 # 100 instances, 10 ms, 30 s
    python benchmarks/runtime_jitter.py --instances 50 --period 0.005 --seconds 10

No assertion on time: the numbers depend on the machine (and on what else runs on it).
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
FCL = ROOT / "examples" / "siemens_fpltest.fcl"


def config(n: int, period: float, priority: int = 0) -> str:
    lines = [
        "[runtime]",
        f"realtime_priority = {priority}",
        "",
        "[connections.mb]",
        'type = "modbus-server"',
        "port = 0",
        "registers = 2000",
        f"poll_interval = {period}",
        "",
    ]
    for i in range(n):
        base = i * 6
        lines += [
            f"[instances.fb{i:03d}]",
            f'knowledge_base = "{FCL}"',
            f"period = {period}",
            f"[instances.fb{i:03d}.inputs]",
            f'Temp = {{ connection = "mb", address = {base} }}',
            f'Pressure = {{ connection = "mb", address = {base + 2} }}',
            f"[instances.fb{i:03d}.outputs]",
            f'Valve = {{ connection = "mb", address = {base + 4}, safe = 0.0 }}',
            "",
        ]
    return "\n".join(lines)


def percentile(values: list[float], q: float) -> float:
    if not values:
        return math.nan
    s = sorted(values)
    return s[max(0, min(len(s) - 1, math.ceil(q / 100 * len(s)) - 1))]


def run(n: int = 100, period: float = 0.01, seconds: float = 30.0, priority: int = 0) -> dict[str, Any]:
    """Run the runtime for ``seconds`` and return the measurements (seconds) and checks."""
    from pymodbus.client import ModbusTcpClient

    import fuzzyctl
    from fuzzyctl.io.codec import float32_from_registers, float32_to_registers
    from fuzzyctl.runtime import Runtime, parse_config

    engine = fuzzyctl.compile(fuzzyctl.load(FCL))
    rng = np.random.default_rng(7)
    temps = rng.uniform(0, 30, n).astype(np.float32).astype(float)
    pressures = rng.uniform(50, 100, n).astype(np.float32).astype(float)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "bench.toml"
        text = config(n, period, priority)
        path.write_text(text)
        rt = Runtime(parse_config(text, path), api=False, event_log=None)
        rt.start()
        try:
            deadline = time.monotonic() + 10
            while not rt.links["mb"].up and time.monotonic() < deadline:
                time.sleep(0.01)
            master = ModbusTcpClient("127.0.0.1", port=rt.links["mb"].connector.port, timeout=2)
            master.connect()
            for i in range(n):
                regs = [*float32_to_registers(temps[i]), *float32_to_registers(pressures[i])]
                master.write_registers(i * 6, regs)
            start_counts = {name: inst.task.stats.count for name, inst in rt.instances.items()}
            time.sleep(seconds)
            outputs = []
            for i in range(n):
                r = master.read_holding_registers(i * 6 + 4, count=2).registers
                outputs.append(float32_from_registers(r[0], r[1]))
            master.close()
        finally:
            rt.stop()
    jitters: list[float] = []
    durations: list[float] = []
    overruns = skipped = 0
    counts = []
    for name, inst in rt.instances.items():
        stats = inst.task.stats
        _, jit, dur = inst.ring.ordered()  # the last 2000 cycles (20 s at 10 ms)
        jitters += jit
        durations += dur
        overruns += stats.overruns
        skipped += stats.skipped
        counts.append(stats.count - start_counts[name])
    expected = [
        float(np.float32(engine.evaluate({"Temp": t, "Pressure": p})["Valve"]))
        for t, p in zip(temps, pressures, strict=True)
    ]
    wrong = sum(
        not math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-4) for a, b in zip(outputs, expected, strict=True)
    )
    return {
        "instances": n,
        "period": period,
        "seconds": seconds,
        "cycles_total": sum(i.task.stats.count for i in rt.instances.values()),
        "cycles_min_per_instance": min(counts),
        "cycles_expected_per_instance": seconds / period,
        "jitter_p50": percentile(jitters, 50),
        "jitter_p99": percentile(jitters, 99),
        "jitter_p999": percentile(jitters, 99.9),
        "jitter_max": max(jitters) if jitters else math.nan,
        "duration_mean": statistics.fmean(durations) if durations else math.nan,
        "duration_p99": percentile(durations, 99),
        "overruns": overruns,
        "skipped": skipped,
        "outputs_wrong": wrong,
        "cpu_load_cycles": (statistics.fmean(durations) if durations else 0) * n / period,
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--instances", type=int, default=100)
    ap.add_argument("--period", type=float, default=0.01)
    ap.add_argument("--seconds", type=float, default=30.0)
    ap.add_argument("--priority", type=int, default=0, help="SCHED_FIFO priority of the cycle thread")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    r = run(args.instances, args.period, args.seconds, args.priority)
    if args.json:
        print(json.dumps(r))
        return 0
    ms = 1e3
    prio = f", SCHED_FIFO {args.priority}" if args.priority else ""
    print(f"{r['instances']} instances at {r['period'] * ms:g} ms for {r['seconds']:g} s{prio}")
    print(
        f"  jitter  p50 {r['jitter_p50'] * ms:.3f} ms  p99 {r['jitter_p99'] * ms:.3f} ms  "
        f"p99.9 {r['jitter_p999'] * ms:.3f} ms  max {r['jitter_max'] * ms:.3f} ms"
    )
    print(f"  cycle   mean {r['duration_mean'] * ms:.3f} ms  p99 {r['duration_p99'] * ms:.3f} ms")
    print(f"  overruns {r['overruns']}  skipped releases {r['skipped']}  cycles {r['cycles_total']}")
    print(f"  cycle-thread load {r['cpu_load_cycles'] * 100:.1f} % of one core")
    print(f"  outputs different from the engine: {r['outputs_wrong']} of {r['instances']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
