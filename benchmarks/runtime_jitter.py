"""Jitter and overruns of the soft controller: N Siemens FUZZY instances (the manual's
FPLTEST controller) at a common period, all bound to the runtime's own Modbus server (so
the I/O loop exchanges 3N FLOAT32 values every poll while the cycles run), while a
Modbus master on loopback writes fresh inputs.  Prints jitter percentiles, execution
times and overruns; checks that every instance cycled and computed the engine's value.

    python benchmarks/runtime_jitter.py                 # 100 instances, 10 ms, 30 s
    python benchmarks/runtime_jitter.py --instances 50 --period 0.005 --seconds 10
    python benchmarks/runtime_jitter.py --priority 50 --abuse anonymous   # 500 MB PUTs meanwhile
    python benchmarks/runtime_jitter.py --table 50,100,200 --seconds 20   # docs/runtime.md's table
    python benchmarks/runtime_jitter.py --floor --priority 50 --seconds 10 # the machine alone

No assertion on time: the numbers depend on the machine (and on what else runs on it).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
FCL = ROOT / "examples" / "siemens_fpltest.fcl"


def config(n: int, period: float, priority: int = 0, api_state: Path | None = None) -> str:
    lines = [
        "[runtime]",
        f"realtime_priority = {priority}",
    ]
    if api_state is not None:
        lines += [f'state_dir = "{api_state}"', "[api]", "port = 0"]
    lines += [
        "",
        "[connections.mb]",
        'type = "modbus-server"',
        "port = 0",
        # 6 registers an instance: more than 333 instances need more than the default 2000
        f"registers = {max(2000, 6 * n)}",
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


def _thread_cpu(thread: Any) -> float:
    """CPU seconds a thread has used (Linux: its CPU-time clock); NaN when unknown."""
    try:
        return time.clock_gettime(time.pthread_getcpuclockid(thread.ident))
    except (AttributeError, OSError, TypeError):
        return math.nan


def _counts(inst: Any) -> tuple[int, int, int]:
    stats = inst.task.stats
    return stats.count, stats.overruns, stats.skipped


def _start_abuse(url: str, seconds: float, token: str | None) -> subprocess.Popen[str]:
    """The abusive client in its own process (its work must not count as ours)."""
    cmd = [sys.executable, str(ROOT / "benchmarks" / "http_abuse.py"), url, "--mb", "500"]
    cmd += ["--seconds", str(seconds)] + (["--token", token] if token else [])
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, text=True)


def run(
    n: int = 100,
    period: float = 0.01,
    seconds: float = 30.0,
    priority: int = 0,
    abuse: str | None = None,
) -> dict[str, Any]:
    """Run the runtime for ``seconds`` and return the measurements (seconds) and checks.

    ``abuse``: None, or ``"anonymous"`` / ``"token"``: the API is served and
    benchmarks/http_abuse.py sends 500 MB PUTs (Content-Length and chunked) to it, without
    or with the token, for the whole measurement."""
    from pymodbus.client import ModbusTcpClient

    import fuzzyctl
    from fuzzyctl.io.codec import float32_from_registers, float32_to_registers
    from fuzzyctl.runtime import Runtime, parse_config

    engine = fuzzyctl.compile(fuzzyctl.load(FCL))
    rng = np.random.default_rng(7)
    temps = rng.uniform(0, 30, n).astype(np.float32).astype(float)
    pressures = rng.uniform(50, 100, n).astype(np.float32).astype(float)
    abuse_report: list[dict[str, Any]] = []
    load_before = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "bench.toml"
        text = config(n, period, priority, api_state=Path(tmp) if abuse else None)
        path.write_text(text)
        rt = Runtime(parse_config(text, path), api=bool(abuse), event_log=None)
        rt.start()
        abuser = None
        try:
            deadline = time.monotonic() + 10
            while not rt.links["mb"].up and time.monotonic() < deadline:
                time.sleep(0.01)
            master = ModbusTcpClient("127.0.0.1", port=rt.links["mb"].connector.port, timeout=2)
            master.connect()
            for i in range(n):
                regs = [*float32_to_registers(temps[i]), *float32_to_registers(pressures[i])]
                master.write_registers(i * 6, regs)
            # Counted over the measurement only (start-up has its own hiccups).
            start_counts = {name: _counts(inst) for name, inst in rt.instances.items()}
            thread, io_thread = rt.scheduler._thread, rt._io_thread
            cpu0, io0, wall0 = _thread_cpu(thread), _thread_cpu(io_thread), time.perf_counter()
            if abuse and rt.api_address is not None:
                host, port = rt.api_address
                url = f"http://{host}:{port}/api/v1/instances/fb000/knowledge_base"
                abuser = _start_abuse(url, seconds, rt.token if abuse == "token" else None)
            time.sleep(seconds)
            cpu1, io1, wall1 = _thread_cpu(thread), _thread_cpu(io_thread), time.perf_counter()
            end_counts = {name: _counts(inst) for name, inst in rt.instances.items()}
            outputs = []
            for i in range(n):
                r = master.read_holding_registers(i * 6 + 4, count=2).registers
                outputs.append(float32_from_registers(r[0], r[1]))
            master.close()
            link_failures = rt.links["mb"].counters.failures
        finally:
            if abuser is not None:
                try:
                    out, _ = abuser.communicate(timeout=120)
                except subprocess.TimeoutExpired:
                    abuser.kill()
                    out, _ = abuser.communicate()
                abuse_report = [json.loads(line) for line in out.splitlines() if line.startswith("{")]
            rt.stop()
    load_after = os.getloadavg()
    jitters: list[float] = []
    durations: list[float] = []
    overruns = skipped = 0
    counts = []
    for name, inst in rt.instances.items():
        starts, jit, dur = inst.ring.ordered()  # the last 2000 cycles (20 s at 10 ms)
        kept = [i for i, t in enumerate(starts) if wall0 <= t <= wall1]  # those of the measurement
        jitters += [jit[i] for i in kept]
        durations += [dur[i] for i in kept]
        (c0, o0, s0), (c1, o1, s1) = start_counts[name], end_counts[name]
        overruns += o1 - o0
        skipped += s1 - s0
        counts.append(c1 - c0)
    expected = [
        float(np.float32(engine.evaluate({"Temp": t, "Pressure": p})["Valve"]))
        for t, p in zip(temps, pressures, strict=True)
    ]
    wrong = sum(
        not math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-4) for a, b in zip(outputs, expected, strict=True)
    )
    wall = wall1 - wall0
    return {
        "instances": n,
        "period": period,
        "seconds": seconds,
        "priority": priority,
        "abuse": abuse,
        "cycles_total": sum(counts),
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
        # The cycle thread's own CPU time over the measurement, as a fraction of one core
        # (what the cycles cost; wall-clock durations would also count preemptions).
        "cpu_load_cycles": (cpu1 - cpu0) / wall if wall > 0 else math.nan,
        "cpu_load_io": (io1 - io0) / wall if wall > 0 else math.nan,
        # Releases the cycles ran per second against the releases due.
        "cycles_per_second": sum(counts) / wall if wall > 0 else math.nan,
        "cycles_per_second_due": n / period,
        "loadavg_before": load_before[0],
        "loadavg_after": load_after[0],
        "link_failures": link_failures,
        "abuse_requests": abuse_report,
    }


def floor(seconds: float, priority: int, step: float = 0.001) -> dict[str, Any]:
    """What the machine gives any thread: a bare thread (no interpreter lock shared with
    anything) waking every ``step`` at ``priority`` (SCHED_FIFO; 0 normal).  The runtime's
    jitter cannot be better than this, whatever it does."""
    if priority:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
    late: list[float] = []
    due = time.perf_counter()
    end = due + seconds
    while due < end:
        due += step
        wait = due - time.perf_counter()
        if wait > 0:
            time.sleep(wait)
        late.append(time.perf_counter() - due)
    return {
        "floor_p50": percentile(late, 50),
        "floor_p99": percentile(late, 99),
        "floor_max": max(late),
        "priority": priority,
        "loadavg": os.getloadavg()[0],
    }


def report(r: dict[str, Any]) -> str:
    ms = 1e3
    prio = f", SCHED_FIFO {r['priority']}" if r["priority"] else ", normal priority"
    abuse = f", abused ({r['abuse']})" if r["abuse"] else ""
    lines = [
        f"{r['instances']} instances at {r['period'] * ms:g} ms for {r['seconds']:g} s{prio}{abuse}",
        f"  jitter  p50 {r['jitter_p50'] * ms:.3f} ms  p99 {r['jitter_p99'] * ms:.3f} ms  "
        f"p99.9 {r['jitter_p999'] * ms:.3f} ms  max {r['jitter_max'] * ms:.3f} ms",
        f"  cycle   mean {r['duration_mean'] * ms:.3f} ms  p99 {r['duration_p99'] * ms:.3f} ms",
        f"  overruns {r['overruns']}  skipped releases {r['skipped']}  cycles {r['cycles_total']}"
        f"  ({r['cycles_per_second']:.0f}/s of {r['cycles_per_second_due']:.0f}/s due)",
        f"  cycle thread CPU {r['cpu_load_cycles'] * 100:.1f} % of one core,"
        f" I/O thread {r['cpu_load_io'] * 100:.1f} %;"
        f" load average {r['loadavg_before']:.2f} -> {r['loadavg_after']:.2f}",
        f"  outputs different from the engine: {r['outputs_wrong']} of {r['instances']};"
        f" Modbus link failures {r['link_failures']}",
    ]
    for a in r["abuse_requests"]:
        lines.append(
            f"  abuse: {a['mode']:<14} {a['megabytes']} MB, token {a['token']}: sent {a['sent_mb']} MB,"
            f" answer {a['status']!r} after {a['seconds']} s"
        )
    return "\n".join(lines)


def table(instances: list[int], period: float, seconds: float, priority: int) -> int:
    """Each configuration in a fresh process, normal priority and SCHED_FIFO: a Markdown
    table for docs/runtime.md."""
    rows = []
    for prio in (0, priority):
        for n in instances:
            # The machine's own floor just before, in a process of its own (10 s).
            cmd = [sys.executable, __file__, "--floor", "--seconds", "10", "--priority", str(prio)]
            bare = json.loads(subprocess.run(cmd, capture_output=True, text=True, check=True).stdout)
            cmd = [sys.executable, __file__, "--instances", str(n), "--period", str(period)]
            cmd += ["--seconds", str(seconds), "--priority", str(prio), "--json"]
            out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
            r = json.loads(out.strip().splitlines()[-1]) | bare
            print(report(r), file=sys.stderr, flush=True)
            rows.append(r)
    ms = 1e3
    print(
        "| instances | priority | load avg | jitter p50 | p99 | p99.9 | max | overruns | skipped "
        "| cycles run / due | cycle thread CPU | outputs right | bare thread p99 / max |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(
            f"| {r['instances']} | {'FIFO ' + str(r['priority']) if r['priority'] else 'normal'} "
            f"| {r['loadavg_before']:.1f} | {r['jitter_p50'] * ms:.3f} ms "
            f"| **{r['jitter_p99'] * ms:.3f} ms** "
            f"| {r['jitter_p999'] * ms:.3f} ms | {r['jitter_max'] * ms:.3f} ms | **{r['overruns']}** "
            f"| {r['skipped']} | {r['cycles_per_second'] / r['cycles_per_second_due'] * 100:.1f} % "
            f"| {r['cpu_load_cycles'] * 100:.0f} % | {r['instances'] - r['outputs_wrong']}/{r['instances']} "
            f"| {r['floor_p99'] * ms:.3f} / {r['floor_max'] * ms:.1f} ms |"
        )
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--instances", type=int, default=100)
    ap.add_argument("--period", type=float, default=0.01)
    ap.add_argument("--seconds", type=float, default=30.0)
    ap.add_argument("--priority", type=int, default=0, help="SCHED_FIFO priority of the cycle thread")
    ap.add_argument(
        "--abuse",
        choices=["anonymous", "token"],
        default=None,
        help="serve the API and send it 500 MB PUTs from another process, without / with the token",
    )
    ap.add_argument(
        "--table",
        type=lambda s: [int(x) for x in s.split(",")],
        default=None,
        metavar="N,N,..",
        help="run these instance counts at normal priority and at --priority (default 50), print a table",
    )
    ap.add_argument("--floor", action="store_true", help="only the machine's floor: a bare thread's lateness")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    if args.floor:
        print(json.dumps(floor(args.seconds, args.priority)))
        return 0
    if args.table:
        return table(args.table, args.period, args.seconds, args.priority or 50)
    r = run(args.instances, args.period, args.seconds, args.priority, args.abuse)
    print(json.dumps(r) if args.json else report(r))
    return 0


if __name__ == "__main__":
    sys.exit(main())
