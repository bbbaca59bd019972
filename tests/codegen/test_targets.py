"""The code-generation targets registry (:mod:`fuzzyctl.kinds.targets`): every record is
complete, the CLI's choices are the registry's, and each renderer is driven by its record - a
record with another comment syntax or number format changes exactly that in the output, and
the code still computes the same (compiled C and exec'd Python compared bit for bit)."""

from __future__ import annotations

import ctypes
import dataclasses
import math
import re
import shutil
import subprocess
from pathlib import Path
from types import MappingProxyType, SimpleNamespace
from typing import Any

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.codegen.api import build, generate_st, lower_block
from fuzzyctl.escape import CodegenError, c_comment, st_comment
from fuzzyctl.ir.nodes import Program
from fuzzyctl.ir.programs.evaluator import build_fast
from fuzzyctl.ir.programs.plc_block import build_program
from fuzzyctl.ir.render.c import render_c
from fuzzyctl.ir.render.pysrc import PythonPrinter, render_py
from fuzzyctl.ir.render.st import render_st
from fuzzyctl.kinds import targets
from fuzzyctl.kinds.targets import Comments, incomplete, st_real
from tests.codegen import systems as S

SRC = Path(__file__).resolve().parents[2] / "src" / "fuzzyctl"
ALL_RECORDS = {**{f"target {k}": t for k, t in targets.TARGETS.items()}, **targets.DIALECTS}


# --------------------------------------------------------------------------- the registry


@pytest.mark.parametrize("name", sorted(ALL_RECORDS))
def test_every_record_is_complete(name: str) -> None:
    assert incomplete(ALL_RECORDS[name]) == []


def test_an_incomplete_record_is_reported() -> None:
    st = targets.ST
    cases: list[tuple[targets.Target, str]] = [
        (dataclasses.replace(st, label=""), "label is empty"),
        (dataclasses.replace(st, functions=MappingProxyType({"LN": "LN", "SQRT": "SQRT"})), "lack ABS, EXP"),
        (dataclasses.replace(st, to_real="INT_TO_REAL"), "to_real"),
        (dataclasses.replace(st, operators=MappingProxyType({"=": "="})), "operators lack <>"),
        (dataclasses.replace(st, comments=Comments("(* ", " *)", lambda s: s)), "closing delimiter"),
        (
            dataclasses.replace(st, identifiers=targets.Identifiers(lambda n, w: n, frozenset({"IF"}), 24)),
            "accepts the reserved word IF",
        ),
        (dataclasses.replace(st, extensions=("st",)), "extensions"),
        (dataclasses.replace(st, generator=""), "generator"),
        (dataclasses.replace(st, cli_options=frozenset({"colour"})), "cli_options"),
        (dataclasses.replace(st, language="cobol"), "no builder target"),
    ]
    for record, problem in cases:
        found = incomplete(record)
        assert any(problem in p for p in found), (problem, found)


def test_lookups_refuse_unknown_names() -> None:
    with pytest.raises(CodegenError, match="unknown dialect 'beckhoff'"):
        targets.dialect("beckhoff")
    with pytest.raises(CodegenError, match="unknown code generation target"):
        targets.get("cobol")
    assert targets.dialect("openplc") is targets.DIALECTS["iec"]  # an alias is its dialect


def test_the_cli_choices_are_the_registry(capsys: pytest.CaptureFixture[str]) -> None:
    from fuzzyctl.cli.app import main
    from fuzzyctl.cli.codegen import Dialect, Lang, generator_of

    assert [m.value for m in Lang] == list(targets.cli_choices()) == ["st", "plcopen", "c", "fmu"]
    assert [m.value for m in Dialect] == list(targets.dialect_names())
    for choice in targets.cli_choices():
        assert callable(generator_of(targets.cli_target(choice)))
    assert main(["codegen", "--help"]) == 0
    shown = re.sub(r"[\s│]+", " ", capsys.readouterr().out)
    for record in targets.TARGETS.values():
        if record.cli is not None:
            assert f"{record.cli}: {record.cli_help}" in shown


def test_options_a_target_does_not_take_are_refused(capsys: pytest.CaptureFixture[str]) -> None:
    """What each record's ``cli_options`` leaves out is a usage error naming the option."""
    from fuzzyctl.cli.app import main

    fig7 = str(S.EXAMPLES / "figure7.fcl")
    for choice in targets.cli_choices():
        record = targets.cli_target(choice)
        for option, argv in (
            ("dialect", ["--dialect", "twincat"]),
            ("lreal", ["--lreal"]),
            ("float", ["--float"]),
        ):
            if option in record.cli_options:
                continue
            assert main(["codegen", fig7, "--lang", choice, *argv]) == 2
            assert f"--{option}" in capsys.readouterr().err


# --------------------------------------------------------------------------- the builders read the record


def test_a_target_without_pow_gets_exp_of_ln(monkeypatch: pytest.MonkeyPatch) -> None:
    """The bell shape's power is POW where the record has it, EXP(y * LN(x)) where not."""
    plan = lower_block(fuzzyctl.load(S.DATA / "fuzzylite/mamdani/AllTerms.fcl"))
    assert "POW" in build_program(plan, "c").uses
    no_pow = dataclasses.replace(
        targets.C, functions=MappingProxyType({k: v for k, v in targets.C.functions.items() if k != "POW"})
    )
    real_get = targets.get
    monkeypatch.setattr(targets, "get", lambda name: no_pow if name == "c" else real_get(name))
    uses = build_program(plan, "c").uses
    assert "POW" not in uses and {"EXP", "LN"} <= uses


def test_a_target_without_nan_refuses_default_nan() -> None:
    doc = fuzzyctl.load(S.DATA / "fuzzylite/mamdani/AllTerms.fcl")
    assert targets.ST.numbers.nan is None and targets.C.numbers.nan is not None
    with pytest.raises(CodegenError, match="has no NaN"):
        generate_st(doc)


# --------------------------------------------------------------------------- renderers follow the record

# a REAL literal as ST and C print it (not part of an identifier, not an array bound)
_ST_REAL = re.compile(r"(?<![\w#.])(-?\d+\.\d+(?:E[+-]?\d+)?)")


def test_st_renderer_follows_the_dialect_record() -> None:
    """A dialect record with C++ comments and typed literals (``REAL#1.5``, IEC 61131-3):
    the text is the codesys text with exactly those two things changed."""
    codesys = targets.DIALECTS["codesys"]
    fake = dataclasses.replace(
        codesys,
        name="fake",
        comments=Comments("// ", "", st_comment),
        numbers=dataclasses.replace(codesys.numbers, real=lambda v: f"REAL#{st_real(v)}"),
    )
    for path in S.example_files():
        plan = lower_block(fuzzyctl.load(path))
        prog = build_program(plan, "st")
        want = render_st(prog, dialect="codesys")
        got = render_st(prog, dialect=fake)
        assert "(*" not in got and "// dialect: fake; arithmetic in REAL" in got
        expected = _ST_REAL.sub(r"REAL#\1", re.sub(r"\(\* (.*?) \*\)$", r"// \1", want, flags=re.M))
        assert got == expected.replace("dialect: codesys", "dialect: fake"), path.name


def _cc() -> str:
    cc = shutil.which("cc")
    if cc is None:
        pytest.fail("the C tests need the system compiler 'cc'")
    return cc


def _run_c(name: str, header: str, source: str, rows: np.ndarray, n_out: int, where: Path) -> np.ndarray:
    (where / f"{name}.h").write_text(header)
    (where / f"{name}.c").write_text(source + f"\nsize_t {name}_size(void) {{ return sizeof({name}); }}\n")
    lib = where / f"{name}.so"
    cmd = [_cc(), "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O1", "-ffp-contract=off"]
    res = subprocess.run(
        [*cmd, "-fPIC", "-shared", "-o", str(lib), str(where / f"{name}.c"), "-lm"],
        text=True,
        capture_output=True,
    )
    assert res.returncode == 0, res.stderr[:3000]
    so = ctypes.CDLL(str(lib))
    so[f"{name}_size"].restype = ctypes.c_size_t
    fb = ctypes.create_string_buffer(so[f"{name}_size"]())
    so[f"{name}_init"](fb)
    data = np.ascontiguousarray(rows, dtype=np.float64)
    out = np.zeros((len(rows), n_out))
    ptr = ctypes.POINTER(ctypes.c_double)
    so[f"{name}_batch"](fb, ctypes.c_size_t(len(rows)), data.ctypes.data_as(ptr), out.ctypes.data_as(ptr))
    return out


def test_c_renderer_follows_its_record(tmp_path: Path) -> None:
    """A C record with ``//`` comments and hexadecimal float literals (C99): every comment
    and REAL literal of the block follows it, and the compiled block computes bit for bit
    what the decimal build computes."""
    fake = dataclasses.replace(
        targets.C,
        comments=Comments("// ", "", c_comment),
        numbers=dataclasses.replace(targets.C.numbers, real=float.hex),
    )
    plan = S.plan_of(S.EXAMPLES / "figure7.fcl")
    prog = build_program(plan, "c")
    header, source = render_c(prog)
    fh, fs = render_c(prog, target=fake)
    assert header.splitlines()[0].startswith("/* ") and fh.splitlines()[0].startswith("// ")
    assert "/*" not in fh and "0x1." in fs and not _ST_REAL.search(fs.split("void ")[1])
    rows = S.random_inputs(plan, 500, seed=3)
    n_out = sum(1 for o in plan.outputs if o.is_output)
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    want = _run_c(prog.name, header, source, rows, n_out, tmp_path / "a")
    got = _run_c(prog.name, fh, fs, rows, n_out, tmp_path / "b")
    assert np.array_equal(got, want, equal_nan=True)


def test_python_renderer_follows_its_record() -> None:
    """A Python record writing literals as ``float.fromhex(...)``: the source changes, the
    function computes the same values bit for bit."""
    fake = dataclasses.replace(
        targets.PY,
        numbers=dataclasses.replace(targets.PY.numbers, real=lambda v: f"float.fromhex({float.hex(v)!r})"),
    )

    def function(caps: targets.Target, fp: Any) -> tuple[str, Any]:
        src, env = render_py(fp, caps)
        exec(compile(src, "<test>", "exec"), env)
        return src, env["_fast"]

    for path in [*S.example_files()[:4], S.DATA / "fuzzylite/mamdani/AllTerms.fcl"]:
        plan = S.plan_of(path)
        fp = build_fast(plan, "py")
        src, fn = function(targets.PY, fp)
        fsrc, ffn = function(fake, fp)
        assert "float.fromhex(" in fsrc and "float.fromhex(" not in src
        for row in S.random_inputs(plan, 200, seed=5):
            a, b = fn(list(row), [None] * 8), ffn(list(row), [None] * 8)
            assert [x if not math.isnan(x) else "nan" for x in a] == [
                x if not math.isnan(x) else "nan" for x in b
            ], path.name


# --------------------------------------------------------------------------- no name comparisons

_NAMES = "|".join(sorted({*targets.TARGETS, *targets.dialect_names()}))
_COMPARE = re.compile(
    rf"""(==|!=|\bis|\bin|not in)\s*\(?\s*["']({_NAMES})["']|["']({_NAMES})["']\s*(==|!=)"""
)


def test_no_target_name_is_compared_outside_the_registry() -> None:
    """Code switches on the record, not on a target or dialect name (``target == "st"``)."""
    places = [SRC / "engine", SRC / "codegen", SRC / "cli" / "codegen.py", SRC / "escape.py"]
    found = []
    for place in places:
        for path in [place] if place.is_file() else sorted(place.rglob("*.py")):
            for n, line in enumerate(path.read_text().splitlines(), 1):
                if _COMPARE.search(line.split("#")[0]):
                    found.append(f"{path.relative_to(SRC)}:{n}: {line.strip()}")
    assert found == []


# --------------------------------------------------------------------------- a new target


class _BlockPrinter(PythonPrinter):
    """A toy target's renderer: the PLC function block as a Python function ``step(fb)``
    whose instance variables are attributes of ``fb`` (the temporaries are locals)."""

    def __init__(self, caps: targets.Target, prog: Program) -> None:
        super().__init__(caps)
        self.fields = {d.name for d in prog.decls if d.storage != "temp"}

    def name(self, n: str) -> str:
        return f"fb.{n}" if n in self.fields else n


def _render_block(caps: targets.Target, prog: Program) -> str:
    r = _BlockPrinter(caps, prog)
    r.block(prog.body, 1)
    temps = [f"    {d.name} = {f'[0] * {d.size}' if d.size is not None else '0'}" for d in prog.of("temp")]
    return "def step(fb):\n" + "\n".join(temps + r.lines) + "\n"


def test_a_new_target_is_a_record_and_a_renderer(monkeypatch: pytest.MonkeyPatch) -> None:
    """A target the registry did not know - the PLC block as Python - needs its record and a
    renderer (a Printer subclass) and nothing else: the program builder, the renaming and the
    CLI's choices read the record, and the block computes what the engine computes."""
    toy = dataclasses.replace(
        targets.PY,
        name="pyblock",
        language="pyblock",
        kernels=frozenset(),  # the PLC block calls none
        function_terms=True,
        data_dependent_loops=True,
        cli="pyblock",
        cli_help="the block as Python",
        generator="tests.codegen.test_targets:_render_block",
    )
    monkeypatch.setattr(targets, "TARGETS", MappingProxyType({**targets.TARGETS, "pyblock": toy}))
    assert incomplete(toy) == [] and targets.cli_target("pyblock") is toy
    assert "pyblock" in targets.cli_choices()
    for path in S.example_files():
        plan = S.plan_of(path)
        gen = build(plan, "pyblock", default="0")
        prog = gen.program
        env: dict[str, Any] = {"_m": math, "_NAN": math.nan, "_INF": math.inf}
        exec(compile(_render_block(toy, prog), f"<pyblock {path.name}>", "exec"), env)
        fb = SimpleNamespace()
        for d in prog.decls:  # as C and ST initialise them: INT as integers
            kind = {"REAL": float, "BOOL": bool}.get(d.type, int)
            value = d.init if d.init is not None else (0 if d.size is None else (0,) * d.size)
            setattr(fb, d.name, [kind(v) for v in value] if isinstance(value, tuple) else kind(value))
        ins = [d.name for d in prog.of("input") if d.name != "ENABLE"]
        outs = [d.name for d in prog.of("output") if d.name != "INFO"]
        data = S.random_inputs(gen.plan, 300, seed=11)
        got = []
        for row in data:
            for name, x in zip(ins, row, strict=True):
                setattr(fb, name, float(x))
            env["step"](fb)
            got.append([getattr(fb, o) for o in outs])
        want = S.reference(gen.plan, data, "scalar")
        assert S.max_error(gen.plan, np.array(got, dtype=float).reshape(want.shape), want) < 1e-9, path.name
