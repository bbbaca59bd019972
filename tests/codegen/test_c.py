"""Generated C against the engine.

Every example and every expressible conformance system is generated (renamed ``s0``, ``s1``,
... so that all share one library), compiled in ONE strict invocation of the system compiler
(``cc -std=c99 -Wall -Wextra -Werror -pedantic``) and run on 10,000 random inputs each, as
successive cycles of one instance (so DEFAULT := NC is exercised); outputs must match the
engine within 1e-9 of the output's range.  The float build of the examples compiles as
strictly and stays within 1e-4 of the range."""

from __future__ import annotations

import ctypes
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fuzzyctl.codegen import CodegenError
from fuzzyctl.engine.plan import Plan
from fuzzyctl.ir.programs.plc_block import build_program
from fuzzyctl.ir.render.c import render_c
from tests.codegen import systems as S
from tests.diskcache import cached_dir

STRICT = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"]
N = 10_000
N_CORE = 2_000  # rows also checked against the scalar Python core
# systems with a smooth output: their generated quadrature is adaptive (cuts at every level and
# branch, Gauss-Kronrod 7/15), so a row costs ~100x a piecewise-linear one; the operator sweeps
# (test_gen_accuracy.py, test_native_operators.py) cover them in depth
N_SMOOTH = 2_000


def _cc() -> str:
    cc = shutil.which("cc")
    if cc is None:
        pytest.fail("the C tests need the system compiler 'cc'")
    return cc


def build_library(plans: list[Plan], out: Path, single: bool = False) -> ctypes.CDLL:
    """All plans in one shared library, compiled in one strict cc invocation (cached on disk
    by the generated text and the compiler: tests/diskcache.py)."""
    files: dict[str, str] = {}
    sizes = ["#include <stddef.h>"]
    for plan in plans:
        header, source = render_c(build_program(plan, "c"), single=single)
        files[f"{plan.name}.h"] = header
        files[f"{plan.name}.c"] = source
        sizes.append(f'#include "{plan.name}.h"')
    sizes += [f"size_t {p.name}_size(void) {{ return sizeof({p.name}); }}" for p in plans]
    files["sizes.c"] = "\n".join(sizes) + "\n"
    sources = [f"{p.name}.c" for p in plans]
    compiler = subprocess.run([_cc(), "--version"], capture_output=True, text=True).stdout

    def build(where: Path) -> None:
        for name, text in files.items():
            (where / name).write_text(text)
        # two strict compiler runs side by side (2 cores), one link
        halves = [sources[0::2], [*sources[1::2], "sizes.c"]]
        objs = [where / "part0.o", where / "part1.o"]
        procs = []
        for part, obj in zip(halves, objs, strict=True):
            unit = where / f"{obj.stem}.c"
            unit.write_text("".join(f'#include "{src}"\n' for src in part))
            cmd = [_cc(), *STRICT, "-O1", "-ffp-contract=off", "-fPIC", "-c", "-o", str(obj), str(unit)]
            procs.append(subprocess.Popen(cmd, stderr=subprocess.PIPE, text=True))
        for p in procs:
            _out, err = p.communicate()
            assert p.returncode == 0, err[:4000]
        res = subprocess.run(
            [_cc(), "-shared", "-o", str(where / "systems.so"), *map(str, objs), "-lm"],
            capture_output=True,
            text=True,
        )
        assert res.returncode == 0, res.stderr[:4000]

    built = cached_dir("c-systems", (files, STRICT, compiler), build)
    for name in files:  # the sources next to the test's other files, for a human to read
        shutil.copy(built / name, out / name)
    return ctypes.CDLL(str(built / "systems.so"))


def run(lib: ctypes.CDLL, plan: Plan, data: np.ndarray) -> np.ndarray:
    """Successive rows through one instance (``NAME_batch``)."""
    name = plan.name
    size = getattr(lib, f"{name}_size")
    size.restype = ctypes.c_size_t
    inst = ctypes.create_string_buffer(int(size()))
    getattr(lib, f"{name}_init")(inst)
    n_out = sum(1 for o in plan.outputs if o.is_output)
    data = np.ascontiguousarray(data, dtype=np.float64)
    out = np.empty((len(data), n_out))
    fn = getattr(lib, f"{name}_batch")
    fn.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p, ctypes.c_void_p]
    fn(inst, len(data), data.ctypes.data, out.ctypes.data)
    return out


def _systems() -> list[tuple[str, Plan]]:
    out = []
    for p in S.example_files():
        out.append((f"examples/{p.name}", S.plan_of(p)))
    for rel, p in S.conformance_files():
        if rel not in S.NOT_EXPRESSIBLE_C:
            out.append((rel, S.plan_of(p)))
    return [(label, _renamed(plan, f"s{k}")) for k, (label, plan) in enumerate(out)]


def _renamed(plan: Plan, name: str) -> Plan:
    import dataclasses

    return dataclasses.replace(plan, name=name)


@pytest.fixture(scope="module")
def compiled(tmp_path_factory: pytest.TempPathFactory) -> tuple[ctypes.CDLL, list[tuple[str, Plan]]]:
    systems = _systems()
    lib = build_library([p for _l, p in systems], tmp_path_factory.mktemp("c"))
    return lib, systems


def test_every_expressible_system_matches_the_engine(
    compiled: tuple[ctypes.CDLL, list[tuple[str, Plan]]],
) -> None:
    lib, systems = compiled
    assert len(systems) >= 60  # examples + conformance
    worst, worst_core = {}, {}
    for label, plan in systems:
        smooth_out = any(o.kind == "mamdani" and not o.exact for o in plan.outputs)
        data = S.random_inputs(plan, N_SMOOTH if smooth_out else N, seed=len(label))
        got = run(lib, plan, data)
        want = S.reference(plan, data)
        worst[label] = S.max_error(plan, got, want)
        # the native backend runs this very C (plus a batch wrapper): against the Python
        # core's scalar path it must agree to 1e-12 (tests/codegen/test_native.py builds
        # the native libraries themselves for the examples and random systems)
        head = data[:N_CORE]
        worst_core[label] = S.max_error(plan, got[:N_CORE], S.reference(plan, head, "scalar"))
    bad = {k: v for k, v in worst.items() if not v <= 1e-9}
    assert not bad, bad
    # smooth outputs: the generated quadrature against the engine's adaptive one (1e-9 above)
    smooth = {
        label for label, plan in systems if any(o.kind == "mamdani" and not o.exact for o in plan.outputs)
    }
    bad_core = {k: v for k, v in worst_core.items() if not v <= (1e-9 if k in smooth else 1e-12)}
    assert not bad_core, bad_core
    print(
        f"\nC double: worst deviation {max(worst.values()):.2e} of the range over {len(worst)} systems"
        f" ({max(worst_core.values()):.2e} against the scalar core)"
    )


def test_the_not_expressible_list_is_exactly_what_the_generator_refuses() -> None:
    refused = {}
    for rel, p in S.conformance_files():
        try:
            build_program(S.plan_of(p), "c")
        except CodegenError as exc:
            refused[rel] = str(exc)
    assert set(refused) == set(S.NOT_EXPRESSIBLE_C)
    for msg in refused.values():  # the message names the element
        assert msg.startswith(("output ", "term ")), msg


def test_float_build_compiles_strictly_and_stays_close(tmp_path: Path) -> None:
    plans = [_renamed(S.plan_of(p), f"f{k}") for k, p in enumerate(S.example_files())]
    lib = build_library(plans, tmp_path, single=True)
    for plan in plans:
        data = S.random_inputs(plan, 2000, seed=3, single=True)
        err = S.max_error(plan, run(lib, plan, data), S.reference(plan, data))
        assert err <= 1e-4, (plan.name, err)
    assert "typedef float f0_real;" in (tmp_path / "f0.h").read_text()


LIBM = re.compile(
    r"\b(exp|log|log10|sqrt|fabs|sin|cos|tan|asin|acos|atan|sinh|cosh|tanh|floor|ceil|rint|pow|atan2|fmod)f?\s*\("
)
ALLOC = re.compile(r"\b(malloc|calloc|realloc|free|alloca)\s*\(")


def test_no_allocation_no_mutable_globals_and_no_libm_beyond_exp(
    compiled: tuple[ctypes.CDLL, list[tuple[str, Plan]]],
) -> None:
    """C99 for small targets: no heap, no state outside the instance struct, and no libm
    beyond exp - none for piecewise-linear systems, exp for smooth input terms; sqrt (exact
    CoA), pow (bell terms) and sin/cos (cosine and function terms) are static fz_ helpers
    (the header comment lists both)."""
    _lib, systems = compiled
    used: dict[str, set[str]] = {}
    helpers: dict[str, set[str]] = {}
    for label, plan in systems:
        header, source = render_c(build_program(plan, "c"))
        code = re.sub(r"/\*.*?\*/", " ", source, flags=re.S)
        assert not ALLOC.search(code + header), label
        assert re.findall(r"#include\s+\S+", code) == [f'#include "{plan.name}.h"', "#include <math.h>"], (
            label
        )
        assert re.findall(r"#include\s+\S+", header) == ["#include <stddef.h>"], label
        # file-scope data is constant tables only
        for line in code.splitlines():
            if line and not line[0].isspace() and "=" in line and "(" not in line.split("=")[0]:
                assert line.startswith("static const "), (label, line)
        calls = {m.group(1) for m in LIBM.finditer(code)}  # fz_sqrt( is no match: no \b after _
        assert calls <= {"exp"}, (label, calls)
        declared = re.search(r"/\* libm functions used: (.*?) \*/", source)
        assert declared, label
        listed = set() if declared.group(1) == "none" else set(declared.group(1).split(", "))
        assert calls == listed, (label, calls, listed)
        used[label] = calls
        helpers[label] = set(re.findall(r"^static double (fz_\w+)\(", code, flags=re.M))
    for name in ("figure7", "crane", "tank", "pendulum", "siemens_fpltest"):  # points and singletons
        assert used[f"examples/{name}.fcl"] == set(), name
        assert helpers[f"examples/{name}.fcl"] == set(), name
    assert used["examples/heater_extension.fcl"] == set()  # CoA, points only: sqrt is a helper
    assert helpers["examples/heater_extension.fcl"] == {"fz_sqrt"}
    assert used["examples/dryer_chained.fcl"] == {"exp"}  # a Gaussian input term, CoA
    # the systems that called sqrt/pow/sin/fabs before now carry those helpers instead
    assert helpers["fuzzylite/takagi-sugeno/matlab/fpeaks.fcl"] >= {"fz_pow", "fz_log"}
    assert helpers["fuzzylite/takagi-sugeno/approximation.fcl"] >= {"fz_sin", "fz_fabs"}
