"""Differential checks for the fuzzer (issue 25, point 2): every path that evaluates a model
against the reference interpreter (``compile(doc, backend="interpreted")``).

Paths and their verdict categories (``disagree:<path>``):

* ``python`` / ``numpy``: ``compile(backend="python")`` ``evaluate`` and ``evaluate_batch``;
* ``native`` / ``native-batch``: the same on ``backend="native"`` (a fallback to the Python
  path, when the C generator refuses the plan, is counted as ``native-fallback``);
* ``explain``: the value :meth:`Controller.explain` reports (the default backend);
* ``cli-set`` / ``cli-data``: ``fuzzyctl eval --set ... --json`` (the first vector, fresh
  state) and ``eval --data`` (every vector, in order) run in-process;
* ``c``: generated C (``codegen.generate_c``) with a small driver compiled by ``cc``; where
  the header states an error bound for an output (smooth CoG by quadrature) the observed
  difference must be within it (``bound:c-header``), elsewhere within the 1e-9 tolerance;
* ``interpreted``: blamed when every other path that ran agrees among itself and none agrees
  with the reference (the reference is then the odd one out).

Agreement: within 1e-9 of the output's range (``RANGE``, else the span of its terms, else
max(1, |value|)) - or, for values past a thousand ranges, within 1e-13 of the value -, both
NaN, the same infinity, or the same refusal (a project error).
Vectors are evaluated in order from a reset state, so ``DEFAULT := NC`` carries over the
same way on every path (``evaluate_batch`` and the C ``_batch`` are documented to)."""

from __future__ import annotations

import contextlib
import csv
import dataclasses
import io
import itertools
import json
import math
import random
import re
import shutil
import subprocess
import tempfile
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

REL_TOL = 1e-9
LARGE_RULES = 500
VALUE_TOL = 1e-13
#: the paths compared, in the order of the summary table
PATHS = (
    "python",
    "numpy",
    "native",
    "native-batch",
    "explain",
    "cli-set",
    "cli-data",
    "c",
    "interpreted",
)
REFUSED = "refused"


@dataclass
class Finding:
    category: str  # disagree:<path>, bound:c-header
    detail: str


@dataclass
class DiffResult:
    """What one model gave: the paths compared (at least one vector) and the findings."""

    compared: set[str] = field(default_factory=set)
    findings: list[Finding] = field(default_factory=list)
    notes: set[str] = field(default_factory=set)  # native-fallback, ...


Value = float | str  # a number or "refused"


def _project_error() -> type[Exception]:
    from fuzzyctl.diagnostics import FuzzyctlError

    return FuzzyctlError


def output_scale(op: Any, ref_values: Sequence[Value]) -> float:
    """The output's range: RANGE (plan low/high), else the span of its terms' points, else
    max(1, |value|) over the reference's values."""
    lo, hi = op.low, op.high
    if lo is not None and hi is not None and math.isfinite(hi - lo) and hi > lo:
        return float(hi - lo)
    xs: list[float] = []
    for t in op.terms:
        if t.pwl is not None:
            xs += [x for x, _ in t.pwl]
        else:
            xs += [float(p) for p in t.params if isinstance(p, int | float)]
    xs = [x for x in xs if math.isfinite(x)]
    if xs and max(xs) > min(xs) and math.isfinite(max(xs) - min(xs)):
        return max(xs) - min(xs)
    nums = [abs(v) for v in ref_values if isinstance(v, float) and math.isfinite(v)]
    return max([1.0, *nums])


def agree(a: Value, b: Value, scale: float, tol: float = REL_TOL) -> bool:
    if isinstance(a, str) or isinstance(b, str):
        return a == b
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    if math.isinf(a) or math.isinf(b):
        return a == b
    # past a thousand ranges (a Takagi-Sugeno linear term extrapolated to x = 1e30) a
    # fraction of the range is below the values' own rounding: then ~450 ulps of the value
    return abs(a - b) <= max(tol * scale, VALUE_TOL * max(abs(a), abs(b)))


# --------------------------------------------------------------------------- input vectors


def _points(plan: Any, slot: int) -> list[float]:
    """Breakpoints and characteristic points of the terms that read input ``slot``."""
    from fuzzyctl.engine.semantics import shapes

    xs: list[float] = []
    for fi in plan.fuzzy_inputs:
        if fi.slot != slot:
            continue
        for t in fi.terms:
            if t.pwl is not None:
                xs += [x for x, _ in t.pwl]
            elif t.constant and t.kind not in ("function",):
                with contextlib.suppress(Exception):
                    xs += list(shapes.characteristic_points(t.kind, [float(p) for p in t.params]))
    return [x for x in xs if math.isfinite(x)]


def vectors(plan: Any, rng: random.Random, n: int = 8) -> list[list[float]]:
    """``n`` input rows (plan input order): breakpoints (and their float neighbours), the
    ends of the input's hull and beyond, and random values inside it."""
    cols: list[list[float]] = []
    for i, spec in enumerate(plan.inputs):
        if spec.degree:
            cols.append([rng.choice([0.0, 1.0, 0.5, rng.random(), 5e-324, 1 - 2**-53]) for _ in range(n)])
            continue
        pts = _points(plan, i)
        lo, hi = (min(pts), max(pts)) if pts else (0.0, 1.0)
        if spec.clamp is not None:
            lo, hi = spec.clamp
        if not math.isfinite(hi - lo) or hi <= lo:
            lo, hi = (lo - 1.0, lo + 1.0) if math.isfinite(lo) else (0.0, 1.0)
        col = []
        for _ in range(n):
            kind = rng.randrange(8)
            if kind <= 1 and pts:
                x = rng.choice(pts)
                x = x if kind == 0 else math.nextafter(x, rng.choice([-math.inf, math.inf]))
            elif kind == 2:
                x = rng.choice([lo, hi])
            elif kind == 3:
                x = rng.choice([lo - 0.25 * (hi - lo), hi + 0.25 * (hi - lo), -1e30, 1e30])
            else:
                x = lo + rng.random() * (hi - lo)
            col.append(float(x) if math.isfinite(x) else 0.0)
        cols.append(col)
    return [list(row) for row in zip(*cols, strict=True)] if cols else [[] for _ in range(n)]


# --------------------------------------------------------------------------- the paths


def _quiet(fn: Callable[[], Any]) -> Any:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fn()


def sequential(
    ctl: Any, names: Sequence[str], rows: Sequence[Sequence[float]], outs: Sequence[str]
) -> list[list[Value]]:
    """``evaluate`` row after row from a reset state; a refused row is ``"refused"``."""
    err = _project_error()
    ctl.reset()
    res: list[list[Value]] = []
    for row in rows:
        try:
            got = ctl.evaluate(dict(zip(names, row, strict=True)))
            res.append([float(got[o]) for o in outs])
        except err:
            res.append([REFUSED] * len(outs))
    return res


def _batch(
    ctl: Any, names: Sequence[str], rows: Sequence[Sequence[float]], outs: Sequence[str]
) -> list[list[Value]]:
    import numpy as np

    err = _project_error()
    ctl.reset()
    try:
        got = ctl.evaluate_batch(  # rows=: a model without inputs has no column to count
            {n: np.array([r[i] for r in rows], dtype=float) for i, n in enumerate(names)}, rows=len(rows)
        )
    except err:
        return [[REFUSED] * len(outs) for _ in rows]
    if any(len(got[o]) != len(rows) for o in outs):  # a wrong shape is a disagreement on every row
        return [[f"{len(got[o])} values for {len(rows)} rows" for o in outs] for _ in rows]
    return [[float(got[o][k]) for o in outs] for k in range(len(rows))]


def _explain(
    ctl: Any, names: Sequence[str], rows: Sequence[Sequence[float]], outs: Sequence[str]
) -> list[list[Value]]:
    err = _project_error()
    ctl.reset()
    res: list[list[Value]] = []
    for row in rows:
        try:
            e = ctl.explain(dict(zip(names, row, strict=True)))
            vals = {o.name: o.value for o in e.outputs}
            res.append([float(vals[o]) for o in outs])
        except err:
            res.append([REFUSED] * len(outs))
    return res


def _cli(
    model_path: Path,
    fmt: str,
    block: str | None,
    names: Sequence[str],
    rows: Sequence[Sequence[float]],
    outs: Sequence[str],
    data: bool,
) -> list[list[Value]] | None:
    """``fuzzyctl eval`` in-process; None when it exits with a usage error (2: for example
    a name the command line cannot carry)."""
    from fuzzyctl.cli.app import main

    args = ["eval", str(model_path), "--json"]
    if block is not None:
        args += ["--block", block]
    if data:
        csv_path = Path(tempfile.mkdtemp(prefix="fuzzyctl-diff-")) / "rows.csv"
        with csv_path.open("w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(names)
            w.writerows([[repr(v) for v in r] for r in rows])
        args += ["--data", str(csv_path), "--on-error", "fail"]
    else:
        rows = rows[:1]
        for n, v in zip(names, rows[0], strict=True):
            args += ["--set", f"{n}={v!r}"]
    # a real text stream over bytes: the --data path writes to sys.stdout.buffer
    raw, err = io.BytesIO(), io.StringIO()
    out = io.TextIOWrapper(raw, encoding="utf-8", newline="")
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(args)
    out.flush()
    text = raw.getvalue().decode("utf-8", "replace")
    if code not in (0, 1):
        return None
    lines = [json.loads(ln) for ln in text.splitlines() if ln.strip().startswith("{")]
    if code == 1 and not lines:
        return [[REFUSED] * len(outs) for _ in rows]
    if len(lines) != len(rows):  # exit 1 with a NaN output prints it as null (and says why)
        raise AssertionError(f"eval printed {len(lines)} rows for {len(rows)}: {text[:300]}")
    return [[_num(d.get(o)) for o in outs] for d in lines]


def _num(v: Any) -> Value:
    if v is None:
        return math.nan
    if isinstance(v, str):
        with contextlib.suppress(ValueError):
            return float(v)
        return REFUSED
    return float(v)


# --------------------------------------------------------------------------- generated C

_BOUND = re.compile(r"output (\S+): .*\|CoG error\| <= ([0-9.eE+-]+) x \(high - low\)\^2 / area")


def header_bounds(header: str) -> dict[str, float]:
    """Output name -> K of ``|CoG error| <= K x (high - low)^2 / area`` in a C header."""
    return {m.group(1): float(m.group(2)) for m in _BOUND.finditer(header)}


def _driver(name: str, n_in: int, n_out: int) -> str:
    return f"""#include <stdio.h>
#include <stdlib.h>
#include "{name}.h"
int main(void) {{
  static {name} fb; long n, r; int k;
  double in[{max(1, n_in)}], out[{max(1, n_out)}];
  {name}_init(&fb);
  if (scanf("%ld", &n) != 1) return 3;
  for (r = 0; r < n; r++) {{
    for (k = 0; k < {n_in}; k++) if (scanf("%la", &in[k]) != 1) return 3;
    {name}_batch(&fb, 1, in, out);
    for (k = 0; k < {n_out}; k++) printf("%a ", out[k]);
    printf("\\n");
  }}
  return 0;
}}
"""


def run_c(plan: Any, rows: Sequence[Sequence[float]]) -> tuple[list[list[float]], dict[str, float]] | None:
    """The generated C's outputs for ``rows`` (in order, one instance) and the header's
    bounds; None when the generator refuses the plan or there is no compiler."""
    from fuzzyctl.codegen import generate_c

    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        return None
    plan = dataclasses.replace(plan, name="fzd")
    try:
        files = _quiet(lambda: generate_c(plan))
    except _project_error():
        return None
    n_in = len(plan.inputs)
    n_out = sum(1 for o in plan.outputs if o.is_output)
    with tempfile.TemporaryDirectory(prefix="fuzzyctl-diff-c-") as tmp:
        d = Path(tmp)
        for fname, text in files.items():
            (d / fname).write_text(text)
        (d / "drv.c").write_text(_driver("fzd", n_in, n_out))
        res = subprocess.run(
            [cc, "-O1", "-w", "-o", "drv", "drv.c", "fzd.c", "-lm"],
            cwd=d,
            capture_output=True,
            text=True,
            timeout=120,
        )
        if res.returncode != 0:
            raise RuntimeError(f"cc failed on generated C: {res.stderr[-500:]}")
        feed = f"{len(rows)}\n" + "".join(" ".join(float.hex(float(v)) for v in r) + "\n" for r in rows)
        res = subprocess.run([str(d / "drv")], input=feed, capture_output=True, text=True, timeout=60)
        if res.returncode != 0:
            raise RuntimeError(f"the C driver exited {res.returncode}: {res.stderr[-300:]}")
        out = [
            [float.fromhex(t) if "nan" not in t and "inf" not in t else float(t) for t in ln.split()]
            for ln in res.stdout.splitlines()
        ]
    return out, header_bounds(files["fzd.h"])


def accumulated_area(ref: Any, names: Sequence[str], row: Sequence[float], out: str) -> float | None:
    """The area of the reference's accumulated set for ``out`` at ``row`` (trapezoid rule on
    the breakpoints explain reports)."""
    with contextlib.suppress(Exception):
        e = ref.explain(dict(zip(names, row, strict=True)))
        for o in e.outputs:
            if o.name == out and o.breakpoints:
                bp = o.breakpoints
                return float(sum((x1 - x0) * (y0 + y1) / 2 for (x0, y0), (x1, y1) in itertools.pairwise(bp)))
    return None


# --------------------------------------------------------------------------- one model


@dataclass
class ExtraPaths:
    """What :func:`check` is asked to run besides the in-process API paths."""

    cli_path: Path | None = None  # the model as a file the CLI reads
    cli_fmt: str = "fcl"
    cli: bool = False
    c: bool = False


def compile_quiet(model: Any, block: str | None, backend: str | None) -> Any:
    import fuzzyctl

    err = _project_error()
    try:
        return _quiet(lambda: fuzzyctl.compile(model, block=block, backend=backend))
    except err:
        return None


def _compare(
    path: str,
    got: list[list[Value]] | None,
    ref: list[list[Value]],
    outs: Sequence[str],
    scales: Sequence[float],
    rows: Sequence[Sequence[float]],
    result: DiffResult,
    tol: Callable[[int, int], float] | None = None,
    category: Callable[[int, int], str] | None = None,
) -> bool:
    """Record ``path`` as compared and its first disagreement; True when it agrees."""
    if got is None:
        return True
    result.compared.add(path)
    for k, (g_row, r_row) in enumerate(zip(got, ref, strict=False)):
        for j, (g, r) in enumerate(zip(g_row, r_row, strict=True)):
            t = tol(k, j) if tol else REL_TOL
            if not agree(g, r, scales[j], t):
                cat = category(k, j) if category else f"disagree:{path}"
                diff = abs(g - r) / scales[j] if isinstance(g, float) and isinstance(r, float) else math.nan
                result.findings.append(
                    Finding(
                        cat,
                        f"{outs[j]} at row {list(rows[k])!r}: {path} {g!r}, expected {r!r} "
                        f"({diff:.3g} of the range {scales[j]:.6g})",
                    )
                )
                return False
    return True


def check(model: Any, block: str | None, rng: random.Random, extra: ExtraPaths, n: int = 8) -> DiffResult:
    """Every path against the reference on ``n`` vectors of ``model`` (a Document or a
    FunctionBlock); refusals are compared too."""
    result = DiffResult()
    ref = compile_quiet(model, block, "interpreted")
    if ref is None:
        for backend in ("python", "native"):  # the same refusal: no finding
            if compile_quiet(model, block, backend) is not None:
                result.compared.add(backend)
                result.findings.append(Finding(f"disagree:{backend}", "compiles where the reference refuses"))
        return result
    plan = ref.plan
    names = [s.name for s in plan.inputs]
    outs = [o.name for o in plan.outputs if o.is_output]
    ops = [o for o in plan.outputs if o.is_output]
    if not outs:
        return result
    # the reference interprets rule by rule (2.5 s per evaluation at 5000 rules): a large
    # system gets 2 vectors, so that the paths still fit the fuzzer's time budget
    rows = vectors(plan, rng, n if len(plan.rules) <= LARGE_RULES else 2)
    want = sequential(ref, names, rows, outs)
    scales = [output_scale(op, [r[j] for r in want]) for j, op in enumerate(ops)]
    seen: dict[str, list[list[Value]]] = {}

    def run(path: str, fn: Callable[[], list[list[Value]] | None]) -> None:
        got = _quiet(fn)
        if got is not None:
            seen[path] = got

    py = compile_quiet(model, block, "python")
    if py is None:
        result.compared.add("python")
        result.findings.append(Finding("disagree:python", "refused where the reference compiles"))
    else:
        run("python", lambda: sequential(py, names, rows, outs))
        run("numpy", lambda: _batch(py, names, rows, outs))
    nat = compile_quiet(model, block, "native")
    if nat is not None:
        from fuzzyctl.engine.native import NativeController

        if not isinstance(nat, NativeController):
            result.notes.add("native-fallback")
        run("native", lambda: sequential(nat, names, rows, outs))
        run("native-batch", lambda: _batch(nat, names, rows, outs))
    auto = compile_quiet(model, block, None)
    if auto is not None:
        run("explain", lambda: _explain(auto, names, rows, outs))
    if extra.cli and extra.cli_path is not None:
        cli_path = extra.cli_path
        run("cli-set", lambda: _cli(cli_path, extra.cli_fmt, block, names, rows, outs, data=False))
        if names:  # a CSV cannot carry rows without columns: eval --data refuses it, clearly
            run("cli-data", lambda: _cli(cli_path, extra.cli_fmt, block, names, rows, outs, data=True))
    c_rules = None
    if extra.c:
        c_run = _run_c_path(model, block, plan, names, rows, outs, want, scales)
        if c_run is not None:
            seen["c"], c_rules = c_run[0], c_run[1:]
    expected, odd = _expected(seen, want, scales)
    for path, got in seen.items():
        tol, category = c_rules if path == "c" and c_rules is not None else (None, None)
        _compare(path, got, expected, outs, scales, rows, result, tol, category)
    if sum(p in seen for p in CORE) >= 2:
        result.compared.add("interpreted")
    if odd:
        k, agreed = odd[0]
        result.findings.append(
            Finding(
                "disagree:interpreted",
                f"at row {list(rows[k])!r}: {', '.join(p for p in CORE if p in seen)} agree on {agreed!r}, "
                f"the reference gives {want[k]!r} ({len(odd)} of {len(rows)} rows)",
            )
        )
    return result


#: the in-process paths whose consensus can outvote the reference
CORE = ("python", "numpy", "native", "native-batch")


def _expected(
    seen: dict[str, list[list[Value]]], want: list[list[Value]], scales: Sequence[float]
) -> tuple[list[list[Value]], list[tuple[int, list[Value]]]]:
    """The values every path is held to: the reference's, except on rows where at least two
    in-process paths ran, all disagree with the reference and agree among themselves - there
    the reference is the odd one out and their consensus stands (listed in the second item)."""
    core = [p for p in CORE if p in seen]
    if len(core) < 2:
        return want, []

    def same(a: Sequence[Value], b: Sequence[Value]) -> bool:
        return all(agree(x, y, s) for x, y, s in zip(a, b, scales, strict=True))

    expected, odd = list(want), []
    for k, ref_row in enumerate(want):
        vals = [seen[p][k] for p in core if k < len(seen[p])]
        if (
            len(vals) == len(core)
            and not any(same(v, ref_row) for v in vals)
            and all(same(v, vals[0]) for v in vals)
        ):
            expected[k] = vals[0]
            odd.append((k, vals[0]))
    return expected, odd


def _run_c_path(
    model: Any,
    block: str | None,
    plan: Any,
    names: Sequence[str],
    rows: Sequence[Sequence[float]],
    outs: Sequence[str],
    want: list[list[Value]],
    scales: Sequence[float],
) -> tuple[list[list[Value]], Callable[[int, int], float], Callable[[int, int], str]] | None:
    """The generated C block's outputs, the tolerance per (row, output) - the header's bound
    where it states one, else 1e-9 of the range - and the verdict category."""
    if any(v == REFUSED for r in want for v in r):
        return None  # the C block has no refusal: it runs what it is given
    got = run_c(plan, rows)
    if got is None:
        return None
    values, bounds = got
    fresh = compile_quiet(model, block, "interpreted")

    def tol(k: int, j: int) -> float:
        kk = bounds.get(outs[j])
        if kk is None:
            return REL_TOL
        area = accumulated_area(fresh, names, rows[k], outs[j])
        stated = kk * scales[j] / area if area and area > 0 else math.inf  # K (hi-lo)^2 / area, relative
        return max(REL_TOL, stated)

    def category(k: int, j: int) -> str:
        return "bound:c-header" if outs[j] in bounds else "disagree:c"

    return [list(map(float, r)) for r in values], tol, category
