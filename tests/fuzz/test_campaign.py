"""The mutation fuzzer of :mod:`tests.fuzz.campaign` in the suite (issue 14.5): a fixed,
seeded sample of mutants of the examples and the vendored files goes through load, compile,
evaluate/evaluate_batch (which must agree), explain, convert, codegen and one CLI command;
none may raise a non-project exception, exit 3, run over 10 CPU seconds or grow its worker
over 500 MB.  ``make fuzz`` runs thousands (and the shared corpus when present)."""

from __future__ import annotations

import os

from tests.fuzz.campaign import campaign, seeds

# A few hundred mutants would take minutes on a loaded 2-core machine; this sample keeps the
# suite's share under a minute.  FUZZYCTL_FUZZ_MUTANTS raises it.
MUTANTS = int(os.environ.get("FUZZYCTL_FUZZ_MUTANTS", "80"))


def test_no_mutant_crashes_hangs_or_runs_away() -> None:
    report = campaign(seeds(), MUTANTS, seed=20261202, workers=2, timeout=10.0, memory_mb=500)
    print(report.summary())
    assert report.tried == MUTANTS
    assert not report.failures, report.describe()
    # the sample reaches the engine, not only the readers' first error
    assert report.counts["ok"] >= MUTANTS // 20, report.summary()
