"""Interval type-2 function blocks: Structured Text (every dialect), C, PLCopen XML and the
test benches, from the type-2 IR program (:func:`fuzzyctl.ir.programs.type2.build_type2_block`).

Every Mamdani output is sampled at ``samples`` points (default 101, MATLAB's
OutputSampleNumber); the header states it, each output's type-reduction method with its
iteration bound, and the cost per cycle (:mod:`fuzzyctl.ir.cost`, the bound counted).  The
test bench compares the block with ``Type2Controller(fb, samples=N)`` - the same samples,
so the tolerance is the arithmetic's, as for type-1 blocks.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass
from typing import Any, cast

from fuzzyctl.codegen.testbench import TOLERANCE, Bench, render_c_bench, render_st_bench
from fuzzyctl.engine.plan import Plan
from fuzzyctl.escape import CodegenError
from fuzzyctl.ir.builders.type2 import SAMPLES
from fuzzyctl.ir.nodes import Program
from fuzzyctl.ir.render.c import render_c
from fuzzyctl.ir.render.st import STParts, render_st, st_parts
from fuzzyctl.kinds import targets
from fuzzyctl.model import Document, FunctionBlock


def type2_blocks(model: Document | FunctionBlock, block: str | None) -> list[FunctionBlock]:
    if isinstance(model, FunctionBlock):
        return [model]
    return [model.block(block)] if block is not None else list(model.blocks)


def refuse_options(arith: str = "float", lookup: bool = False, default: object = None) -> None:
    """What the type-2 generators do not take (said clearly)."""
    from fuzzyctl.kinds import arith as arith_kinds

    if lookup:
        raise CodegenError("interval type-2 systems: --lookup is not available (generate the block itself)")
    if arith_kinds.get(arith).integer:
        raise CodegenError(
            f"interval type-2 systems: --arith {arith} is not available (REAL/LREAL/float/double)"
        )
    if default is not None:
        raise CodegenError(
            "interval type-2 systems: --default is not available (the outputs' DEFAULT is used)"
        )


@dataclass
class Type2Generated:
    """One generated type-2 block (for ``codegen --json``: the name, notes and cost)."""

    program: Program
    notes: list[str]

    @property
    def renames(self) -> list[Any]:
        """What was renamed for the target: nothing (``codegen -o`` prints this list)."""
        return []

    def to_dict(self) -> dict[str, Any]:
        from fuzzyctl.ir.cost import cost

        return {
            "block": self.program.name,
            "renames": self.renames,
            "notes": list(self.notes),
            "cost": cost(self.program).to_dict(),
        }


def program(fb: FunctionBlock, target: str, samples: int, report: list[Any] | None) -> Program:
    from fuzzyctl.engine.type2 import Type2Controller
    from fuzzyctl.ir.programs.type2 import build_type2_block

    Type2Controller(fb)  # the engine's checks (lower <= upper, supported features)
    prog = build_type2_block(fb, target, samples).fast.program
    if report is not None:
        report.append(Type2Generated(prog, [line for line in prog.header if line.startswith("output ")]))
    return prog


def generate_st_type2(
    model: Document | FunctionBlock,
    *,
    block: str | None = None,
    dialect: str = "codesys",
    lreal: bool = False,
    testbench: int = 0,
    report: list[Any] | None = None,
    samples: int = SAMPLES,
) -> str:
    parts = []
    for fb in type2_blocks(model, block):
        parts.append(render_st(program(fb, "st", samples, report), dialect=dialect, lreal=lreal))
        if testbench:
            parts.append(
                render_st_bench(
                    choose(fb, testbench, samples, single=not lreal), dialect=dialect, lreal=lreal
                )
            )
    return "\n".join(parts)


def st_blocks_type2(
    model: Document | FunctionBlock, block: str | None, dialect: str, lreal: bool, samples: int = SAMPLES
) -> list[STParts]:
    """The blocks :func:`generate_st_type2` prints, as parts (PLCopen XML)."""
    return [
        st_parts(program(fb, "st", samples, None), dialect=dialect, lreal=lreal)
        for fb in type2_blocks(model, block)
    ]


def generate_c_type2(
    model: Document | FunctionBlock,
    *,
    block: str | None = None,
    single: bool = False,
    testbench: int = 0,
    report: list[Any] | None = None,
    samples: int = SAMPLES,
) -> dict[str, str]:
    files: dict[str, str] = {}
    h_ext, c_ext = targets.C.extensions
    for fb in type2_blocks(model, block):
        prog = program(fb, "c", samples, report)
        header, source = render_c(prog, single=single)
        files[f"{prog.name}{h_ext}"] = header
        files[f"{prog.name}{c_ext}"] = source
        if testbench:
            files[f"{prog.name}_testbench.c"] = render_c_bench(
                choose(fb, testbench, samples, single=single), single=single
            )
    return files


# --------------------------------------------------------------------------- test bench


@dataclass(frozen=True)
class _Var:
    name: str
    is_output: bool = True
    kind: str = "mamdani"


@dataclass(frozen=True)
class _BenchPlan:
    """What the test bench renderers read of a plan."""

    name: str
    inputs: tuple[_Var, ...]
    outputs: tuple[_Var, ...]
    rules: tuple[object, ...]


def choose(fb: FunctionBlock, n: int, samples: int, *, single: bool, seed: int = 0) -> Bench:
    """``n`` input vectors for ``fb`` (the ends of every input's range, then random points
    of the ranges) and what ``Type2Controller(fb, samples=N)`` gives for them.  Vectors
    where the output moves by more than half the tolerance across a few roundings of the
    inputs are left out (a correct REAL block passes, a wrong one fails)."""
    from fuzzyctl.engine.type2 import Type2Controller

    if n < 1:
        raise CodegenError("the test bench needs at least 1 input vector")
    eng = Type2Controller(fb, samples=samples)
    rng = random.Random(seed)
    names = [v.name for v in fb.inputs]
    bounds = [eng.input_ranges.get(nm, (0.0, 1.0)) for nm in names]
    rel = TOLERANCE["REAL" if single else "LREAL"]
    spans = [(d.range.high - d.range.low) if d.range else 1.0 for d in fb.defuzzify]

    def cast_row(row: list[float]) -> list[float]:
        if not single:
            return row
        import numpy as np

        return [float(np.float32(v)) for v in row]

    def run(row: list[float]) -> tuple[list[float], int]:
        ex = eng.explain(dict(zip(names, row, strict=True)), out_of_range="ignore")
        quiet = any(math.isnan(o.yl) for o in ex.outputs)
        return [o.value for o in ex.outputs], 2 if quiet else 0

    step = 1e-6 if single else 1e-12

    def stable(row: list[float]) -> bool:
        base, info = run(row)
        if not all(math.isfinite(v) for v in base):
            return False
        for i, (lo, hi) in enumerate(bounds):
            for sign in (-1.0, 1.0):
                moved = list(row)
                moved[i] += sign * step * max(hi - lo, abs(row[i]))
                got, info2 = run(moved)
                if info2 != info or any(
                    abs(a - b) > 0.5 * rel * s for a, b, s in zip(got, base, spans, strict=True)
                ):
                    return False
        return True

    mid = [(lo + hi) / 2 for lo, hi in bounds]
    cands: list[tuple[list[float], str]] = []
    for i, (lo, hi) in enumerate(bounds):
        for end, label in ((lo, "low"), (hi, "high")):
            cands.append((cast_row([*mid[:i], end, *mid[i + 1 :]]), f"{names[i]} at the {label} end"))
    cands += [(cast_row([rng.uniform(lo, hi) for lo, hi in bounds]), "random") for _ in range(max(4 * n, 40))]
    picked: list[tuple[list[float], str]] = []
    for row, why in cands:
        if len(picked) >= n:
            break
        if stable(row):
            picked.append((row, why))
    rows = [p[0] for p in picked]
    results = [run(r) for r in rows]
    plan = _BenchPlan(
        fb.name or "FUZZY",
        tuple(_Var(v) for v in names),
        tuple(_Var(d.variable) for d in fb.defuzzify),
        tuple(fb.rules()),
    )
    return Bench(
        cast(Plan, plan),
        rows,
        [p[1] for p in picked],
        [r[0] for r in results],
        [r[1] for r in results],
        [rel * s for s in spans],
        rel,
        0,
    )
