"""Run the integer C block (``codegen --arith int16|int32``) against the engine.

The generated C is compiled with ``cc -std=c99 -Wall -Wextra -Werror -pedantic`` together
with a small driver that reads stored inputs from stdin and prints the stored outputs; the
engine evaluates the same inputs as real values (``stored * scale + offset``, from the
``--json`` report), so what is compared is exactly what the stated bound speaks of."""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

import fuzzyctl
from fuzzyctl.codegen.api import generate_c

STRICT = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"]


@dataclass
class Outcome:
    report: dict[str, Any]  # the block's --json report
    stored_in: np.ndarray  # rows of stored inputs
    stored_out: np.ndarray  # rows of stored outputs
    values_in: np.ndarray  # the same inputs as engine values
    exact: np.ndarray  # the engine's outputs
    got: np.ndarray  # the block's outputs as values

    def errors(self) -> np.ndarray:
        return np.asarray(np.abs(self.got - self.exact).max(axis=0))

    def bounds(self) -> np.ndarray:
        return np.array([o["error_bound"] for o in self.report["outputs"]])


def _driver(name: str, n_in: int, n_out: int, inputs: list[str], outputs: list[str]) -> str:
    lines = [
        f'#include "{name}.h"',
        "#include <stdio.h>",
        "int main(void)",
        "{",
        f"    {name} fb;",
        "    long v;",
    ]
    lines.append(f"    {name}_init(&fb);")
    lines.append("    for (;;) {")
    for k in inputs:
        lines.append(f'        if (scanf("%ld", &v) != 1) return 0;\n        fb.{k} = v;')
    lines.append(f"        {name}_step(&fb);")
    fmt = " ".join(["%ld"] * n_out)
    args = ", ".join(f"(long)fb.{o}" for o in outputs)
    lines.append(f'        printf("{fmt}\\n", {args});')
    lines += ["    }", "}"]
    del n_in
    return "\n".join(lines) + "\n"


def run_c(
    model: Any, arith: str, rows: int = 2000, seed: int = 0, extra: np.ndarray | None = None, **kw: Any
) -> Outcome:
    """The block of ``model`` (a document or text) in ``arith`` on random stored inputs over
    the whole stored range (plus ``extra`` rows), against the engine."""
    doc = fuzzyctl.load(model) if isinstance(model, str) else model
    report: list[Any] = []
    files = generate_c(doc, arith=arith, report=report, **kw)
    rep = report[0].to_dict()
    name = rep["block"]
    ins = [p["name"] for p in rep["inputs"]]
    outs = [p["name"] for p in rep["outputs"]]
    rng = np.random.default_rng(seed)
    lo = np.array([p["stored_range"][0] for p in rep["inputs"]])
    hi = np.array([p["stored_range"][1] for p in rep["inputs"]])
    low, high = (
        np.iinfo(np.int16 if arith == "int16" else np.int32).min,
        np.iinfo(np.int16 if arith == "int16" else np.int32).max,
    )
    stored = rng.integers(lo, hi + 1, size=(rows, len(ins)))
    stored[: rows // 20] = rng.integers(low, high + 1, size=(rows // 20, len(ins)))  # outside the range too
    # also the points just around the range's ends and every stored value near zero
    stored = np.vstack([stored, lo[None, :], hi[None, :], np.zeros((1, len(ins)), dtype=np.int64)])
    if extra is not None:
        stored = np.vstack([stored, extra.astype(np.int64)])
    cc = shutil.which("cc")
    assert cc is not None, "the integer C tests need the system compiler 'cc'"
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        for fname, text in files.items():
            (d / fname).write_text(text)
        (d / "main.c").write_text(_driver(name, len(ins), len(outs), ins, outs))
        subprocess.run(
            [cc, *STRICT, "-O1", "-o", str(d / "block"), str(d / f"{name}.c"), str(d / "main.c")],
            check=True,
            capture_output=True,
            text=True,
        )
        text = "\n".join(" ".join(str(int(v)) for v in row) for row in stored) + "\n"
        res = subprocess.run([str(d / "block")], input=text, capture_output=True, text=True, check=True)
    got_stored = np.array(
        [[int(v) for v in line.split()] for line in res.stdout.splitlines()], dtype=np.int64
    )
    scale_in = np.array([p["scale"] for p in rep["inputs"]])
    off_in = np.array([p["offset"] for p in rep["inputs"]])
    # the block limits each stored input to its stored range: the engine gets the same value
    values = np.clip(stored, lo, hi) * scale_in + off_in
    ctl = fuzzyctl.compile(doc, out_of_range="ignore")
    cols = {n: values[:, k] for k, n in enumerate(ins)}
    for n in ctl.input_names if hasattr(ctl, "input_names") else []:
        cols.setdefault(n, np.zeros(len(values)))
    batch = ctl.evaluate_batch(cols)
    exact = np.column_stack([np.asarray(batch[o], dtype=float) for o in outs])
    scale_out = np.array([p["scale"] for p in rep["outputs"]])
    off_out = np.array([p["offset"] for p in rep["outputs"]])
    return Outcome(rep, stored, got_stored, values, exact, got_stored * scale_out + off_out)


def within_bound_or_refused(text: str, rows: int, seed: int) -> None:
    """In int16 and int32, the block compiled and run stays within the error bound its
    header states, or the generator refuses it pointing to ``--arith float``."""
    from fuzzyctl.codegen import CodegenError

    for arith in ("int16", "int32"):
        try:
            out = run_c(text, arith, rows=rows, seed=seed)
        except CodegenError as exc:
            assert "(use --arith float" in str(exc)
            continue
        assert (out.errors() <= out.bounds()).all(), (arith, out.errors(), out.bounds())


def generated_in_int32(texts: list[str]) -> int:
    """How many of ``texts`` the int32 generator accepts."""
    from fuzzyctl.codegen import CodegenError

    done = 0
    for text in texts:
        try:
            generate_c(fuzzyctl.load(text), arith="int32")
            done += 1
        except CodegenError:
            pass
    return done
