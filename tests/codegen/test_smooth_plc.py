"""CoA, LM, RM and MoM of smooth outputs in the generated PLC block (ST, C, PLCopen): the
IR of the native evaluator (ir/builders/smooth_methods.py) rendered for every target.

Checked against the reference interpreter and an independent brute force
(tests/engine/bruteforce.py) on seeded random smooth systems (tests/engine/opsweep.py: every
activation and accumulation, Gaussian and bell terms) and on a fixed one:

* CoA within 1e-9 of the range (the header's bound: the half-area tolerance over the set's
  height at the bisector);
* LM, RM, MoM within 1e-9 of the range, or, where the maximum is a smooth peak, within the
  stretch where the set is within 1e-12 of its top (brute force on a fine grid): the maximum
  is defined only to that stretch (docs/engine.md); LM and RM answer a point of the set at
  its top to 1e-10;
* compiled by gcc ``-Wall -Wextra -Werror -pedantic`` and by matiec (REAL and LREAL), the
  generated test bench PASSes and FAILs when an expected value is changed, PLCopen XML is
  valid against the schema.
"""

from __future__ import annotations

import ctypes
import dataclasses
import re
import warnings
from functools import cache
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.codegen import generate_c, generate_plcopen, generate_st
from fuzzyctl.codegen.api import Generated
from fuzzyctl.engine.plan import Plan
from fuzzyctl.kinds.methods import METHODS
from fuzzyctl.model import FunctionBlock
from tests.codegen import matiec as M
from tests.codegen import systems as S
from tests.codegen.test_c import build_library, run
from tests.codegen.test_matiec import compile_all, expected_info
from tests.codegen.test_plcopen import valid
from tests.codegen.test_realsys import SMOOTH_FCL, _st_outputs
from tests.codegen.test_testbench import _run_bench
from tests.engine import bruteforce, opsweep

METHODS_SWEPT = ("COA", "LM", "RM", "MOM")
SEEDS = (1, 2)
ROWS = 8
GRID = 400_001  # brute-force grid of the near-top stretch (step 2.5e-5 of the range)


@cache
def sweep(seed: int) -> tuple[FunctionBlock, Plan]:
    """Nine outputs (every activation and accumulation appears), methods in turn."""
    fb = opsweep.system(seed, True, opsweep.some_pairs(seed), methods=METHODS_SWEPT)
    plan = fuzzyctl.compile(fb, backend="interpreted").plan
    return fb, dataclasses.replace(plan, name=f"smooth_sweep{seed}")


@cache
def rows_and_reference(seed: int, n: int = ROWS, single: bool = False) -> tuple[np.ndarray, np.ndarray]:
    _fb, plan = sweep(seed)
    data = S.random_inputs(plan, n, seed=11 + seed, single=single)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # inputs a little beyond the terms' hull: intended
        return data, S.reference(plan, data, "scalar")


def _near_top(
    fb: FunctionBlock, row: dict[str, float], out: str, lo: float, hi: float
) -> tuple[float, float]:
    """(width of the stretch where the brute-force set is within 1e-12 of its top, the top)."""
    f, _n = bruteforce.accumulated(fb, row, out)
    u = np.linspace(lo, hi, GRID)
    fu = f(u)
    top = float(fu.max())
    near = u[fu >= top * (1.0 - 1e-12)]
    return float(near.max() - near.min()) if near.size else 0.0, top


def check(
    fb: FunctionBlock, plan: Plan, data: np.ndarray, got: np.ndarray, want: np.ndarray, tol: float
) -> None:
    """Every smooth output of ``plan`` against the reference, as the module docstring says."""
    names = [i.name for i in plan.inputs]
    outs = [op for op in plan.outputs if op.is_output]
    for k, op in enumerate(outs):
        assert op.kind == "mamdani" and (op.exact or op.method in METHODS_SWEPT)
        assert op.low is not None and op.high is not None
        span = op.high - op.low
        for i in range(len(data)):
            g, w = float(got[i, k]), float(want[i, k])
            if np.isnan(w) or g == w:
                assert np.isnan(g) == np.isnan(w), (op.name, i, g, w)
                continue
            err = abs(g - w)
            if err <= tol * span:
                continue
            entry = METHODS[op.method]
            assert entry.maximum is not None and not op.exact, (op.name, op.method, i, g, w, err / span)
            row = dict(zip(names, map(float, data[i]), strict=True))
            width, top = _near_top(fb, row, op.name, op.low, op.high)
            step = span / (GRID - 1)
            assert err <= width + 2 * step, (op.name, op.method, i, g, w, width)
            if entry.maximum in ("left", "right"):
                f, _n = bruteforce.accumulated(fb, row, op.name)
                assert float(f(np.array([g]))[0]) >= top * (1.0 - 1e-10), (op.name, i, g)


# --------------------------------------------------------------------------- C (gcc strict)


@pytest.mark.parametrize("seed", SEEDS)
def test_c_every_method_of_smooth_sets_agrees_with_the_reference(seed: int, tmp_path: Path) -> None:
    fb, plan = sweep(seed)
    lib = build_library([plan], tmp_path)  # cc -std=c99 -Wall -Wextra -Werror -pedantic
    data, want = rows_and_reference(seed)
    check(fb, plan, data, run(lib, plan, data), want, 1e-9)


def test_c_header_states_each_methods_bound() -> None:
    _fb, plan = sweep(1)
    report: list[Generated] = []
    src = "".join(generate_c(plan, report=report).values())
    notes = report[0].notes
    for op in (o for o in plan.outputs if o.is_output and not o.exact):
        lines = [n for n in notes if n.startswith(f"output {op.name}: ")]
        assert lines and all(f"/* {n} */" in src for n in lines)  # whole: none cut short
        text = " ".join(lines)
        assert f"smooth set, {op.method} on the panels" in text
        if METHODS[op.method].bisects:
            assert "|CoA error| <= (1e-09 x area" in text
        else:
            assert "within 1e-14 relative of the top count as the top" in text
    assert "cost per cycle, worst case" in src


# --------------------------------------------------------------------------- ST


@pytest.mark.parametrize("method", METHODS_SWEPT)
def test_st_lreal_every_method_on_a_fixed_smooth_system(method: str) -> None:
    """ST run by the test's ST interpreter (LREAL), a clipped (MIN) and an unclipped (PROD)
    smooth set of Gaussian, bell and sigmoid terms."""
    for act in ("MIN", "PROD"):
        text = SMOOTH_FCL.format(accu="MAX", act=act).replace("METHOD : COG", f"METHOD : {method}")
        fb = fuzzyctl.load(text).blocks[0]
        plan = fuzzyctl.compile(fb, backend="interpreted").plan
        st = generate_st(plan, lreal=True)
        data = S.random_inputs(plan, 2, seed=5)
        want = S.reference(plan, data, "scalar")
        got = _st_outputs(st, plan, data, ["x", "y"])
        check(fb, plan, data, got, want, 1e-9)


@pytest.mark.extra("matiec")
@pytest.mark.parametrize("real", ["LREAL", "REAL"])
def test_matiec_every_method_of_smooth_sets(real: str, tmp_path: Path) -> None:
    """matiec-compiled ST against the reference: LREAL as the C, REAL within 1e-4 of the range
    (or the near-top stretch); INFO as the engine says (never 16#04 here)."""
    matiec = M.build()
    fb, plan = sweep(1)
    c = compile_all(matiec, tmp_path, [("sweep/1", plan)], real)
    single = real == "REAL"
    data, want = rows_and_reference(1, 6, single)
    got, info = M.run_block(c.exe, 0, data)
    check(fb, plan, data, got, want, 1e-9 if not single else 1e-4)
    assert np.array_equal(info, expected_info(plan, data)), info


# --------------------------------------------------------------------------- bench, PLCopen

CLIPPED = SMOOTH_FCL.format(accu="MAX", act="MIN")


#: CoA to 1e-9 of the range; a smooth maximum to 1e-4 (the bench's tolerance for a set that
#: may peak smoothly: testbench._relative)
@pytest.mark.parametrize(("method", "off"), [("COA", 1e-7), ("MOM", 2e-3)])
def test_c_bench_passes_and_fails_on_a_wrong_expected_value(method: str, off: float, tmp_path: Path) -> None:
    doc = fuzzyctl.load(CLIPPED.replace("METHOD : COG", f"METHOD : {method}"))
    files = generate_c(doc, testbench=6)
    bench_name = next(n for n in files if n.endswith("_testbench.c"))
    (tmp_path / "ok").mkdir()
    assert _run_bench(files, tmp_path / "ok") == "PASS FAIL_COUNT=0 FIRST_FAIL=0 rc=0"
    bench = files[bench_name]
    m = re.search(r"(_TB_Y0\[6\] = \{)([^}]*)\}", bench)
    assert m, bench[:2000]
    vals = m.group(2).split(", ")
    tol = float(re.search(r"output z: tolerance ([0-9.e+-]+)", bench).group(1))  # type: ignore[union-attr]
    assert tol == pytest.approx((1e-9 if method == "COA" else 1e-4) * 10.0)
    vals[2] = repr(float(vals[2]) + off * 10.0)  # beyond the tolerance
    tampered = dict(files, **{bench_name: bench[: m.start(2)] + ", ".join(vals) + bench[m.end(2) :]})
    (tmp_path / "bad").mkdir()
    assert _run_bench(tampered, tmp_path / "bad") == "FAIL FAIL_COUNT=1 FIRST_FAIL=3 rc=1"


@pytest.mark.extra("plcopen")
@pytest.mark.parametrize("method", METHODS_SWEPT)
def test_plcopen_of_every_method_is_valid(method: str) -> None:
    doc = fuzzyctl.load(CLIPPED.replace("METHOD : COG", f"METHOD : {method}"))
    xml = generate_plcopen(doc)
    root = valid(xml)
    assert "smooth set" in xml and root is not None


# --------------------------------------------------------------------------- the peak cap

PEAKED = """FUNCTION_BLOCK peaks
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x TERM a := (0, 1) (10, 1); END_FUZZIFY
DEFUZZIFY y {terms} RANGE := (0 .. 19); METHOD : {method}; DEFAULT := -1; END_DEFUZZIFY
RULEBLOCK r AND : MIN; ACT : PROD; ACCU : MAX;
{rules}
END_RULEBLOCK END_FUNCTION_BLOCK"""


@pytest.mark.parametrize("count", [16, 18])
def test_more_smooth_peaks_than_searched_set_info_04(count: int, tmp_path: Path) -> None:
    """``count`` equal Gaussian peaks at 1, 2, ...: up to 16 are searched (INFO 0, LM and RM
    the outer peaks as the reference says); beyond, the block flags INFO 16#04 (its RM then
    misses the last peaks: that is what the flag says)."""
    terms = " ".join(f"TERM t{k} := gauss {k} 0.2;" for k in range(1, count + 1))
    rules = "\n".join(f"RULE {k} : IF x IS a THEN y IS t{k};" for k in range(1, count + 1))
    plans = []
    for method in ("LM", "RM"):
        fb = fuzzyctl.load(PEAKED.format(terms=terms, rules=rules, method=method)).blocks[0]
        plan = fuzzyctl.compile(fb, backend="interpreted").plan
        plans.append(dataclasses.replace(plan, name=f"peaks_{method.lower()}_{count}"))
    lib = build_library(plans, tmp_path)
    data = np.array([[5.0]])
    for plan in plans:
        want = float(S.reference(plan, data, "scalar")[0, 0])
        size = getattr(lib, f"{plan.name}_size")
        size.restype = ctypes.c_size_t
        inst = ctypes.create_string_buffer(int(size()))
        getattr(lib, f"{plan.name}_init")(inst)
        out = np.empty(1)
        fn = getattr(lib, f"{plan.name}_batch")  # returns the last row's INFO
        fn.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p, ctypes.c_void_p]
        fn.restype = ctypes.c_ubyte
        info = fn(inst, 1, data.ctypes.data, out.ctypes.data)
        if count <= 16 or plan.outputs[0].method == "LM":
            assert abs(float(out[0]) - want) <= 1e-6, (plan.name, out[0], want)
        assert info == (0x04 if count > 16 else 0x00), (plan.name, info)
    assert abs(want - count) <= 1e-6  # RM: the last peak
