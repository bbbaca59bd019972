"""Time of one call of each PLC block, and of a 10 ms simulated task running both; prints
microseconds per call, no assertion.  The manuals' figures for comparison: Siemens FB30
0.7 ms on a CPU 416 (2 inputs, 1 output, 25 rules); XFUZ 12-40 ms on a TSX 47-40."""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

from fuzzyctl.blocks.schneider import XfuzFB
from fuzzyctl.blocks.siemens import FuzzyFB
from fuzzyctl.blocks.task import CyclicTask
from fuzzyctl.formats.fpl.reader import read_fpl
from fuzzyctl.formats.xfuz.reader import read_tables

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def per_call(call: Callable[[], object], n: int) -> float:
    call()
    start = time.perf_counter()
    for _ in range(n):
        call()
    return (time.perf_counter() - start) / n * 1e6


def main() -> None:
    siemens = FuzzyFB(read_fpl((EXAMPLES / "fpltest.fpl").read_text()))
    siemens.INPUT1, siemens.INPUT2 = 9.0, 65.0
    print(f"Siemens FUZZY (FPLTEST, 4 rules): {per_call(siemens.execute, 20000):.1f} us/call")

    xfuz = XfuzFB(read_tables((EXAMPLES / "xfuz_3_3.xfuz").read_text()), span_rule=False)
    xfuz.MAN_AUTO, xfuz.CONT_ASK, xfuz.START, xfuz.T_OFB = 1, 0, 1, 0  # infer every call
    xfuz["INP1"], xfuz["INP4"] = 20, 10
    print(f"XFUZ (3.3, two levels, Discr 20): {per_call(xfuz.execute, 5000):.1f} us/call")

    task = CyclicTask(0.01)
    task.add(lambda ctx: siemens.execute())
    task.add(lambda ctx: xfuz.execute(ctx.period))
    start = time.perf_counter()
    task.run(5000)
    print(f"simulated 10 ms task, both blocks: {(time.perf_counter() - start) / 5000 * 1e6:.1f} us/cycle")


if __name__ == "__main__":
    main()
