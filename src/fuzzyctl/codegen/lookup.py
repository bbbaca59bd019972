"""``codegen --lookup``: a function block as a lookup table (:mod:`fuzzyctl.engine.table`)
in Structured Text, PLCopen XML or C, in floating point or in integers (``--arith int16`` /
``int32``), with its proven error bound and its size in the header.

The block limits each input to its range, finds its interval by binary search over the
breakpoints, and interpolates multi-linearly (along the last input first).  The integer form
stores every input and output as ``value = stored * scale + offset`` (stored 0..16383 in
int16, 0..2^20 in int32, so that a difference times a difference fits the wide type: DINT /
int32_t, LINT / int64_t) and divides once per input, truncating (under one stored unit each,
counted in the bound).  The test bench feeds the block vectors at random points, the range
ends and the breakpoints, and checks each output against the engine within the stated
bound."""

from __future__ import annotations

import itertools
import math
import random
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from fuzzyctl.engine.controller import Controller
from fuzzyctl.engine.plan import Plan
from fuzzyctl.engine.table import Table, TableError, build_table
from fuzzyctl.ir.state import CodegenError
from fuzzyctl.kinds import arith as arith_kinds
from fuzzyctl.model import Document, FunctionBlock


@dataclass
class LookupReport:
    """What ``codegen --lookup --json`` reports of one block."""

    table: Table
    real: str
    renames: list[Any] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        t = self.table
        out: dict[str, Any] = {
            "block": t.name,
            "lookup": {
                "breakpoints": dict(zip(t.inputs, (len(a) for a in t.axes), strict=True)),
                "bytes": t.size_bytes(self.real),
                "tolerance": t.tolerance,
                "samples": t.samples,
            },
            "outputs": {},
            "renames": [],
            "notes": [],
        }
        for k, name in enumerate(t.outputs):
            out["outputs"][name] = {
                "error_bound": t.bound[k],
                "error_bound_relative": t.relative(t.bound)[k],
                "observed": t.observed[k],
            }
            if t.bits:
                sc, off = t.out_scale[k]
                out["outputs"][name].update(scale=sc, offset=off)
        if t.bits:
            out["inputs"] = {
                n: {"scale": sc, "offset": off} for n, (sc, off) in zip(t.inputs, t.in_scale, strict=True)
            }
        return out


def parse_tolerance(text: str | float) -> float:
    """``--tolerance``: ``"1%"`` or a fraction of the output range (``0.01``)."""
    from fuzzyctl.diagnostics import OptionError

    raw = str(text).strip()
    try:
        value = float(raw[:-1]) / 100.0 if raw.endswith("%") else float(raw)
    except ValueError:
        value = math.nan
    if not 0.0 < value < 1.0:
        raise OptionError(
            f"--tolerance {raw}: give a percentage of the output range (0.1%) or a fraction in (0, 1)",
            "--tolerance",
        )
    return value


def lookup_options(tolerance: str | float | None, max_bytes: int | None) -> dict[str, Any]:
    """The generators' keywords for ``--lookup --tolerance --max-bytes``."""
    out: dict[str, Any] = {"lookup": True}
    if tolerance is not None:
        out["tolerance"] = parse_tolerance(tolerance)
    if max_bytes is not None:
        out["max_bytes"] = max_bytes
    return out


def _fbs(model: Document | FunctionBlock, block: str | None) -> list[FunctionBlock]:
    if isinstance(model, FunctionBlock):
        return [model]
    if block is not None:
        try:
            return [model.block(block)]
        except KeyError as exc:
            raise CodegenError(str(exc.args[0])) from None
    return list(model.blocks)


def tables(
    model: Document | FunctionBlock | Plan,
    *,
    block: str | None,
    real: str,
    arith: str,
    tolerance: float,
    max_bytes: int,
    **options: Any,
) -> list[tuple[Plan, Table]]:
    """Each block's plan and table (:class:`CodegenError` with the reason when one cannot be)."""
    from fuzzyctl.codegen.api import lower_block

    bits = arith_kinds.get(arith).bits
    pairs: list[tuple[Plan, FunctionBlock | None]] = (
        [(model, None)]  # no model: the ranges are the clamps' or the terms'
        if isinstance(model, Plan)
        else [(lower_block(fb, **options), fb) for fb in _fbs(model, block)]
    )
    out = []
    for plan, fb in pairs:
        try:
            table = build_table(
                plan, tolerance=tolerance, max_bytes=max_bytes, bits=bits, real=real, model=fb
            )
        except TableError as exc:
            raise CodegenError(f"--lookup, block {plan.name}: {exc}") from None
        out.append((plan, table))
    return out


def header(table: Table, real: str, comment_target: str) -> list[str]:
    """The header lines: shape, ranges, the bound and how it was proven, the size."""
    shape = " x ".join(f"{n} {name}" for n, name in zip(table.shape, table.inputs, strict=True))
    lines = [
        f"function block {table.name}: a lookup table generated by fuzzyctl ({comment_target})",
        f"breakpoints: {shape}; multi-linear interpolation; inputs limited to their ranges:",
    ]
    lines += [f"  {name} {a[0]:.9g} .. {a[-1]:.9g}" for name, a in zip(table.inputs, table.axes, strict=True)]
    rel = table.relative(table.bound)
    seen = table.relative(table.observed)
    for k, name in enumerate(table.outputs):
        lo, hi = table.out_ranges[k]
        lines.append(
            f"maximum error against the engine: {name} {table.bound[k]:.6g} ({100 * rel[k]:.3g}% of "
            f"{lo:.9g} .. {hi:.9g}); largest seen at {table.samples} samples {100 * seen[k]:.3g}%"
        )
    lines.append("  (proven: the error at sample points plus how far the engine and the table can move")
    lines.append("  between them, and the arithmetic's rounding; docs/codegen.md, lookup tables)")
    lines.append(
        f"table size: {table.size_bytes(real)} bytes ({real if not table.bits else f'int{table.bits}'})"
    )
    if table.bits:
        lines.append("stored integers: value = stored * scale + offset")
        for name, (sc, off) in zip(
            table.inputs + table.outputs, table.in_scale + table.out_scale, strict=True
        ):
            lines.append(f"  {name}: scale {sc!r}, offset {off!r}")
    return lines


# --------------------------------------------------------------------------- the interpolation


def _strides(shape: Sequence[int]) -> list[int]:
    return [math.prod(shape[i + 1 :]) for i in range(len(shape))]


def lerp_text(a: str, b: str, frac: str, width: str | None = None) -> str:
    """The text of ``a`` moved toward ``b`` by ``frac`` (a float fraction), or by ``frac /
    width`` in integers (``width`` given): the product first, so that only the one division
    rounds.  Every target's table interpolation writes its steps with it."""
    if width is not None:
        return f"{a} + (({b} - {a}) * {frac}) / {width}"
    return f"{a} + ({b} - {a}) * {frac}"


def interpolation(
    shape: Sequence[int],
    read: Callable[[int], str],
    lerp: Callable[[str, str, int], str],
    temp: Callable[[str], str],
) -> tuple[list[tuple[str, str]], str]:
    """Assignments ``(temporary, expression)`` reducing the 2^d corners of the cell along the
    last input first, and the final expression; ``read(offset)`` reads the table at the cell
    index plus ``offset``."""
    d = len(shape)
    strides = _strides(shape)
    values = {
        c: read(sum(ci * s for ci, s in zip(c, strides, strict=True)))
        for c in itertools.product((0, 1), repeat=d)
    }
    steps: list[tuple[str, str]] = []
    for axis in range(d - 1, -1, -1):
        reduced = {}
        for prefix in itertools.product((0, 1), repeat=axis):
            expr = lerp(values[(*prefix, 0)], values[(*prefix, 1)], axis)
            if axis == 0:
                reduced[prefix] = expr
            else:
                name = temp("".join(map(str, prefix)) + f"_{axis}")
                steps.append((name, expr))
                reduced[prefix] = name
        values = reduced
    return steps, values[()]


def sample_rows(table: Table, n: int, seed: int = 0) -> list[list[float]]:
    """Test vectors: every corner of the input ranges, the breakpoints, random points."""
    rng = random.Random(seed)
    rows = [list(c) for c in itertools.product(*[(a[0], a[-1]) for a in table.axes])]
    k = 0
    while len(rows) < n and k < max(len(a) for a in table.axes):
        rows.append([float(a[min(k, len(a) - 1)]) for a in table.axes])
        k += 1
    while len(rows) < n:
        rows.append([rng.uniform(a[0], a[-1]) for a in table.axes])
    rows = rows[:n]
    if table.bits:  # the block reads stored integers: the vectors are on their grid
        rows = [
            [off + round((x - off) / sc) * sc for x, (sc, off) in zip(r, table.in_scale, strict=True)]
            for r in rows
        ]
    return rows


def expected(plan: Plan, rows: list[list[float]], single: bool) -> list[list[float]]:
    """The engine's outputs at ``rows`` (rounded to single precision first when the block
    reads REAL)."""
    if single:
        rows = [[float(np.float32(x)) for x in r] for r in rows]
    ctl = Controller(plan)
    cols = {inp.name: np.array([r[i] for r in rows]) for i, inp in enumerate(plan.inputs)}
    out = ctl.evaluate_batch(cols, out_of_range="ignore")
    return [[float(out[o.name][j]) for o in plan.outputs] for j in range(len(rows))]
