"""What the generated PLC code costs, per example and per form of arithmetic: its largest
error against the engine, its memory, its operations per cycle (counted on the IR,
``fuzzyctl.ir.cost``) and its time per cycle compiled by matiec (the IEC 61131-3 compiler of
OpenPLC and Beremiz: ST -> C, then ``gcc -O2``), beside the native backend's time per
evaluation (a batch, per row).

    python benchmarks/bench_codegen.py              # a plain table
    python benchmarks/bench_codegen.py --markdown   # the table of docs/codegen.md
    python benchmarks/bench_codegen.py --markdown --side-by-side   # REAL/LREAL/int16/int32/lookup

``--side-by-side`` gives the table of issue-29 point 3: crane, figure 7, tank and tipper in
every form, with the error each form's header states beside the one observed (integer forms
and the lookup table state a proven bound; REAL/LREAL state none).  The integer forms and the
table read their inputs within the input ranges (a stored integer cannot go beyond them), so
their inputs, and the engine's, are limited to the ranges first.

matiec is built on first use into the test cache (tests/codegen/matiec.py, ~2 min), from
``../shared/tools/matiec-src.tar.gz``.

A form of arithmetic is one :class:`Form` in :data:`FORMS` (a column group of the table): its
Structured Text and how the driver hands it numbers (:class:`Block`).  A new form adds an
entry; nothing else changes.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # tests.codegen.matiec builds and drives matiec

import fuzzyctl  # noqa: E402
from fuzzyctl.codegen.api import Generated, generate_st, lower_block  # noqa: E402
from fuzzyctl.engine.plan import Plan  # noqa: E402
from fuzzyctl.escape import CodegenError  # noqa: E402
from fuzzyctl.ir.cost import cost  # noqa: E402
from fuzzyctl.ir.nodes import Program  # noqa: E402

EXAMPLES = ["crane.fcl", "figure7.fcl", "tank.fcl", "heater_extension.fcl", "pendulum.fcl"]
ROWS = 2000  # inputs for the error, and the timed cycles (repeated)
BYTES = {"REAL": 4, "LREAL": 8, "INT": 2, "DINT": 4, "BOOL": 1, "BYTE": 1}


@dataclass
class Block:
    """One generated block as the benchmark drives it: its ``--dialect iec`` text, its name
    and outputs, the statements one cycle runs (for :func:`fuzzyctl.ir.cost.cost`), its memory
    (instance, temporaries), the error its header states per output (fraction of the output
    range; None: none stated), and how the driver converts engineering values to what the
    block reads and back."""

    text: str
    name: str
    outputs: list[str]
    body: Any
    memory: tuple[int, int]
    stated: list[float | None]
    encode: Callable[[np.ndarray], np.ndarray] = lambda x: x
    decode: Callable[[int, np.ndarray], np.ndarray] = lambda k, y: y
    limited: bool = False  # the inputs are limited to their ranges first


@dataclass(frozen=True)
class Form:
    """One form of generated arithmetic.  ``make(plan, model)`` gives its :class:`Block`;
    ``c_type`` is the C type the driver converts inputs and outputs through."""

    name: str
    c_type: str
    make: Callable[[Plan, Any], Block]


def _st(lreal: bool) -> Callable[[Plan, Any], Block]:
    def make(plan: Plan, model: Any) -> Block:
        report: list[Generated] = []
        text = generate_st(plan, dialect="iec", lreal=lreal, report=report)
        gen = report[0]
        outputs = [op.name for op in gen.plan.outputs if op.is_output]
        mem = memory(gen.program, 8 if lreal else 4)
        return Block(text, gen.program.name, outputs, gen.program, mem, [None] * len(outputs))

    return make


def _scaled(ports: Any) -> tuple[list[float], list[float]]:
    return [float(p.scale) for p in ports], [float(p.offset) for p in ports]


def _int(arith: str) -> Callable[[Plan, Any], Block]:
    def make(plan: Plan, model: Any) -> Block:
        report: list[Any] = []
        text = generate_st(model, dialect="iec", arith=arith, report=report)
        prog = report[0].program
        isc, ioff = _scaled(prog.inputs)
        osc, ooff = _scaled(prog.outputs)
        lows, highs = [p.low for p in prog.inputs], [p.high for p in prog.inputs]
        width = {"narrow": prog.arith.bits // 8, "wide": prog.arith.bits // 4, "bool": 1, "byte": 1}
        inst = sum(width[d.kind] for d in prog.decls if d.storage != "temp")
        temp = sum(width[d.kind] for d in prog.decls if d.storage == "temp")
        stated = [
            p.error_bound / (hi - lo)
            for p, (lo, hi) in zip(prog.outputs, _out_ranges(model, prog.outputs), strict=True)
        ]

        def encode(x: np.ndarray) -> np.ndarray:
            return np.column_stack(
                [np.clip(np.rint((x[:, i] - ioff[i]) / isc[i]), lows[i], highs[i]) for i in range(x.shape[1])]
            )

        def decode(k: int, y: np.ndarray) -> np.ndarray:
            return y * osc[k] + ooff[k]

        names = [p.name for p in prog.outputs]
        return Block(text, prog.name, names, prog, (inst, temp), list(stated), encode, decode, True)

    return make


def _out_ranges(model: Any, ports: Any) -> list[tuple[float, float]]:
    ctl = fuzzyctl.compile(model, backend="interpreted")
    return [span(ctl.outputs[p.name]) for p in ports]


def _lookup(tolerance: float) -> Callable[[Plan, Any], Block]:
    def make(plan: Plan, model: Any) -> Block:
        from fuzzyctl.ir.programs.table_block import build_table_block

        report: list[Any] = []
        text = generate_st(model, dialect="iec", lookup=True, tolerance=tolerance, report=report)
        t = report[0].table
        block = build_table_block(
            t.name, t.inputs, t.outputs, t.axes, [v.ravel() for v in t.values], integer=False
        )
        inst = 4 * (len(t.inputs) + len(t.outputs)) + 1 + t.size_bytes("REAL")
        temp = sum(4 for d in block.decls if d.storage == "temp")
        return Block(text, t.name, list(t.outputs), block, (inst, temp), t.relative(t.bound), limited=True)

    return make


FORMS: dict[str, Form] = {
    "REAL": Form("REAL", "float", _st(False)),
    "LREAL": Form("LREAL", "double", _st(True)),
    "int16": Form("int16", "IEC_INT", _int("int16")),
    "int32": Form("int32", "IEC_DINT", _int("int32")),
    "lookup 1%": Form("lookup 1%", "float", _lookup(0.01)),
}
#: the forms and examples of the side-by-side table (issue 29, point 3)
SIDE_FORMS = ["REAL", "LREAL", "int16", "int32", "lookup 1%"]
SIDE_EXAMPLES = ["crane.fcl", "figure7.fcl", "tank.fcl", "tipper.fis"]


@dataclass
class Row:
    example: str
    form: str
    error: float  # largest |block - engine| over ROWS inputs, in % of the output range
    memory: tuple[int, int]  # instance bytes, temporaries bytes
    stated: float | None  # the largest error the header states, in % of the output range
    ops: tuple[int, int]  # usual, worst operations per cycle
    bounded: bool  # False: loops without a static bound, counted once
    matiec_ns: float
    native_ns: float
    refused: str | None = None  # why the form cannot express the example (the generator's reason)


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


def _limited(ctl: fuzzyctl.engine.Controller, plan: Plan, data: np.ndarray) -> np.ndarray:
    """``data`` with each input limited to its span (what an integer or table block reads)."""
    cols = []
    for i, inp in enumerate(plan.inputs):
        lo, hi = span(ctl.inputs[inp.name]) if inp.name in ctl.inputs else (0.0, 1.0)
        cols.append(np.clip(data[:, i], lo, hi))
    return np.column_stack(cols) if cols else data


def measure(example: str, form: Form, matiec: Path, where: Path) -> Row:
    from tests.codegen.matiec import iec2c

    path = ROOT / "examples" / example
    model = fuzzyctl.load(path)
    plan = lower_block(model)
    ctl = fuzzyctl.compile(path, backend="native", out_of_range="ignore")
    data = _inputs(ctl, plan, np.random.default_rng(7))
    block = form.make(plan, model)
    if block.limited:
        data = _limited(ctl, plan, data)
    where.mkdir(parents=True, exist_ok=True)
    iec2c(matiec, block.text, where)
    (where / "driver.c").write_text(
        _driver(block.name, [i.name for i in plan.inputs], block.outputs, form.c_type)
    )
    subprocess.run(
        ["gcc", "-O2", "-w", "-I", str(matiec / "lib" / "C"), "-o", "driver", "driver.c", "-lm"],
        cwd=where,
        check=True,
    )
    exe = where / "driver"
    fed = block.encode(data)
    got = np.array([[float.fromhex(v) for v in line.split()] for line in _run(exe, fed, "run").splitlines()])
    if block.limited:  # the engine at the inputs the block reads
        isc = getattr(block.body, "inputs", None)
        if isc is not None:  # integer: the stored inputs, back in engineering units
            data = np.column_stack(
                [fed[:, i] * float(p.scale) + float(p.offset) for i, p in enumerate(block.body.inputs)]
            )
    want = ctl.evaluate_batch({inp.name: data[:, i] for i, inp in enumerate(plan.inputs)})
    error = 0.0
    stated = [s for s in block.stated if s is not None]
    for k, name in enumerate(block.outputs):
        lo, hi = span(ctl.outputs[name])
        diff = np.abs(block.decode(k, got[:, k]) - np.asarray(want[name], dtype=np.float64))
        error = max(error, float(np.nanmax(diff)) / (hi - lo) * 100.0)
    ns = min(float(_run(exe, fed, "time", "200").split()[0]) for _ in range(3))
    c = cost(block.body)
    return Row(
        example.rsplit(".", 1)[0],
        form.name,
        error,
        memory=block.memory,
        stated=100.0 * max(stated) if stated else None,
        ops=(c.usual.operations, c.worst.operations),
        bounded=c.worst.bounded,
        matiec_ns=ns,
        native_ns=native_ns(ctl, plan, data),
    )


def markdown(rows: list[Row], side: bool = False) -> str:
    if side:
        out = [
            "| example | form | error stated / observed (% of output range) | memory: instance + temporaries "
            "(bytes) | operations per cycle: usual / worst | matiec + gcc -O2 (ns per cycle) |",
            "|---|---|---:|---:|---:|---:|",
        ]
        for r in rows:
            if r.refused:
                out.append(f"| {r.example} | {r.form} | refused: {r.refused.split(' (use ')[0]} | | | |")
                continue
            stated = "-" if r.stated is None else f"{r.stated:.2g}"
            out.append(
                f"| {r.example} | {r.form} | {stated} / {r.error:.2g} | {r.memory[0]} + {r.memory[1]} | "
                f"{r.ops[0]} / {r.ops[1]}{'' if r.bounded else ' (loops once)'} | {r.matiec_ns:.0f} |"
            )
        return "\n".join(out)
    out = [
        "| example | form | largest error (% of output range) | memory: instance + temporaries (bytes) "
        "| operations per cycle: usual / worst | matiec + gcc -O2 (ns per cycle) "
        "| native (ns per row) | ratio |",
        "|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        if r.refused:
            out.append(f"| {r.example} | {r.form} | refused: {r.refused} | | | | | |")
            continue
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
    ap.add_argument(
        "--side-by-side",
        action="store_true",
        help="REAL, LREAL, int16, int32 and lookup side by side on crane, figure 7, tank and tipper",
    )
    ap.add_argument("--forms", default=None, help="comma-separated forms (columns)")
    ap.add_argument("--examples", default=None, help="comma-separated example files")
    args = ap.parse_args()
    forms = args.forms.split(",") if args.forms else (SIDE_FORMS if args.side_by_side else ["REAL", "LREAL"])
    examples = (
        args.examples.split(",") if args.examples else (SIDE_EXAMPLES if args.side_by_side else EXAMPLES)
    )
    from tests.codegen.matiec import build

    matiec = build()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for ex in examples:
            for name in forms:
                try:
                    rows.append(
                        measure(ex, FORMS[name], matiec, Path(tmp) / f"{ex}-{name}".replace(" ", "_"))
                    )
                except CodegenError as exc:
                    why = str(exc).split(": ", 1)[-1] if "--lookup" in str(exc) else str(exc)
                    rows.append(
                        Row(ex.rsplit(".", 1)[0], name, 0.0, (0, 0), None, (0, 0), True, 0.0, 1.0, why)
                    )
                r = rows[-1]
                if r.refused and not args.markdown:
                    print(f"{r.example:18} {r.form:9} refused: {r.refused}", flush=True)
                elif not args.markdown:
                    stated = "-" if r.stated is None else f"{r.stated:.2g}%"
                    print(
                        f"{r.example:18} {r.form:9} err {stated} / {r.error:.2g}%  "
                        f"mem {r.memory[0]}+{r.memory[1]} B  "
                        f"ops {r.ops[0]}/{r.ops[1]}  matiec {r.matiec_ns:.0f} ns  "
                        f"native {r.native_ns:.1f} ns  "
                        f"x{r.matiec_ns / r.native_ns:.1f}",
                        flush=True,
                    )
    if args.markdown:
        print(markdown(rows, args.side_by_side))


if __name__ == "__main__":
    main()
