"""The mutation and differential fuzzer of :mod:`tests.fuzz.campaign` in the suite (issues
14.5 and 25.2): a fixed, seeded sample of mutants of the examples and the vendored files,
then seeded random systems (:mod:`tests.fuzz.systems`), goes through load, compile, every
backend against the reference interpreter (python and native evaluate / evaluate_batch,
explain; a share through ``fuzzyctl eval --set`` / ``--data`` and generated C, with the
bound its header states), convert, codegen and one CLI command.  None may disagree with the
reference beyond 1e-9 of the output's range, raise a non-project exception, exit 3, run over
30 CPU seconds (a model runs some 60 evaluations) or grow its worker over 500 MB.  ``make
fuzz`` runs thousands (and the shared corpus when present)."""

from __future__ import annotations

import os

from tests.fuzz.campaign import campaign, seeds

# Every loaded model compiles a native library (cc) and some a C test driver: this sample
# keeps the suite's share to about a minute of one core.  FUZZYCTL_FUZZ_MUTANTS and
# FUZZYCTL_FUZZ_SYSTEMS raise it.
MUTANTS = int(os.environ.get("FUZZYCTL_FUZZ_MUTANTS", "80"))
SYSTEMS = int(os.environ.get("FUZZYCTL_FUZZ_SYSTEMS", "16"))


def test_no_mutant_or_random_system_disagrees_crashes_hangs_or_runs_away() -> None:
    report = campaign(
        seeds(), MUTANTS, seed=20261202, workers=2, timeout=30.0, memory_mb=500, n_systems=SYSTEMS,
        rates=(0.2, 0.3),
    )  # fmt: skip
    print(report.counts_table())
    print(report.summary())
    assert report.tried == MUTANTS + SYSTEMS
    assert not report.failures, report.describe()
    # the sample reaches the engine, not only the readers' first error, and compares paths
    assert report.counts["ok"] >= MUTANTS // 20, report.summary()
    for path in ("python", "numpy", "native", "native-batch", "explain", "cli-set", "cli-data", "c"):
        assert (
            report.table["systems", f"compared:{path}"] + report.table["mutants", f"compared:{path}"] > 0
        ), path
