"""What the generated PLC code costs, per example and per form of arithmetic: its largest
error against the engine, its memory, its operations per cycle (counted on the IR,
``fuzzyctl.ir.cost``) and its time per cycle compiled by matiec (the IEC 61131-3 compiler of
OpenPLC and Beremiz: ST -> C, then ``gcc -O2``), beside the native backend's time per
evaluation (a batch, per row).

    python benchmarks/bench_codegen.py              # a plain table
    python benchmarks/bench_codegen.py --markdown   # the table of docs/codegen.md

matiec is built on first use into the test cache (tests/codegen/matiec.py, ~2 min), from
``../shared/tools/matiec-src.tar.gz``.

A form of arithmetic is one :class:`Form` in :data:`FORMS` (a column group of the table): its
Structured Text and how the driver hands it numbers.  A new form (integer, lookup table)
adds an entry; nothing else changes.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # tests.codegen.matiec builds and drives matiec

import fuzzyctl  # noqa: E402
from fuzzyctl.codegen.api import Generated, generate_st, lower_block  # noqa: E402
from fuzzyctl.engine.plan import Plan  # noqa: E402
from fuzzyctl.ir.cost import cost  # noqa: E402
from fuzzyctl.ir.nodes import Program  # noqa: E402

EXAMPLES = ["crane.fcl", "figure7.fcl", "tank.fcl", "heater_extension.fcl", "pendulum.fcl"]
ROWS = 2000  # inputs for the error, and the timed cycles (repeated)
BYTES = {"REAL": 4, "LREAL": 8, "INT": 2, "DINT": 4, "BOOL": 1, "BYTE": 1}


@dataclass(frozen=True)
class Form:
    """One form of generated arithmetic.  ``st(plan)`` gives the ``--dialect iec`` text and the
    report of its block; ``c_type`` is the C type the driver converts inputs and outputs
    through (an integer form would also scale them: give it ``encode``/``decode``)."""

    name: str
    c_type: str
    real_bytes: int
    st: Callable[[Plan], tuple[str, Generated]]
    encode: Callable[[np.ndarray], np.ndarray] = lambda x: x
    decode: Callable[[np.ndarray], np.ndarray] = lambda y: y


def _st(lreal: bool) -> Callable[[Plan], tuple[str, Generated]]:
    def make(plan: Plan) -> tuple[str, Generated]:
        report: list[Generated] = []
        text = generate_st(plan, dialect="iec", lreal=lreal, report=report)
        return text, report[0]

    return make


FORMS: dict[str, Form] = {
    "REAL": Form("REAL", "float", 4, _st(False)),
    "LREAL": Form("LREAL", "double", 8, _st(True)),
}


@dataclass
class Row:
    example: str
    form: str
    error: float  # largest |block - engine| over ROWS inputs, in % of the output range
    memory: tuple[int, int]  # instance bytes, temporaries bytes
    ops: tuple[int, int]  # usual, worst operations per cycle
    bounded: bool  # False: loops without a static bound, counted once
    matiec_ns: float
    native_ns: float


def memory(prog: Program, real_bytes: int) -> tuple[int, int]:
    """Bytes of the instance (inputs, outputs, parameters, state, tables) and of the
    temporaries of one call."""
    inst = temp = 0
    for d in prog.decls:
        size = (real_bytes if d.type == "REAL" else BYTES[d.type]) * (d.size or 1)
        if d.storage == "temp":
            temp += size
        else:
            inst += size
    return inst, temp


def _driver(name: str, inputs: list[str], outputs: list[str], c_type: str) -> str:
    """``driver run`` prints each row's outputs (hexadecimal); ``driver time R`` runs the
    rows R times and prints the nanoseconds per cycle."""
    n_in, n_out = max(1, len(inputs)), max(1, len(outputs))
    sets = "".join(
        f"    __SET_VAR(fb.,{v.upper()},,({c_type})x[r * {n_in} + {i}]);\n" for i, v in enumerate(inputs)
    )
    gets = "".join(f"    y[{i}] = (double)__GET_VAR(fb.{v.upper()});\n" for i, v in enumerate(outputs))
    return f"""#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "POUS.h"
#include "POUS.c"
IEC_TIME __CURRENT_TIME;
IEC_BOOL __DEBUG;
static {name.upper()} fb;
int main(int argc, char **argv) {{
  long n, r, k, reps = argc > 2 ? atol(argv[2]) : 1;
  double *x, y[{n_out}], sink = 0.0;
  struct timespec t0, t1;
  if (scanf("%ld", &n) != 1) return 3;
  x = malloc(sizeof(double) * (size_t)(n * {n_in} + 1));
  for (r = 0; r < n * {len(inputs)}; r++) if (scanf("%la", &x[r]) != 1) return 3;
  {name.upper()}_init__(&fb, 0);
  if (strcmp(argv[1], "run") == 0) {{
    for (r = 0; r < n; r++) {{
{sets}    {name.upper()}_body__(&fb);
{gets}      for (k = 0; k < {len(outputs)}; k++) printf("%a ", y[k]);
      printf("\\n");
    }}
    return 0;
  }}
  clock_gettime(CLOCK_MONOTONIC, &t0);
  for (k = 0; k < reps; k++) for (r = 0; r < n; r++) {{
{sets}    {name.upper()}_body__(&fb);
{gets}    sink += y[0];
  }}
  clock_gettime(CLOCK_MONOTONIC, &t1);
  printf("%.3f %g\\n",
         ((t1.tv_sec - t0.tv_sec) * 1e9 + (t1.tv_nsec - t0.tv_nsec)) / (double)(reps * n), sink);
  return 0;
}}
"""


def span(info: object) -> tuple[float, float]:
    """A variable's RANGE, else the span of its terms' points and parameters."""
    lo, hi = getattr(info, "low", None), getattr(info, "high", None)
    if lo is not None and hi is not None and hi > lo:
        return float(lo), float(hi)
    xs: list[float] = []
    for t in getattr(info, "terms", ()):
        numbers = [float(p) for p in t.params if isinstance(p, int | float)]  # not the variables
        xs += [x for x, _y in t.points] if t.points else numbers
    return (min(xs), max(xs)) if xs and max(xs) > min(xs) else (0.0, 1.0)


def _inputs(ctl: fuzzyctl.engine.Controller, plan: Plan, rng: np.random.Generator) -> np.ndarray:
    """Uniform inputs over each input's span, a tenth beyond both ends."""
    cols = []
    for inp in plan.inputs:
        lo, hi = span(ctl.inputs[inp.name]) if inp.name in ctl.inputs else (0.0, 1.0)
        pad = 0.0 if inp.degree else 0.1 * (hi - lo)  # a degree stays in [0, 1]
        if inp.degree:
            lo, hi = 0.0, 1.0
        cols.append(rng.uniform(lo - pad, hi + pad, ROWS))
    return np.column_stack(cols) if cols else np.zeros((ROWS, 0))


def _run(exe: Path, data: np.ndarray, *args: str) -> str:
    lines = [str(len(data))] + [" ".join(float(v).hex() for v in row) for row in data]
    res = subprocess.run(
        [str(exe), *args], input="\n".join(lines) + "\n", capture_output=True, text=True, timeout=600
    )
    if res.returncode != 0:
        raise RuntimeError(f"{exe} {args}: {res.returncode} {res.stderr[-500:]}")
    return res.stdout


def native_ns(ctl: fuzzyctl.engine.Controller, plan: Plan, data: np.ndarray) -> float:
    """The native backend's time per row of a batch (best of 5)."""
    import time

    big = np.tile(data, (50, 1))
    cols = {inp.name: big[:, i] for i, inp in enumerate(plan.inputs)}
    best = float("inf")
    for _ in range(5):
        t0 = time.perf_counter()
        ctl.evaluate_batch(cols)
        best = min(best, time.perf_counter() - t0)
    return best / len(big) * 1e9


def measure(example: str, form: Form, matiec: Path, where: Path) -> Row:
    from tests.codegen.matiec import iec2c

    path = ROOT / "examples" / example
    plan = lower_block(fuzzyctl.load(path))
    ctl = fuzzyctl.compile(path, backend="native", out_of_range="ignore")
    data = _inputs(ctl, plan, np.random.default_rng(7))
    text, gen = form.st(plan)
    outputs = [op.name for op in gen.plan.outputs if op.is_output]
    where.mkdir(parents=True, exist_ok=True)
    iec2c(matiec, text, where)
    (where / "driver.c").write_text(
        _driver(gen.program.name, [i.name for i in plan.inputs], outputs, form.c_type)
    )
    subprocess.run(
        ["gcc", "-O2", "-w", "-I", str(matiec / "lib" / "C"), "-o", "driver", "driver.c", "-lm"],
        cwd=where,
        check=True,
    )
    exe = where / "driver"
    got = np.array(
        [
            [float.fromhex(v) for v in line.split()]
            for line in _run(exe, form.encode(data), "run").splitlines()
        ]
    )
    want = ctl.evaluate_batch({inp.name: data[:, i] for i, inp in enumerate(plan.inputs)})
    error = 0.0
    for k, name in enumerate(outputs):
        lo, hi = span(ctl.outputs[name])
        diff = np.abs(form.decode(got[:, k]) - np.asarray(want[name], dtype=np.float64))
        error = max(error, float(np.nanmax(diff)) / (hi - lo) * 100.0)
    ns = min(float(_run(exe, data, "time", "200").split()[0]) for _ in range(3))
    c = cost(gen.program)
    return Row(
        example.removesuffix(".fcl"),
        form.name,
        error,
        memory(gen.program, form.real_bytes),
        (c.usual.operations, c.worst.operations),
        c.worst.bounded,
        ns,
        native_ns(ctl, plan, data),
    )


def markdown(rows: list[Row]) -> str:
    out = [
        "| example | form | largest error (% of output range) | memory: instance + temporaries (bytes) "
        "| operations per cycle: usual / worst | matiec + gcc -O2 (ns per cycle) "
        "| native (ns per row) | ratio |",
        "|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        out.append(
            f"| {r.example} | {r.form} | {r.error:.2g} | {r.memory[0]} + {r.memory[1]} | "
            f"{r.ops[0]} / {r.ops[1]}{'' if r.bounded else ' (loops once)'} | {r.matiec_ns:.0f} | "
            f"{r.native_ns:.1f} | "
            f"{r.matiec_ns / r.native_ns:.1f} |"
        )
    return "\n".join(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--markdown", action="store_true", help="print the table of docs/codegen.md")
    ap.add_argument("--forms", default=",".join(FORMS), help="comma-separated forms (columns)")
    ap.add_argument("--examples", default=",".join(EXAMPLES), help="comma-separated example files")
    args = ap.parse_args()
    from tests.codegen.matiec import build

    matiec = build()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for ex in args.examples.split(","):
            for name in args.forms.split(","):
                rows.append(measure(ex, FORMS[name], matiec, Path(tmp) / f"{ex}-{name}"))
                if not args.markdown:
                    r = rows[-1]
                    print(
                        f"{r.example:18} {r.form:6} err {r.error:.2g}%  mem {r.memory[0]}+{r.memory[1]} B  "
                        f"ops {r.ops[0]}/{r.ops[1]}  matiec {r.matiec_ns:.0f} ns  "
                        f"native {r.native_ns:.1f} ns  "
                        f"x{r.matiec_ns / r.native_ns:.1f}",
                        flush=True,
                    )
    if args.markdown:
        print(markdown(rows))


if __name__ == "__main__":
    main()
