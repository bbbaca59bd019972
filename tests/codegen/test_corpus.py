"""Real systems generate: Structured Text and C for at least 95 % of the loadable corpus files
of each format (FCL, FIS, FLL), and every refusal names the element and what gets past it.

Each file is loaded (FCL: the span of the terms is the universe, non-strict), lowered once,
and generated for both targets.  A refusal that names ``--default`` (an output with
``DEFAULT := nan`` in ST) counts as generated when ``--default hold`` then generates: the
option exists for exactly that.  A sample of the C goes through ``cc -fsyntax-only``; the
numbers (what the closing note of issue 16 quotes) are printed."""

from __future__ import annotations

import re
from collections import Counter
from pathlib import Path

import pytest

from fuzzyctl.codegen import CodegenError
from fuzzyctl.codegen.api import generate_c, generate_st, lower_block
from fuzzyctl.diagnostics import DiagnosticError
from tests.codegen.corpus import FILES, compile_sample, load

pytestmark = pytest.mark.extra("corpus")

#: What a refusal must name: the element (how the generator calls the model's parts) ...
ELEMENT = re.compile(r"^(output|term|input|rule|variable|function block|rule block activation) ")
#: ... and a way past it: an option, or the change to the model that the target can express.
WAY = re.compile(r"--\w|use |give |write |rewrite |METHOD|singleton")
#: Python names that must never reach a user (class names of the plan, field paths).
JARGON = re.compile(r"\b\w+Plan\b|\bOptions\.|\b[A-Z]\w+\.\w+ =|semantic switch")


def _generate(plan: object, lang: str) -> str | None:
    """None when generated, else the refusal message (after ``--default hold`` when the first
    message asked for it)."""
    fn = generate_st if lang == "st" else generate_c
    try:
        fn(plan)  # type: ignore[operator]
        return None
    except CodegenError as exc:
        first = str(exc)
    if "--default" not in first:
        return first
    try:
        fn(plan, default="hold")  # type: ignore[operator]
        return None
    except CodegenError as exc:
        return str(exc)


@pytest.mark.parametrize("form", ["fcl", "fis", "fll"])
def test_real_systems_generate(form: str, tmp_path: Path) -> None:
    """One format per test, so that two workers share the ~450 files."""
    assert len(FILES) >= 400
    loadable: Counter[str] = Counter()
    evaluable: Counter[str] = Counter()
    ok: Counter[tuple[str, str]] = Counter()
    ok_eval: Counter[tuple[str, str]] = Counter()
    refusals: dict[str, list[str]] = {}
    c_sample: list[dict[str, str]] = []
    for k, path in enumerate(FILES):
        fmt = path.suffix.lower().lstrip(".")
        if fmt != form:
            continue
        doc = load(path)
        if doc is None:
            continue
        loadable[fmt] += 1
        try:
            plans = [lower_block(doc, fb.name) for fb in doc.blocks]
        except DiagnosticError:
            continue  # the engine refuses it: neither target can be asked to
        evaluable[fmt] += 1
        for lang in ("st", "c"):
            messages = [m for m in (_generate(p, lang) for p in plans) if m is not None]
            if not messages:
                ok[fmt, lang] += 1
                ok_eval[fmt, lang] += 1
                if lang == "c" and k % 10 == 0:
                    c_sample += [generate_c(p) for p in plans]
            for m in messages:
                refusals.setdefault(m, []).append(path.name)
    lines = []
    for fmt in (form,):
        for lang in ("st", "c"):
            n, e = loadable[fmt], evaluable[fmt]
            lines.append(
                f"{lang.upper():2} {fmt.upper()}: {ok[fmt, lang]}/{n} loadable "
                f"({100 * ok[fmt, lang] / n:.1f} %), {ok_eval[fmt, lang]}/{e} evaluable "
                f"({100 * ok_eval[fmt, lang] / e:.1f} %)"
            )
    print("\n" + "\n".join(lines))
    for m, files in sorted(refusals.items(), key=lambda kv: -len(kv[1])):
        print(f"  {len(files):3} x {m[:160]}")
    for fmt in (form,):
        for lang in ("st", "c"):
            assert ok[fmt, lang] >= 0.95 * loadable[fmt], (fmt, lang, ok[fmt, lang], loadable[fmt])
    for m in refusals:
        assert ELEMENT.match(m), m
        assert WAY.search(m), m
        assert not JARGON.search(m), m
    compile_sample(c_sample, tmp_path, ["-std=c99", "-Wall", "-Werror", "-fsyntax-only"])  # a sample of the C
