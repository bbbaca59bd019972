"""Loading large systems: fuzzyctl's load + compile against pyfuzzylite's import of the same
system (issue 17.5), and large inputs accepted or refused (issue 14.4), in one run.

1. grid2401 and rules10k (benchmarks/systems.py): a fresh process with an empty cache runs
   ``fuzzyctl.compile(fuzzyctl.load(FCL), backend=...)`` for the python and the native
   backend, first with empty caches, then again in a new process with the caches the first
   left (document, plan, native library); pyfuzzylite (``.venv-peers``) imports the same
   system written as FLL (``FllImporter().from_string``) in a fresh process.  CPU seconds of
   the work, the C compiler's included (imports excluded where said: each child times its
   own calls) and the ratio to pyfuzzylite.
2. Large inputs: FCL files just under the FCL size limit (a valid rule base, an error on every
   rule, garbage, all on one line), the 10,000-rule FLL and FIS files, and the fuzzer's
   robot.fcl with a TERM line repeated 5000 times (tests/fuzz/campaign.py mutant #16 of the
   suite's seed: load, compile, evaluate, convert, codegen, CLI); CPU seconds and peak RSS
   of a fresh process each.

``--src DIR`` runs the fuzzyctl children on another source tree (e.g. main's ``src``) to
compare before and after in the same run.  Figures only: nothing is asserted.

usage: python benchmarks/load_speed.py [--src DIR] [--peers PYTHON] [--skip-large]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
import large_inputs as L  # noqa: E402
import systems as S  # noqa: E402

_FUZZYCTL = """
import json, resource, sys, time
path, backend = sys.argv[1], sys.argv[2]
import fuzzyctl
from fuzzyctl.diagnostics import DiagnosticError
if sys.argv[3:] == ["preload"]:  # what pyfuzzylite's figure leaves out: imports, parser tables
    import numpy, fuzzyctl.engine.compile, fuzzyctl.fcl.parser
    fuzzyctl.fcl.parser._parser()
t = time.process_time()
status = "ok"
try:
    doc = fuzzyctl.load(path)
    if backend != "none":
        fuzzyctl.compile(doc, backend=backend)
except DiagnosticError as exc:
    status = f"refused ({len(exc.diagnostics)} diagnostic(s))"
cpu = time.process_time() - t
cc = resource.getrusage(resource.RUSAGE_CHILDREN)  # the C compiler of the native backend
rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps({"cpu": cpu + cc.ru_utime + cc.ru_stime, "rss": rss, "status": status}))
"""

_PYFUZZYLITE = """
import json, sys, time
import fuzzylite as fl
text = open(sys.argv[1]).read()
t = time.process_time()
fl.FllImporter().from_string(text)
print(json.dumps({"cpu": time.process_time() - t}))
"""

_MUTANT = """
import json, resource, sys, tempfile, time
from pathlib import Path
sys.path.insert(0, sys.argv[1])
from tests.fuzz.campaign import mutants, run_one, seeds
m = next(m for m in mutants(seeds(), 17, 20261202) if m.index == 16)
import fuzzyctl
t = time.process_time()
with tempfile.TemporaryDirectory() as d:
    out = run_one(m, Path(d))
cpu = time.process_time() - t
rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps({"cpu": cpu, "rss": rss, "status": f"{out.kind}: {' + '.join(m.ops)}"}))
"""


def child(python: str, code: str, args: list[str], env: dict[str, str], timeout: float) -> dict[str, Any]:
    try:
        res = subprocess.run(
            [python, "-c", code, *args], capture_output=True, text=True, env=env, timeout=timeout
        )
    except subprocess.TimeoutExpired:
        return {"cpu": float("nan"), "rss": float("nan"), "status": f"over {timeout:.0f} s"}
    lines = res.stdout.strip().splitlines()
    if res.returncode != 0 or not lines:
        failed = f"exit {res.returncode}: {res.stderr[-300:]}"
        return {"cpu": float("nan"), "rss": float("nan"), "status": failed}
    out: dict[str, Any] = json.loads(lines[-1])
    return out


def systems_section(args: argparse.Namespace, work: Path, env: dict[str, str]) -> None:
    print("## load + compile against pyfuzzylite's import (CPU seconds, C compiler included)\n")
    print(
        "First: a fresh process, empty caches (imports and lark's tables included, then with the "
        "modules loaded first). Cached: another fresh process on the same file, its document, plan "
        "and library on disk from the first (what every later run of a program does).\n"
    )
    print(
        "| system | backend | first | first, modules loaded | cached, modules loaded "
        "| pyfuzzylite import | ratio (first, loaded / cached) |"
    )
    print("|---|---|---|---|---|---|---|")
    for name in ("grid2401", "rules10k"):
        system = S.SYSTEMS[name]
        fcl, fll = work / f"{name}.fcl", work / f"{name}.fll"
        fcl.write_text(S.fcl(system))
        fll.write_text(S.fll(system))
        peer = child(args.peers, _PYFUZZYLITE, [str(fll)], dict(os.environ), 600) if args.peers else None
        peer_cpu = peer["cpu"] if peer and "cpu" in peer else float("nan")
        for backend in ("python", "native"):
            runs = []
            for extra in ([], ["preload"], ["preload"]):  # the third finds the second's caches
                # an empty cache: no document, plan or library, and lark tables built anew
                cache_env = dict(env, FUZZYCTL_CACHE_DIR=str(work / f"cache-{name}-{backend}-{len(extra)}"))
                runs.append(child(sys.executable, _FUZZYCTL, [str(fcl), backend, *extra], cache_env, 900))
            cold, warm, cached = runs
            print(
                f"| {name} ({system.n_rules:,} rules) | {backend} | {cold['cpu']:.2f} s {cold['status']} "
                f"| {warm['cpu']:.2f} s | {cached['cpu']:.2f} s | {peer_cpu:.2f} s "
                f"| {cold['cpu'] / peer_cpu:.2f}x, {warm['cpu'] / peer_cpu:.2f}x / "
                f"{cached['cpu'] / peer_cpu:.2f}x |"
            )


def _large_files(work: Path) -> list[tuple[str, Path, str]]:
    from fuzzyctl.limits import max_input_bytes

    out: list[tuple[str, Path, str]] = []
    for shape in ("valid", "errors", "garbage", "one-line"):
        path = work / f"big-{shape}.fcl"
        path.write_text(L.fcl(shape, max_input_bytes("fcl") - 4096))
        out.append((f"FCL {shape}, {path.stat().st_size / 2**20:.1f} MiB", path, "none"))
    for fmt in ("fis", "fll"):
        path = work / f"big-valid.{fmt}"
        path.write_text(getattr(L, fmt)("valid", max_input_bytes(fmt) - 4096))
        out.append((f"{fmt.upper()} valid, {path.stat().st_size / 2**20:.1f} MiB", path, "none"))
    fll = work / "rules10k-load.fll"
    fll.write_text(S.fll(S.SYSTEMS["rules10k"]))
    out.append(("FLL rules10k, load only", fll, "none"))
    return out


def large_section(args: argparse.Namespace, work: Path, env: dict[str, str]) -> None:
    print("\n## large inputs (fresh process, empty cache: CPU seconds, peak RSS)\n")
    print("| input | result | CPU | peak RSS |")
    print("|---|---|---|---|")
    cache_env = dict(env, FUZZYCTL_NO_CACHE="1", FUZZYCTL_CACHE_DIR=str(work / "cache-large"))
    for label, path, backend in _large_files(work):
        got = child(sys.executable, _FUZZYCTL, [str(path), backend], cache_env, 300)
        print(f"| {label} | {got['status']} | {got['cpu']:.2f} s | {got['rss']:.0f} MB |")
    got = child(sys.executable, _MUTANT, [str(ROOT)], cache_env, 300)
    print(f"| fuzzer mutant #16 (robot.fcl) | {got['status']} | {got['cpu']:.2f} s | {got['rss']:.0f} MB |")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--src", type=Path, default=None, help="fuzzyctl source tree for the children")
    default_peers = ROOT / ".venv-peers" / "bin" / "python"
    ap.add_argument("--peers", default=str(default_peers) if default_peers.exists() else None)
    ap.add_argument("--skip-large", action="store_true")
    args = ap.parse_args()
    env = dict(os.environ, FUZZYCTL_QUIET="1")
    env.pop("FUZZYCTL_BACKEND", None)
    if args.src is not None:
        env["PYTHONPATH"] = str(args.src.resolve())
    print(f"load average {os.getloadavg()[0]:.1f} at the start")
    with tempfile.TemporaryDirectory() as tmp:
        systems_section(args, Path(tmp), env)
        if not args.skip_large:
            large_section(args, Path(tmp), env)
    print(f"\nload average {os.getloadavg()[0]:.1f} at the end")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
