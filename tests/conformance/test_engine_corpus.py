"""Every system of the real-world corpus (extra suite ``corpus``) that the readers accept either
compiles or is refused with diagnostics - never a crash - and the specialised, numpy and
interpreted evaluators agree on it, with explanations available."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.diagnostics import DiagnosticError, FuzzyctlError
from tests.conftest import shared_path

pytestmark = pytest.mark.extra("corpus")


def test_corpus_compiles_or_is_refused_and_the_evaluators_agree() -> None:
    compiled = refused = 0
    disagreements: list[str] = []
    for path in sorted(shared_path("corpus").rglob("*")):
        if path.suffix.lower() not in (".fcl", ".fis", ".fll"):
            continue
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                doc = fuzzyctl.load(path)
        except (FuzzyctlError, UnicodeDecodeError):
            continue  # the readers' business (tests/conformance/test_*_corpus.py)
        for fb in doc.blocks:
            try:
                fast, ref, batch = (fuzzyctl.compile(fb) for _ in range(3))
            except DiagnosticError as exc:
                assert any(d.is_error for d in exc.diagnostics)
                refused += 1
                continue
            compiled += 1
            rng = np.random.default_rng(0)
            rows = [
                {
                    i.name: float(rng.uniform(0, 1) if i.degree else rng.uniform(-5, 100))
                    for i in fast.plan.inputs
                }
                for _ in range(4)
            ]
            if fast.inputs:
                cols = batch.evaluate_batch({k: np.array([r[k] for r in rows]) for k in fast.inputs})
            else:  # no input column tells a batch its row count: one evaluation per row
                cols = {k: np.array([batch.evaluate({})[k] for _ in rows]) for k in fast.outputs}
            for n, row in enumerate(rows):
                a, b = fast.evaluate(row), ref.evaluate_reference(row)
                for k, y in b.items():
                    x, z = a[k], float(cols[k][n])
                    same = (math.isnan(x) and math.isnan(y) and math.isnan(z)) or (
                        abs(x - y) <= 1e-9 * (1 + abs(y)) and abs(z - y) <= 1e-9 * (1 + abs(y))
                    )
                    if not same:
                        disagreements.append(f"{path.name} {k}: {x} {y} {z}")
            assert fast.explain(rows[0]).outputs is not None
    assert not disagreements, disagreements[:5]
    assert compiled >= 300 and refused <= 100, (compiled, refused)
