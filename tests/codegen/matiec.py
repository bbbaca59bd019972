"""matiec, the IEC 61131-3 compiler of OpenPLC and Beremiz (ST -> C), for the tests: built
once from ``../shared/tools/matiec-src.tar.gz`` into the test cache (keyed by the tarball's
hash; a file lock keeps two pytest-xdist workers from building it twice), then used to
translate generated Structured Text and compile it with gcc and a generated C driver.

The driver follows the matiec note in ``../shared/tools/README.md``: ``NAME_init__`` and
``NAME_body__`` of each FUNCTION_BLOCK, inputs and outputs through the ``__SET_VAR`` /
``__GET_VAR`` macros of ``lib/C/accessor.h``, ``__CURRENT_TIME`` and ``__DEBUG`` defined.
Numbers cross the process boundary as C99 hexadecimal floats (exact)."""

from __future__ import annotations

import fcntl
import hashlib
import shutil
import subprocess
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from tests.diskcache import cache_dir, cached_dir
from tests.extras import extra_path

TARBALL = extra_path("matiec", "tools", "matiec-src.tar.gz")
TOOLS = ("autoreconf", "libtoolize", "flex", "bison", "make", "gcc")


def _run(cmd: Sequence[str], cwd: Path, what: str, timeout: float = 900) -> str:
    res = subprocess.run(list(cmd), cwd=cwd, capture_output=True, text=True, timeout=timeout)
    if res.returncode != 0:
        raise AssertionError(f"{what} failed ({res.returncode}):\n{res.stdout[-3000:]}\n{res.stderr[-3000:]}")
    return res.stdout


def _build(where: Path) -> None:
    src = where / "src"
    src.mkdir()
    _run(["tar", "xzf", str(TARBALL), "-C", str(src), "--strip-components=1"], where, "unpacking matiec")
    _run(["autoreconf", "-i"], src, "autoreconf")
    _run(["./configure"], src, "configure")
    _run(["make", "-j2"], src, "make")
    shutil.copy2(src / "iec2c", where / "iec2c")
    shutil.copytree(src / "lib", where / "lib")
    shutil.rmtree(src)


def build() -> Path:
    """The directory holding ``iec2c`` and ``lib/`` (built on first use, ~2 min)."""
    missing = [t for t in TOOLS if shutil.which(t) is None]
    if missing:
        pytest.fail(f"building matiec needs {', '.join(missing)}: run scripts/system-deps.sh")
    digest = hashlib.sha256(TARBALL.read_bytes()).hexdigest()
    lock = cache_dir("matiec") / "build.lock"
    with lock.open("w") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)  # the other worker waits for this build
        return cached_dir("matiec", ("matiec-build", digest, 1), _build)


def iec2c(matiec: Path, text: str, where: Path) -> None:
    """Translate ``text`` (one .st file) to ``where/POUS.c`` and ``POUS.h``."""
    (where / "program.st").write_text(text)
    _run([str(matiec / "iec2c"), "-I", str(matiec / "lib"), "-T", str(where), "program.st"], where, "iec2c")


def compile_c(matiec: Path, where: Path, driver: str, exe: str = "driver") -> Path:
    """gcc on the driver, which includes matiec's POUS.h and POUS.c."""
    (where / f"{exe}.c").write_text(driver)
    _run(
        ["gcc", "-O0", "-w", "-I", str(matiec / "lib" / "C"), "-o", exe, f"{exe}.c", "-lm"],
        where,
        "gcc on matiec's C",
    )
    return where / exe


#: The start of a C driver: matiec's translation included, and the globals its library expects.
PRELUDE = (
    "#include <stdio.h>",
    "#include <stdlib.h>",
    '#include "POUS.h"',
    '#include "POUS.c"',
    "IEC_TIME __CURRENT_TIME;",
    "IEC_BOOL __DEBUG;",
)


@dataclass(frozen=True)
class Block:
    """One FUNCTION_BLOCK in a translated program: its ST name and interface (matiec
    upper-cases every identifier)."""

    name: str
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]  # then INFO


def driver(blocks: Sequence[Block], real: str) -> str:
    """A C program: ``driver K`` runs block K on rows read from stdin (first the row count,
    then one row of hexadecimal floats per line) and prints each row's outputs and INFO."""
    parts = list(PRELUDE)
    for k, b in enumerate(blocks):
        name = b.name.upper()
        n_in = max(1, len(b.inputs))
        sets = "".join(f"    __SET_VAR(fb.,{v.upper()},,({real})x[{i}]);\n" for i, v in enumerate(b.inputs))
        reads = "".join(f'    if (scanf("%la", &x[{i}]) != 1) return 3;\n' for i in range(len(b.inputs)))
        prints = "".join(f'    printf("%a ", (double)__GET_VAR(fb.{v.upper()}));\n' for v in b.outputs)
        parts.append(
            f"static int run{k}(void) {{\n"
            f"  static {name} fb;\n  double x[{n_in}];\n  long n, r;\n"
            f"  {name}_init__(&fb, 0);\n"
            '  if (scanf("%ld", &n) != 1) return 3;\n'
            "  for (r = 0; r < n; r++) {\n"
            f"{reads}{sets}    {name}_body__(&fb);\n{prints}"
            '    printf("%d\\n", (int)__GET_VAR(fb.INFO));\n  }\n  return 0;\n}'
        )
    cases = "".join(f"  case {k}: return run{k}();\n" for k in range(len(blocks)))
    parts.append(
        "int main(int argc, char **argv) {\n  switch (argc > 1 ? atoi(argv[1]) : -1) {\n"
        f"{cases}  }}\n  return 2;\n}}"
    )
    return "\n".join(parts) + "\n"


def run_block(exe: Path, k: int, data: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Block ``k`` of the driver on the rows of ``data``: (outputs, INFO)."""
    lines = [str(len(data))] + [" ".join(float(v).hex() for v in row) for row in data]
    res = subprocess.run(
        [str(exe), str(k)], input="\n".join(lines) + "\n", capture_output=True, text=True, timeout=120
    )
    assert res.returncode == 0, (res.returncode, res.stderr[-2000:])
    rows = [line.split() for line in res.stdout.splitlines()]
    assert len(rows) == len(data)
    outs = np.array([[float.fromhex(v) for v in r[:-1]] for r in rows], dtype=np.float64).reshape(
        len(data), -1
    )
    info = np.array([int(r[-1]) for r in rows], dtype=np.int64)
    return outs, info


def bench_driver(names: Sequence[str]) -> str:
    """A C program: ``driver K`` runs the test bench PROGRAM ``names[K]`` cycle by cycle until
    DONE and prints ``PASS FAIL_COUNT FIRST_FAIL cycles``."""
    parts = list(PRELUDE)
    for k, name in enumerate(names):
        n = name.upper()
        parts.append(
            f"static int run{k}(void) {{\n  static {n} p;\n  long cycles = 0;\n  {n}_init__(&p, 0);\n"
            f"  while (!__GET_VAR(p.DONE) && cycles < 100000) {{ {n}_body__(&p); cycles++; }}\n"
            '  printf("%d %d %d %ld\\n", (int)__GET_VAR(p.PASS), (int)__GET_VAR(p.FAIL_COUNT),'
            " (int)__GET_VAR(p.FIRST_FAIL), cycles);\n  return 0;\n}"
        )
    cases = "".join(f"  case {k}: return run{k}();\n" for k in range(len(names)))
    parts.append(
        f"int main(int argc, char **argv) {{\n  switch (atoi(argv[1])) {{\n{cases}  }}\n  return 2;\n}}"
    )
    return "\n".join(parts) + "\n"
