"""Real systems in integer arithmetic: every corpus file that generates in REAL generates in
int32, or the refusal names the element and the way past it (``--arith float``); the int32 C
of a sample compiles with the strict flags.  The numbers are printed."""

from __future__ import annotations

import re
from collections import Counter
from pathlib import Path

import pytest

import fuzzyctl
from fuzzyctl.codegen import CodegenError
from fuzzyctl.codegen.api import generate_c, lower_block
from fuzzyctl.diagnostics import DiagnosticError
from tests.codegen.corpus import FILES, compile_sample, load
from tests.codegen.fixed_check import STRICT

pytestmark = pytest.mark.extra("corpus")

ELEMENT = re.compile(r"^(output|term|input|rule|function block|rule block activation) ")
WAY = re.compile(r"\(use --arith float")


def _in_real(doc: fuzzyctl.model.Document) -> bool:
    try:
        plans = [lower_block(doc, fb.name) for fb in doc.blocks]
        for plan in plans:
            generate_c(plan, default=0.0)
    except (DiagnosticError, CodegenError):
        return False
    return True


def test_corpus_generates_in_int32_or_says_why(tmp_path: Path) -> None:
    assert len(FILES) >= 400
    real = done = 0
    reasons: Counter[str] = Counter()
    sample: list[dict[str, str]] = []
    for path in FILES:
        doc = load(path)
        if doc is None:
            continue
        if not _in_real(doc):
            continue
        real += 1
        try:
            files = generate_c(doc, arith="int32")
        except CodegenError as exc:
            message = str(exc)
            assert ELEMENT.match(message) and WAY.search(message), (path.name, message)
            reasons[re.sub(r"'[^']*'|\(at .*?\)|rule \S+:|-?\d[\d.e+-]*", "_", message)[:120]] += 1
            continue
        done += 1
        if len(sample) < 12:
            sample.append(files)
    print(f"\nint32: {done} of {real} corpus files that generate in REAL")
    for why, n in reasons.most_common():
        print(f"  {n:3} x {why}")
    # smooth input terms as proven chords, Mamdani CoG/CoA/LM/RM/MoM (92 with CoG alone, 38 before)
    assert done >= 180
    compile_sample(sample, tmp_path, [*STRICT, "-c", "-o", str(tmp_path / "x.o")])
