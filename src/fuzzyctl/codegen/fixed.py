"""``codegen --arith int16|int32``: Structured Text and C in fixed point
(:mod:`fuzzyctl.ir.programs.fixed_block`), with the ``--json`` report of every input's and
output's type, ``scale`` and ``offset`` (``value = stored * scale + offset``) and every
output's ``error_bound``."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from fuzzyctl.codegen.defaults import apply_default, parse_default
from fuzzyctl.codegen.rename import Rename, rename_plan
from fuzzyctl.engine.plan import Plan
from fuzzyctl.escape import CodegenError
from fuzzyctl.ir.builders.fixed_smooth import parse_term_tolerance
from fuzzyctl.ir.cost import Cost, stmts
from fuzzyctl.ir.programs.fixed_block import FixedProgram, build_fixed
from fuzzyctl.ir.render.fixed import fixed_st_parts, render_fixed_c, render_fixed_st
from fuzzyctl.ir.render.st import STParts
from fuzzyctl.kinds import arith as arith_kinds
from fuzzyctl.kinds import targets
from fuzzyctl.model import Document, FunctionBlock

__all__ = ["FixedGenerated", "build_fixed_block", "fixed_cost", "generate_c_fixed", "generate_st_fixed"]


@dataclass
class FixedGenerated:
    """One integer block and what the generator changed to express it."""

    program: FixedProgram
    plan: Plan
    lang: str  # st or c: the type names of the report
    renames: list[Rename] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        prog = self.program
        type_name = prog.arith.types[self.lang]
        return {
            "block": prog.name,
            "arith": prog.arith.name,
            "renames": [r.to_dict() for r in self.renames],
            "notes": list(self.notes),
            "inputs": [p.to_dict(type_name, False) for p in prog.inputs],
            "outputs": [p.to_dict(type_name, True) for p in prog.outputs],
            "approximated_terms": list(prog.approximations),
            "cost": fixed_cost(prog).to_dict(),
        }


def fixed_cost(prog: FixedProgram) -> Cost:
    """The usual and worst cost of one cycle of the integer block (:mod:`fuzzyctl.ir.cost`)."""
    return prog.cost or Cost(stmts(prog.body, True), stmts(prog.body, False))


def input_ranges(model: Document | FunctionBlock | Plan, plan: Plan) -> dict[str, tuple[float, float]]:
    """Each input's range as the engine takes it: the declared RANGE, else its terms' span."""
    from fuzzyctl.engine.ranges import declared_ranges
    from fuzzyctl.engine.variables import inputs_of

    if isinstance(model, Plan):
        fb = None
    elif isinstance(model, FunctionBlock):
        fb = model
    else:
        fb = model.block(plan.name)
    return declared_ranges(dict(inputs_of(plan, fb).items()))


def _plans(model: Document | FunctionBlock | Plan, block: str | None, options: dict[str, Any]) -> list[Plan]:
    from fuzzyctl.codegen.api import plans

    return plans(model, block, **options)


def build_fixed_block(
    plan: Plan,
    target: str,
    arith: str,
    default: float | str | None = None,
    int_output: str = "scaled",
    ranges: dict[str, tuple[float, float]] | None = None,
    term_tolerance: float | None = None,
) -> FixedGenerated:
    if default == "hold":
        raise CodegenError("--default hold is not generated in integer arithmetic: give a number")
    plan, notes = apply_default(plan, parse_default(default))
    plan, renames = rename_plan(plan, target)
    renamed = {r.original: r.name for r in renames if r.kind == "input"}
    ranges = {renamed.get(k, k): v for k, v in (ranges or {}).items()}
    prog = build_fixed(plan, arith_kinds.get(arith), int_output, ranges, term_tolerance)
    if renames:
        prog.header[1:1] = ["renamed for the target (model name -> generated name):"] + [
            f"  {r.comment()}" for r in renames
        ]
    prog.header[1:1] = notes
    prog.header += fixed_cost(prog).header()
    return FixedGenerated(prog, plan, target, renames, notes)


def generate_st_fixed(
    model: Document | FunctionBlock | Plan,
    block: str | None,
    options: dict[str, Any],
    *,
    arith: str,
    dialect: str,
    default: float | str | None = None,
    report: list[Any] | None = None,
    testbench: int = 0,
    int_output: str = "scaled",
) -> str:
    """The integer blocks as Structured Text (``int_output``: ``scaled``, each output stored
    with the finest power-of-ten scale that holds it, or ``unit``, in its own unit; also read
    from ``options``)."""
    options = dict(options)
    int_output = options.pop("int_output", int_output)
    tol = parse_term_tolerance(options.pop("term_tolerance", None))
    parts = []
    for plan in _plans(model, block, options):
        gen = build_fixed_block(plan, "st", arith, default, int_output, input_ranges(model, plan), tol)
        if report is not None:
            report.append(gen)
        parts.append(render_fixed_st(gen.program, dialect))
        if testbench:
            from fuzzyctl.codegen.fixed_bench import choose_fixed, render_fixed_st_bench

            parts.append(render_fixed_st_bench(choose_fixed(gen, testbench), dialect))
    return "\n".join(parts)


def fixed_st_blocks(
    model: Document | FunctionBlock | Plan,
    block: str | None,
    options: dict[str, Any],
    *,
    arith: str,
    dialect: str,
    int_output: str = "scaled",
) -> list[STParts]:
    """The integer blocks :func:`generate_st_fixed` prints, as parts (for PLCopen XML)."""
    options = dict(options)
    int_output = options.pop("int_output", int_output)
    tol = parse_term_tolerance(options.pop("term_tolerance", None))
    default = options.pop("default", None)
    out = []
    for plan in _plans(model, block, options):
        gen = build_fixed_block(plan, "st", arith, default, int_output, input_ranges(model, plan), tol)
        out.append(fixed_st_parts(gen.program, dialect))
    return out


def generate_c_fixed(
    model: Document | FunctionBlock | Plan,
    block: str | None,
    options: dict[str, Any],
    *,
    arith: str,
    default: float | str | None = None,
    report: list[Any] | None = None,
    testbench: int = 0,
    int_output: str = "scaled",
) -> dict[str, str]:
    """The integer blocks as C files (``NAME.h``, ``NAME.c``, ``NAME_testbench.c``)."""
    options = dict(options)
    int_output = options.pop("int_output", int_output)
    tol = parse_term_tolerance(options.pop("term_tolerance", None))
    files: dict[str, str] = {}
    for plan in _plans(model, block, options):
        gen = build_fixed_block(plan, "c", arith, default, int_output, input_ranges(model, plan), tol)
        if report is not None:
            report.append(gen)
        header, source = render_fixed_c(gen.program)
        h_ext, c_ext = targets.C.extensions
        files[f"{gen.program.name}{h_ext}"] = header
        files[f"{gen.program.name}{c_ext}"] = source
        if testbench:
            from fuzzyctl.codegen.fixed_bench import choose_fixed, render_fixed_c_bench

            files[f"{gen.program.name}_testbench.c"] = render_fixed_c_bench(choose_fixed(gen, testbench))
    return files
