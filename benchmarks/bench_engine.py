"""fuzzyctl's speed, measured in ONE run against pyfuzzylite, scikit-fuzzy, simpful, Debian's
fuzzylite 6 C++ (its ``benchmark`` mode) and a hand-written C loop.

usage: python benchmarks/bench_engine.py [--quick] [--json out.json] [--peers PYTHON] [--only SECTIONS]

Peers run in their own virtual environment (``.venv-peers``: they pin numpy<2, the project
keeps numpy 2) through benchmarks/peer_driver.py; the systems are written for each tool
independently by benchmarks/systems.py (tipper and grid49 are ../shared/bench/peers/models.py's).

1. Peers: single = mean latency of one evaluation through each library's single-sample API
   (fuzzyctl: ``Controller.evaluate(dict)``, inputs checked), best of 3 repeats; batch =
   throughput over up to 100,000 samples through the library's vectorised path (fuzzyctl
   ``evaluate_batch``; pyfuzzylite numpy arrays as input values; scikit-fuzzy array inputs;
   simpful a loop); fuzzylite C++ = ``fuzzylite benchmark`` (its own timing of a loop of
   evaluations); |err| = largest difference from fuzzyctl's exact value on 300 samples.
   Ratios against pyfuzzylite, measured in this run.
2. The hand-written C loop for grid49 (benchmarks/handwritten_grid49.c, -O3) against the
   native backend's ``evaluate_batch`` on the same samples, one thread each, CPU time (the
   whole call: input checks, the C loop, the result arrays).
3. Scaling with the rule count (49, 343, 2,401, 10,000 rules): single evaluation (Python and
   native), batch (numpy and native), compile time cold (parse, lower, C build: empty caches)
   and warm (caches filled), pyfuzzylite's import of the same system; the exponent of single
   time against rule count (least squares on log-log).
4. Cold start: median of 10 runs of ``fuzzyctl eval FILE --set ...`` (caches warm), against
   ``fuzzyctl --help`` and fuzzylite's C++ command line.
5. Peak resident memory of a 10,000,000-row batch (grid49), native and numpy.
6. Per defuzzification method (CoG, CoA, LM, RM, MoM, CoGS, COGF, Takagi-Sugeno) on one
   2-input, 4-rule base: the batch cost per row on one core, native and numpy, the numpy
   path with its hand-written kernels replaced by the native builder's IR printed as numpy
   ("np IR": the row that keeps ir/kernels/columns.py where it is faster), the native batch
   as a multiple of CoG's, and the native single evaluation (``--only methods``).
7. Each hand-written kernel against its IR twin rendered in the same language, Python per
   call and numpy per row (``--only kernels``; benchmarks/bench_kernels.py says how): a
   kernel is kept only where this row shows the rendered IR slower.

The machine's load average is printed at the start and the end: speed ratios measured in the
same run are what counts on a shared machine.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

import fuzzyctl

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
import systems as S  # noqa: E402
from bench_kernels import section_kernels  # noqa: E402

PEERS = ("pyfuzzylite", "skfuzzy", "simpful")
N_BATCH = 100_000


def _ranges(system: str, n_inputs: int) -> list[tuple[float, float]]:
    return [(0.0, 10.0)] * 2 if system == "tipper" else [(-1.0, 1.0)] * n_inputs


def samples(system: str, n: int, n_inputs: int, seed: int = 3) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.uniform(lo, hi, n) for lo, hi in _ranges(system, n_inputs)])


def fcl_path(system: str, work: Path) -> Path:
    if system in ("tipper", "grid49"):
        return HERE / f"{system}.fcl"
    path = work / f"{system}.fcl"
    if not path.exists():
        path.write_text(S.fcl(S.SYSTEMS[system]))
    return path


def fll_text(system: str) -> str:
    if system in ("tipper", "grid49"):
        models = _shared_models()
        return str(models.tipper_fll() if system == "tipper" else models.grid49_fll())
    return S.fll(S.SYSTEMS[system])


def _shared_models() -> Any:
    import importlib.util

    shared = Path(os.environ.get("FUZZYCTL_SHARED", ROOT.parent / "shared"))
    spec = importlib.util.spec_from_file_location("peer_models", shared / "bench" / "peers" / "models.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


# --------------------------------------------------------------------------- fuzzyctl


def latency(fn: Any, rows: np.ndarray, budget: float) -> float:
    for r in rows[:20]:
        fn(r)
    t0 = time.perf_counter()
    fn(rows[0])
    est = max(time.perf_counter() - t0, 1e-7)
    n = int(min(5000, max(10, budget / 3 / est), len(rows) // 3))
    best = float("inf")
    for k in range(3):
        part = rows[k * n : (k + 1) * n]
        t0 = time.perf_counter()
        for r in part:
            fn(r)
        best = min(best, (time.perf_counter() - t0) / len(part))
    return best


def throughput(fn: Any, rows: np.ndarray, budget: float) -> float:
    t0 = time.perf_counter()
    fn(rows[:200])
    est = (time.perf_counter() - t0) / 200
    n = int(min(len(rows), max(200, budget / est)))
    best = 0.0
    for _ in range(2 if n == len(rows) else 1):
        t0 = time.perf_counter()
        fn(rows[:n])
        best = max(best, n / (time.perf_counter() - t0))
    return best


def ours(path: Path, rows: np.ndarray, budget: float) -> dict[str, dict[str, Any]]:
    doc = fuzzyctl.load(path)
    out: dict[str, dict[str, Any]] = {}
    for label, backend in (("fuzzyctl python/numpy", "python"), ("fuzzyctl native", "native")):
        ctl = fuzzyctl.compile(doc, backend=backend)
        names = list(ctl.inputs)
        o = next(iter(ctl.outputs))

        def single(r: np.ndarray, ctl: Any = ctl, names: list[str] = names, o: str = o) -> float:
            return float(ctl.evaluate(dict(zip(names, r.tolist(), strict=True)))[o])

        def batch(x: np.ndarray, ctl: Any = ctl, names: list[str] = names, o: str = o) -> Any:
            return ctl.evaluate_batch({n: x[:, i] for i, n in enumerate(names)})[o]

        out[label] = {
            "single_s": latency(single, rows, budget),
            "batch_per_s": throughput(batch, rows, 5 * budget),
            "outputs": np.asarray(batch(rows[:300]), dtype=float),
            "type": type(ctl).__name__,
        }
    return out


# --------------------------------------------------------------------------- others


def peer(
    python: str, lib: str, system: str, rows: np.ndarray, budget: float, work: Path
) -> dict[str, Any] | None:
    f = work / f"{system}-samples.npy"
    np.save(f, rows)
    cmd = [python, str(HERE / "peer_driver.py"), lib, system, str(f), "--budget", str(budget)]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=3600)
    if res.returncode != 0:
        print(f"  {lib} on {system}: {res.stderr.strip().splitlines()[-1:]}", file=sys.stderr)
        return None
    got: dict[str, Any] = json.loads(res.stdout.strip().splitlines()[-1])
    got["outputs"] = np.asarray(got["outputs"], dtype=float)
    return got


def fuzzylite_cpp(system: str, rows: np.ndarray, work: Path) -> dict[str, Any] | None:
    """``fuzzylite benchmark`` on 1,000 rows, 3 runs: its mean time per run / rows."""
    exe = shutil.which("fuzzylite")
    if exe is None:
        return None
    fll = work / f"{system}.fll"
    fll.write_text(fll_text(system))
    fld = work / f"{system}.fld"
    n = min(1000, len(rows))
    names = [
        ln.split(":", 1)[1].strip() for ln in fll.read_text().splitlines() if ln.startswith("InputVariable:")
    ]
    with fld.open("w") as fh:
        fh.write(" ".join([*names, "u"]) + "\n")
        for r in rows[:n]:
            fh.write(" ".join(repr(float(v)) for v in r) + " 0\n")
    res = subprocess.run(
        [exe, "benchmark", str(fll), str(fld), "3"], capture_output=True, text=True, timeout=3600
    )
    lines = [ln for ln in res.stdout.splitlines() if ln.startswith("fuzzylite")]
    if not lines:
        return None
    cells = lines[-1].split("\t")
    mean_ns = float(cells[18])  # mean(t) of one run of n evaluations
    per = mean_ns * 1e-9 / n
    return {"single_s": per, "batch_per_s": 1.0 / per}


def handwritten(rows: np.ndarray, work: Path) -> tuple[float, np.ndarray] | None:
    cc = shutil.which(os.environ.get("CC", "cc"))
    if cc is None:
        return None
    exe = work / "handwritten_grid49"
    subprocess.run([cc, "-std=c99", "-O3", "-o", str(exe), str(HERE / "handwritten_grid49.c")], check=True)
    inp, outp = work / "hw_in.bin", work / "hw_out.bin"
    np.ascontiguousarray(rows, dtype=np.float64).tofile(inp)
    times = []
    for _ in range(3):
        res = subprocess.run([str(exe), str(inp), str(outp)], capture_output=True, text=True, check=True)
        times.append(float(res.stdout.strip()))
    return min(times) * 1e-9, np.fromfile(outp)


# --------------------------------------------------------------------------- sections


def section_peers(args: argparse.Namespace, work: Path, results: dict[str, Any]) -> None:
    budget = 0.5 if args.quick else 2.0
    table: dict[str, dict[str, dict[str, Any]]] = {}
    for system in ("tipper", "grid49", "gauss343"):
        path = fcl_path(system, work)
        n_in = len(fuzzyctl.compile(fuzzyctl.load(path), backend="interpreted").inputs)
        rows = samples(system, N_BATCH, n_in)
        mine = ours(path, rows, budget)
        exact = mine["fuzzyctl python/numpy"]["outputs"]
        for name, rec in mine.items():
            table.setdefault(name, {})[system] = rec
        for lib in PEERS:
            if args.peers is None or (lib != "pyfuzzylite" and system == "gauss343"):
                continue
            got = peer(args.peers, lib, system, rows, budget, work)
            if got is not None:
                table.setdefault(lib, {})[system] = got
        cpp = fuzzylite_cpp(system, rows, work)
        if cpp is not None:
            table.setdefault("fuzzylite 6 C++", {})[system] = cpp
        for rec in table.values():
            if system in rec and "outputs" in rec[system]:
                k = len(rec[system]["outputs"])
                rec[system]["max_err"] = float(np.max(np.abs(rec[system]["outputs"] - exact[:k])))
    results["peers"] = {
        k: {s: {m: v for m, v in r.items() if m != "outputs"} for s, r in d.items()} for k, d in table.items()
    }
    base = table.get("pyfuzzylite", {})
    print("\n## 1. Against the peers (ratios: x pyfuzzylite)\n")
    head = "| engine |" + "".join(f" {s} single | {s} batch/s |" for s in ("tipper", "grid49", "gauss343"))
    print(head)
    print("|" + "---|" * (head.count("|") - 1))
    for name, per in table.items():
        cells = [name]
        for s in ("tipper", "grid49", "gauss343"):
            rec = per.get(s)
            if rec is None:
                cells += ["-", "-"]
                continue
            b = base.get(s)
            r1 = f" ({b['single_s'] / rec['single_s']:,.1f}x)" if b else ""
            r2 = f" ({rec['batch_per_s'] / b['batch_per_s']:,.1f}x)" if b else ""
            cells += [f"{rec['single_s'] * 1e6:,.1f} us{r1}", f"{rec['batch_per_s']:,.0f}{r2}"]
        print("| " + " | ".join(cells) + " |")
    print("\nmax |error| against fuzzyctl's exact values (300 samples):")
    for name, per in table.items():
        errs = ", ".join(f"{s} {r['max_err']:.1g}" for s, r in per.items() if "max_err" in r)
        if errs:
            print(f"  {name}: {errs}")
    nat, num = table["fuzzyctl native"], table["fuzzyctl python/numpy"]
    print(
        "native batch / numpy batch: "
        + ", ".join(f"{s} {nat[s]['batch_per_s'] / num[s]['batch_per_s']:.1f}x" for s in nat)
    )


def section_handwritten(args: argparse.Namespace, work: Path, results: dict[str, Any]) -> None:
    rows = samples("grid49", 1_000_000, 2, seed=5)
    hw = handwritten(rows, work)
    if hw is None:
        return
    per_hw, out_hw = hw
    from fuzzyctl.engine import native

    ctl = fuzzyctl.compile(fuzzyctl.load(HERE / "grid49.fcl"), backend="native")
    cols = {"e": np.ascontiguousarray(rows[:, 0]), "de": np.ascontiguousarray(rows[:, 1])}
    saved = native.THREAD_ROWS
    native.THREAD_ROWS = 1 << 62  # one thread, as the hand-written loop
    best = float("inf")
    for _ in range(3):  # CPU time, as the hand-written loop measures itself
        t0 = time.process_time()
        got = ctl.evaluate_batch(cols)["u"]
        best = min(best, (time.process_time() - t0) / len(rows))
    native.THREAD_ROWS = saved
    t0 = time.perf_counter()
    ctl.evaluate_batch(cols)
    threaded = (time.perf_counter() - t0) / len(rows)
    err = float(np.max(np.abs(got - out_hw)))
    results["handwritten"] = {
        "hand_ns": per_hw * 1e9,
        "native_ns": best * 1e9,
        "native_threads_ns": threaded * 1e9,
        "max_diff": err,
    }
    print("\n## 2. Hand-written C (grid49, 1,000,000 rows, -O3)\n")
    print(
        f"hand-written loop {per_hw * 1e9:.1f} ns/row; native evaluate_batch {best * 1e9:.1f} ns/row "
        "one thread "
        "(CPU time) "
        f"({best / per_hw:.2f}x the hand-written loop), {threaded * 1e9:.1f} ns/row on all cores; "
        f"largest difference {err:.1g}"
    )


def _subprocess_time(code: str, env: dict[str, str]) -> float:
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    return float(res.stdout.strip().splitlines()[-1])


def section_scaling(args: argparse.Namespace, work: Path, results: dict[str, Any]) -> None:
    budget = 0.5 if args.quick else 1.5
    rows_out: list[dict[str, Any]] = []
    for system in ("grid49", "grid343", "grid2401", "rules10k"):
        path = fcl_path(system, work)
        cache = work / f"cache-{system}"
        env = dict(os.environ, FUZZYCTL_CACHE_DIR=str(cache), FUZZYCTL_QUIET="1")
        env.pop("FUZZYCTL_BACKEND", None)
        code = (
            "import time; t=time.perf_counter(); import fuzzyctl; "
            f"c=fuzzyctl.compile(fuzzyctl.load({str(path)!r})); "
            "assert type(c).__name__ == 'NativeController'; print(time.perf_counter()-t)"
        )
        cold = _subprocess_time(code, env)
        warm = _subprocess_time(code, env)
        doc = fuzzyctl.load(path)
        n_rules = len(fuzzyctl.compile(doc, backend="interpreted").plan.rules)
        py = fuzzyctl.compile(doc, backend="python")
        nat = fuzzyctl.compile(doc, backend="native")
        names = list(py.inputs)
        x = samples(system, 20_000, len(names))
        rec: dict[str, Any] = {
            "system": system,
            "rules": n_rules,
            "compile_cold_s": cold,
            "load_compile_warm_s": warm,
        }
        for label, ctl in (("python", py), ("native", nat)):
            names = list(ctl.inputs)
            rec[f"single_{label}_s"] = latency(
                lambda r, c=ctl, names=names: c.evaluate(dict(zip(names, r.tolist(), strict=True))), x, budget
            )
            rec[f"batch_{'numpy' if label == 'python' else label}_per_s"] = throughput(
                lambda a, c=ctl, names=names: c.evaluate_batch({n: a[:, i] for i, n in enumerate(names)}),
                x,
                3 * budget,
            )
        if args.peers is not None:
            got = peer(
                args.peers, "pyfuzzylite", system, x[:200], 0.3 if system == "rules10k" else budget, work
            )
            if got is not None:
                rec["pyfuzzylite_import_s"] = got["build_s"]
                rec["pyfuzzylite_single_s"] = got["single_s"]
        rows_out.append(rec)
    results["scaling"] = rows_out
    print("\n## 3. Scaling with the rule count\n")
    print(
        "| system | rules | single python | single native | batch numpy/s | batch native/s "
        "| compile cold (parse, lower, C) | load+compile warm | pyfuzzylite import | pyfuzzylite single |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows_out:
        print(
            f"| {r['system']} | {r['rules']:,} | {r['single_python_s'] * 1e6:,.1f} us "
            f"| {r['single_native_s'] * 1e6:,.1f} us | "
            f"{r['batch_numpy_per_s']:,.0f} | {r['batch_native_per_s']:,.0f} | {r['compile_cold_s']:.2f} s | "
            f"{r['load_compile_warm_s']:.3f} s | {r.get('pyfuzzylite_import_s', math.nan):.2f} s | "
            f"{r.get('pyfuzzylite_single_s', math.nan) * 1e3:,.2f} ms |"
        )
    lr = np.log([r["rules"] for r in rows_out])
    for label in ("python", "native"):
        slope = float(np.polyfit(lr, np.log([r[f"single_{label}_s"] for r in rows_out]), 1)[0])
        results[f"exponent_{label}"] = slope
        print(f"single evaluation time ~ rules^{slope:.2f} ({label})")


def section_cold_start(args: argparse.Namespace, work: Path, results: dict[str, Any]) -> None:
    exe = shutil.which("fuzzyctl") or str(Path(sys.executable).parent / "fuzzyctl")
    env = dict(os.environ, FUZZYCTL_CACHE_DIR=str(work / "cache-cli"))
    env.pop("FUZZYCTL_BACKEND", None)

    def median(cmd: list[str]) -> float:
        subprocess.run(cmd, capture_output=True, env=env)  # fill the caches
        times = []
        for _ in range(10):
            t0 = time.perf_counter()
            subprocess.run(cmd, capture_output=True, env=env, check=False)
            times.append(time.perf_counter() - t0)
        return statistics.median(times)

    out = {
        "eval grid49": median(
            [exe, "eval", str(fcl_path("grid49", work)), "--set", "e=0.1", "--set", "de=0.2"]
        ),
        "eval grid2401": median(
            [
                exe,
                "eval",
                str(fcl_path("grid2401", work)),
                *[a for k in range(1, 5) for a in ("--set", f"x{k}=0.1")],
            ]
        ),
        "--help": median([exe, "--help"]),
        "python -c pass": median([sys.executable, "-c", "pass"]),
    }
    cpp = shutil.which("fuzzylite")
    if cpp is not None:
        fll = work / "grid49.fll"
        fll.write_text(fll_text("grid49"))
        fld = work / "one.fld"
        fld.write_text("e de\n0.1 0.2\n")
        out["fuzzylite C++ (one row)"] = median(
            [cpp, "-i", str(fll), "-of", "fld", "-d", str(fld), "-o", str(work / "o.fld")]
        )
    results["cold_start"] = out
    print("\n## 4. Cold start (median of 10 runs, caches warm)\n")
    for k, v in out.items():
        print(f"  {k}: {v * 1e3:.0f} ms")


def section_memory(args: argparse.Namespace, work: Path, results: dict[str, Any]) -> None:
    n = 1_000_000 if args.quick else 10_000_000
    out = {}
    for backend in ("native", "python"):
        code = (
            "import resource, numpy as np, fuzzyctl; "
            f"c = fuzzyctl.compile(fuzzyctl.load({str(HERE / 'grid49.fcl')!r}), backend={backend!r}); "
            "rng = np.random.default_rng(0); "
            f"x = {{'e': rng.uniform(-1, 1, {n}), 'de': rng.uniform(-1, 1, {n})}}; "
            "base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss; "
            "y = c.evaluate_batch(x); "
            "print(base, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)"
        )
        res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
        before, after = (int(v) for v in res.stdout.split())
        out[backend] = {"peak_mb": after / 1024, "inputs_mb": before / 1024}
    results["memory"] = {"rows": n, **out}
    print(
        f"\n## 5. Peak resident memory of a {n:,}-row batch (grid49; inputs {2 * n * 8 / 2**20:,.0f} MB, "
        f"output {n * 8 / 2**20:,.0f} MB)\n"
    )
    for k, v in out.items():
        print(f"  {k}: peak {v['peak_mb']:,.0f} MB (with the inputs in memory: {v['inputs_mb']:,.0f} MB)")


# --------------------------------------------------------------------------- methods

METHODS_FCL = """
FUNCTION_BLOCK methods
VAR_INPUT a : REAL; b : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY a RANGE := (0 .. 10); TERM lo := (0, 1) (10, 0); TERM hi := (0, 0) (10, 1); END_FUZZIFY
FUZZIFY b RANGE := (0 .. 10); TERM lo := (0, 1) (10, 0); TERM hi := (0, 0) (10, 1); END_FUZZIFY
DEFUZZIFY y RANGE := (0 .. 10); {terms} METHOD : {method}; DEFAULT := 0; END_DEFUZZIFY
RULEBLOCK r AND : MIN; ACT : {act}; ACCU : MAX;
RULE 1 : IF a IS lo AND b IS lo THEN y IS s;
RULE 2 : IF a IS hi AND b IS lo THEN y IS m;
RULE 3 : IF a IS lo AND b IS hi THEN y IS m;
RULE 4 : IF a IS hi AND b IS hi THEN y IS l;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""
_SETS = "TERM s := (0,0) (2,1) (4,0); TERM m := (3,0) (5,1) (7,0); TERM l := (6,0) (8,1) (10,0);"
_POINTS = "TERM s := 2; TERM m := 5; TERM l := 8;"
_LINEAR = "TERM s := 2; TERM m := LINEAR 0.25 0.25 2; TERM l := LINEAR 0.5 0.25 1;"
#: (row label, METHOD, terms, ACT): one rule base, every method (section 6)
METHOD_ROWS = (
    ("COG", "COG", _SETS, "MIN"),
    ("COA", "COA", _SETS, "MIN"),
    ("LM", "LM", _SETS, "MIN"),
    ("RM", "RM", _SETS, "MIN"),
    ("MoM", "MOM", _SETS, "MIN"),
    ("COGS", "COGS", _POINTS, "MIN"),
    ("COGF", "COGF", _POINTS, "MIN"),
    ("TS", "WTAVER", _LINEAR, "PROD"),
)


def _cpu_batch(ctl: Any, cols: dict[str, np.ndarray], repeats: int) -> float:
    """Best CPU time per row of one batch (below the threading threshold: one core)."""
    n = len(next(iter(cols.values())))
    ctl.evaluate_batch({k: v[:10] for k, v in cols.items()})
    best = float("inf")
    for _ in range(repeats):
        t0 = time.process_time()
        ctl.evaluate_batch(cols)
        best = min(best, time.process_time() - t0)
    return best / n


def _numpy_ir(ctl: Any, cols: dict[str, np.ndarray], repeats: int) -> float:
    """CPU time per row of the native builder's output IR printed as numpy (what replacing
    the hand-written kernels of ir/kernels/columns.py with rendered IR would cost)."""
    from fuzzyctl.ir.programs.native import NativeBuilder
    from fuzzyctl.ir.render.npsrc import vectorise

    fn = vectorise(NativeBuilder(ctl.plan, "np").build())
    columns = [cols[name] for name in ctl.inputs]
    n = len(columns[0])
    best = float("inf")
    for _ in range(repeats):
        t0 = time.process_time()
        fn(columns, [0.0] * len(ctl.plan.outputs), n)
        best = min(best, time.process_time() - t0)
    return best / n


def section_methods(args: argparse.Namespace, work: Path, results: dict[str, Any]) -> None:
    """6. Per method on one 2-input, 4-rule base: batch cost (ns/row, one core) native and
    numpy, and single evaluation (us) native; the native batch as a multiple of CoG's."""
    n = 50_000 if args.quick else 100_000
    repeats = 3 if args.quick else 7
    rng = np.random.default_rng(5)
    cols = {"a": rng.uniform(0, 10, n), "b": rng.uniform(0, 10, n)}
    rows = np.column_stack([cols["a"], cols["b"]])
    print("\n6. methods: one 2-input, 4-rule base per method; batch ns/row (one core), single us")
    print(f"{'method':8s} {'native':>8s} {'numpy':>8s} {'np IR':>8s} {'x CoG':>6s} {'single':>8s}")
    out: dict[str, Any] = {}
    for label, method, terms, act in METHOD_ROWS:
        doc = fuzzyctl.load(METHODS_FCL.format(terms=terms, method=method, act=act))
        nat = fuzzyctl.compile(doc, backend="native")
        npy = fuzzyctl.compile(doc, backend="python")
        native_ns = _cpu_batch(nat, cols, repeats) * 1e9
        numpy_ns = _cpu_batch(npy, cols, repeats) * 1e9
        ir_ns = _numpy_ir(npy, cols, repeats) * 1e9

        def single(r: np.ndarray, ctl: Any = nat) -> float:
            return float(ctl.evaluate({"a": float(r[0]), "b": float(r[1])})["y"])

        single_us = latency(single, rows, 0.3 if args.quick else 1.0) * 1e6
        out[label] = {
            "numpy_ir_ns": ir_ns,
            "native_ns": native_ns,
            "numpy_ns": numpy_ns,
            "single_us": single_us,
            "type": type(nat).__name__,
        }
        ratio = native_ns / out["COG"]["native_ns"]
        print(
            f"{label:8s} {native_ns:8.0f} {numpy_ns:8.0f} {ir_ns:8.0f} {ratio:6.2f} {single_us:8.2f}"
            + ("" if type(nat).__name__ == "NativeController" else "  (not native)")
        )
    results["methods"] = out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="smaller budgets (rougher numbers)")
    ap.add_argument("--json", type=Path, help="also write the numbers as JSON")
    default_peers = ROOT / ".venv-peers" / "bin" / "python"
    ap.add_argument(
        "--peers",
        default=str(default_peers) if default_peers.exists() else None,
        help="python of the peers' virtual environment (default: .venv-peers)",
    )
    ap.add_argument(
        "--only", help="comma-separated sections: peers,handwritten,scaling,cold,memory,methods,kernels"
    )
    args = ap.parse_args()
    if args.peers is None:
        print("no .venv-peers: peers skipped (make .venv-peers)", file=sys.stderr)
    load0 = os.getloadavg()
    print(
        f"python {platform.python_version()} on {platform.machine()}, {os.cpu_count()} cores; "
        f"numpy {np.__version__}; "
        f"load average {load0[0]:.1f} {load0[1]:.1f} {load0[2]:.1f}"
    )
    results: dict[str, Any] = {"load_start": load0}
    sections = {
        "peers": section_peers,
        "handwritten": section_handwritten,
        "scaling": section_scaling,
        "cold": section_cold_start,
        "memory": section_memory,
        "methods": section_methods,
        "kernels": section_kernels,
    }
    wanted = args.only.split(",") if args.only else list(sections)
    with tempfile.TemporaryDirectory(prefix="fuzzyctl-bench-") as tmp:
        for name in wanted:
            sections[name](args, Path(tmp), results)
    load1 = os.getloadavg()
    results["load_end"] = load1
    print(f"\nload average at the end {load1[0]:.1f} {load1[1]:.1f} {load1[2]:.1f}")
    if args.json:
        args.json.write_text(json.dumps(results, indent=1, default=float))


if __name__ == "__main__":
    main()
