"""Entry points: model -> Structured Text or C source text."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from fuzzyctl.codegen.defaults import apply_default, parse_default
from fuzzyctl.codegen.rename import Rename, rename_plan
from fuzzyctl.engine.plan import Plan
from fuzzyctl.escape import CodegenError
from fuzzyctl.ir.cost import cost
from fuzzyctl.ir.nodes import Program
from fuzzyctl.ir.programs.plc_block import build_program
from fuzzyctl.ir.render.c import render_c
from fuzzyctl.ir.render.st import render_st
from fuzzyctl.ir.state import Target
from fuzzyctl.kinds import arith as arith_kinds
from fuzzyctl.kinds import targets
from fuzzyctl.model import Document, FunctionBlock

#: A Structured Text dialect's name (:data:`fuzzyctl.kinds.targets.DIALECTS` or an alias).
Dialect = str
#: Every dialect name, aliases last (the registry's).
DIALECTS: tuple[str, ...] = targets.dialect_names()
#: Other names of a dialect: OpenPLC (and Beremiz) compile strict IEC 61131-3 with matiec.
DIALECT_ALIASES = targets.ALIASES


def lower_block(model: Document | FunctionBlock, block: str | None = None, **options: Any) -> Plan:
    """The engine's plan of one function block (``compat=``/option keywords as for
    :func:`fuzzyctl.compile`); raises ``DiagnosticError`` for what the engine refuses."""
    from fuzzyctl.engine.compile import compile_block

    return compile_block(model, block=block, backend="interpreted", **options).plan


def _blocks(model: Document | FunctionBlock, block: str | None) -> list[str | None]:
    if isinstance(model, FunctionBlock) or block is not None:
        return [block]
    return [fb.name for fb in model.blocks]


@dataclass
class Generated:
    """One generated function block: its program, and what the generator changed to express
    it (the rename table, the ``--default`` choice, the quadrature notes of the header)."""

    program: Program
    plan: Plan  # the plan the program computes (``--default`` applied, names renamed)
    renames: list[Rename] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return {
            "block": self.program.name,
            "renames": [r.to_dict() for r in self.renames],
            "notes": list(self.notes),
            "cost": cost(self.program).to_dict(),
        }


def build(plan: Plan, target: Target, default: float | str | None = None) -> Generated:
    """The program of one lowered block for ``target`` with ``--default`` applied and the
    interface renamed where the target needs it (header comment lines say so)."""
    plan, notes = apply_default(plan, parse_default(default))
    plan, renames = rename_plan(plan, target)
    prog = build_program(plan, target)
    extra = [*notes]
    if renames:
        extra.append("renamed for the target (model name -> generated name):")
        extra += [f"  {r.comment()}" for r in renames]
    prog.header[1:1] = extra
    quad = [line for line in prog.header if line.startswith("output ")]  # smooth outputs' notes
    return Generated(prog, plan, renames, notes + quad)


def plans(model: Document | FunctionBlock | Plan, block: str | None = None, **options: Any) -> list[Plan]:
    """The lowered plans of ``model``'s blocks (or of ``block``); a plan is taken as is."""
    if isinstance(model, Plan):
        return [model]
    return [lower_block(model, name, **options) for name in _blocks(model, block)]


def generate_st(
    model: Document | FunctionBlock | Plan,
    *,
    block: str | None = None,
    dialect: str = "codesys",
    lreal: bool = False,
    testbench: int = 0,
    default: float | str | None = None,
    report: list[Generated] | None = None,
    arith: str = arith_kinds.DEFAULT,
    lookup: bool = False,
    **options: Any,
) -> str:
    """Structured Text for every function block of ``model`` (or just ``block``).

    ``dialect`` is ``codesys`` / ``twincat`` (IEC 61131-3 text both accept), ``iec`` (alias
    ``openplc``: strict IEC 61131-3 as matiec, the compiler of OpenPLC and Beremiz, accepts it)
    or ``scl`` (Siemens TIA Portal: ``#`` before block variables, ``REGION``, ``VERSION``); ``lreal``
    computes in LREAL instead of REAL; ``testbench`` > 0 adds after each block a PROGRAM that
    checks it on that many input vectors against the engine (:mod:`fuzzyctl.codegen.testbench`);
    ``default`` (a number or ``"hold"``) replaces ``DEFAULT := nan``.  Names the target cannot
    use are renamed (header comment; ``report`` receives one :class:`Generated` per block).
    ``arith`` chooses the arithmetic (:mod:`fuzzyctl.kinds.arith`).
    ``lookup`` writes each block as a lookup table (:mod:`fuzzyctl.codegen.lookup_st`;
    ``tolerance`` and ``max_bytes`` keywords go to it).
    Raises :class:`CodegenError` naming what cannot be expressed."""
    dialect = targets.dialect(dialect).name  # an alias as its dialect; unknown names refused
    if _type2(model, arith, lookup, default):
        from fuzzyctl.codegen.type2 import generate_st_type2

        assert not isinstance(model, Plan)
        return generate_st_type2(
            model,
            block=block,
            dialect=dialect,
            lreal=lreal,
            testbench=testbench,
            report=report,
            **_samples(options),
        )
    if lookup:  # before check_arith: tables are written in every arithmetic
        from fuzzyctl.codegen.lookup_st import generate_lookup_st

        return generate_lookup_st(
            model,
            block=block,
            dialect=dialect,
            lreal=lreal,
            testbench=testbench,
            arith=arith,
            report=report,
            **options,
        )
    if check_arith(arith):
        from fuzzyctl.codegen.fixed import generate_st_fixed

        return generate_st_fixed(
            model,
            block,
            options,
            arith=arith,
            dialect=dialect,
            default=default,
            report=report,
            testbench=testbench,
        )
    parts = []
    for plan in plans(model, block, **options):
        gen = build(plan, "st", default)
        if report is not None:
            report.append(gen)
        parts.append(render_st(gen.program, dialect=dialect, lreal=lreal))
        if testbench:
            from fuzzyctl.codegen.testbench import choose, render_st_bench

            bench = choose(gen.plan, testbench, single=not lreal)
            parts.append(render_st_bench(bench, dialect=dialect, lreal=lreal))
    return "\n".join(parts)


def generate_c(
    model: Document | FunctionBlock | Plan,
    *,
    block: str | None = None,
    single: bool = False,
    testbench: int = 0,
    default: float | str | None = None,
    report: list[Generated] | None = None,
    arith: str = arith_kinds.DEFAULT,
    lookup: bool = False,
    **options: Any,
) -> dict[str, str]:
    """C99 files (``NAME.h``, ``NAME.c``) for every function block of ``model`` (or just
    ``block``); ``single`` computes in float instead of double; ``testbench`` > 0 adds
    ``NAME_testbench.c`` checking the block on that many input vectors against the engine;
    ``default`` replaces ``DEFAULT := nan`` (without it the C outputs NaN as the engine does);
    ``arith`` chooses the arithmetic (:mod:`fuzzyctl.kinds.arith`); ``lookup`` writes each
    block as a lookup table (:mod:`fuzzyctl.codegen.lookup_c`)."""
    if _type2(model, arith, lookup, default):
        from fuzzyctl.codegen.type2 import generate_c_type2

        assert not isinstance(model, Plan)
        return generate_c_type2(
            model, block=block, single=single, testbench=testbench, report=report, **_samples(options)
        )
    if lookup:  # before check_arith: tables are written in every arithmetic
        from fuzzyctl.codegen.lookup_c import generate_lookup_c

        return generate_lookup_c(
            model, block=block, single=single, testbench=testbench, arith=arith, report=report, **options
        )
    if check_arith(arith):
        from fuzzyctl.codegen.fixed import generate_c_fixed

        return generate_c_fixed(
            model, block, options, arith=arith, default=default, report=report, testbench=testbench
        )
    files: dict[str, str] = {}
    for plan in plans(model, block, **options):
        gen = build(plan, "c", default)
        if report is not None:
            report.append(gen)
        prog = gen.program
        header, source = render_c(prog, single=single)
        h_ext, c_ext = targets.C.extensions
        files[f"{prog.name}{h_ext}"] = header
        files[f"{prog.name}{c_ext}"] = source
        if testbench:
            from fuzzyctl.codegen.testbench import choose, render_c_bench

            bench = choose(gen.plan, testbench, single=single)
            files[f"{prog.name}_testbench.c"] = render_c_bench(bench, single=single)
    return files


def check_arith(arith: str) -> bool:
    """Whether ``arith`` is an integer arithmetic (:mod:`fuzzyctl.codegen.fixed` generates
    it); an unknown name is refused."""
    try:
        return arith_kinds.get(arith).integer
    except ValueError as exc:
        raise CodegenError(str(exc)) from None


def _type2(model: Document | FunctionBlock | Plan, arith: str, lookup: bool, default: object) -> bool:
    """Whether ``model`` is an interval type-2 system (:mod:`fuzzyctl.codegen.type2`
    generates it); the options it does not take are refused."""
    from fuzzyctl.type2 import is_type2

    if isinstance(model, Plan) or not is_type2(model):
        return False
    from fuzzyctl.codegen.type2 import refuse_options

    refuse_options(arith, lookup, default)
    return True


def _samples(options: dict[str, Any]) -> dict[str, Any]:
    """The ``samples`` keyword of the type-2 generators (other engine options do not apply)."""
    return {"samples": int(options["samples"])} if options.get("samples") is not None else {}
