"""A simulated PLC task drives both blocks through their mode sequences, cycle by cycle,
on the deterministic clock: the Siemens block through START_STOP (3.1) and the XFUZ block
through cold restart, MANUAL/AUTO, continuous mode with T_OFB, forcing, REFRESH and INIT
(2.6)."""

from __future__ import annotations

from dataclasses import replace

import pytest

from fuzzyctl.blocks.schneider import XfuzConstants, XfuzFB
from fuzzyctl.blocks.siemens import FuzzyFB, fuzzy_ai, fuzzy_ao
from fuzzyctl.blocks.task import CycleContext, CyclicTask, SimulatedClock
from fuzzyctl.formats.fpl.reader import read_fpl
from tests.blocks.manual_3_3 import ESV, FA, RG, words
from tests.conftest import EXAMPLES


def test_task_drives_both_blocks_through_their_modes() -> None:
    siemens = FuzzyFB(read_fpl((EXAMPLES / "fpltest.fpl").read_text()))
    constants = XfuzConstants(
        esv=words({**ESV, 24: 6}, 62),
        fa=words(FA, 576),
        rg=words(RG, 384),
        contask=False,
        t_ofb=3,
        o_def=(0, 0, 1, 0, 0, 0),
    )
    xfuz = XfuzFB(constants)
    log: list[dict[str, object]] = []

    def plc_program(ctx: CycleContext) -> None:
        k = ctx.index
        # Siemens: disabled from cycle 5 to 9; the analog inputs go through FUZZY_AI
        # (Temp unipolar 0..30: half scale 13824 -> 15, full scale 27648 -> 30 from cycle 8;
        # Pressure bipolar 50..100: 0 -> 75) and the valve through FUZZY_AO (bipolar).
        siemens.START_STOP = 0 if 5 <= k < 10 else 0xFFFF
        fuzzy_ai(siemens, 13824 if k < 8 else 27648, input_nr=1)
        fuzzy_ai(siemens, 0, bipolar=True, input_nr=2)
        info = siemens.execute()
        ao = fuzzy_ao(siemens, bipolar=True)
        # XFUZ: the operator switches to AUTO and starts the continuous inferences at cycle
        # 2, the process changes at 15, INP4 is forced from 20, a new base is loaded with
        # REFRESH at 30 and the block is re-initialised with INIT at 40.
        xfuz["INP1"], xfuz["INP4"] = (0, -50) if k < 15 else (20, 10)
        if k == 2:
            xfuz.MAN_AUTO, xfuz.START = 1, 1
        if k == 20:
            xfuz["I4_SIM"], xfuz.COMMAND = -50, 0b1000
        if k == 30:
            xfuz.constants = replace(xfuz.constants, o_def=(0, 0, 7, 0, 0, 0))
            xfuz.REFRESH = 1
        if k == 40:
            xfuz.INIT = 1
        snap = xfuz.execute(ctx.period)
        log.append(
            {
                "info": info,
                "valve": siemens.OUTPUT1,
                "ao": ao.word,
                "out3": snap.out[2],
                "inferred": snap.inferred,
                "man_auto": xfuz.MAN_AUTO,
                "t_ofb": xfuz.T_OFB,
            }
        )

    task = CyclicTask(0.01, [plc_program], clock=SimulatedClock(latency=[0.0, 0.0005]))
    stats = task.run(45)
    assert stats.count == 45 and stats.overruns == 0 and stats.jitter_max == pytest.approx(0.0005)

    # Siemens.  15 degC / 75: every rule .5 -> 0.  Cycles 5-9: INFO 01, value kept, FUZZY_AO
    # and FUZZY_AI not processed.  From 10, 30 degC / 75: hot 1, low .5, high .5 -> closed .5,
    # drainage .5 -> -50; FUZZY_AO: 27648 (2 * -50 - 101 + 101) / 202 = -13687.1 -> -13687.
    assert [r["info"] for r in log[:12]] == [0] * 5 + [1] * 5 + [0] * 2
    assert [r["valve"] for r in log[:12]] == [0.0] * 10 + [-50.0] * 2
    assert [r["ao"] for r in log[:12]] == [0] * 5 + [None] * 5 + [-13687] * 2

    # XFUZ.  T_OFB = 3 hundredths = 3 cycles of 10 ms: the first inference 3 cycles after
    # START (cycle 4), then every 3; REFRESH at 30 restarts the count (next at 33); INIT at
    # 40 goes back to MANUAL with START = 0.
    assert [k for k, r in enumerate(log) if r["inferred"]] == [4, 7, 10, 13, 16, 19, 22, 25, 28, 33, 36, 39]
    assert {r["t_ofb"] for r in log} == {3}
    # OUT3: O3_MAN = O3_DEF$ = 1 in MANUAL, O3_CALC = 1 in AUTO until the first inference;
    # (0, -50) -> 8, (20, 10) -> 3, (20, forced -50) -> 2 (hand computations in
    # test_xfuz_block.py); REFRESH puts O3_DEF$ = 7 on every output datum, INIT too.
    expected = [1] * 4 + [8] * 12 + [3] * 6 + [2] * 8 + [7] * 3 + [2] * 7 + [7] * 5
    assert [r["out3"] for r in log] == expected
    assert [r["man_auto"] for r in log] == [0, 0] + [1] * 38 + [0] * 5
