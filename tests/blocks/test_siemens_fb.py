"""The Siemens FUZZY block (FB30, manual 3.1 and 1.5) and FUZZY_AI / FUZZY_AO (3.2, 3.3),
against values worked out by hand from the manual's formulas."""

from __future__ import annotations

import numpy as np
import pytest

from fuzzyctl.blocks.siemens import FuzzyFB, Info, fuzzy_ai, fuzzy_ao
from fuzzyctl.diagnostics import DiagnosticError, InputError
from fuzzyctl.fcl import parse_fcl
from fuzzyctl.formats.fpl.reader import read_fpl
from tests.conftest import EXAMPLES


def fpltest() -> FuzzyFB:
    return FuzzyFB(read_fpl((EXAMPLES / "fpltest.fpl").read_text()))


def call(fb: FuzzyFB, *inputs: float) -> float:
    fb.set_inputs(list(inputs))
    assert fb.execute() == Info.OK and fb.ENO
    return fb.OUTPUT1


def f32(x: float) -> float:
    return float(np.float32(x))


# ---------------------------------------------------------------- 1.3 / 1.4 FPLTEST


# Section 1.4: x_S' = (mu_A x_A + mu_B x_B + ...) / (mu_A + mu_B + ...), one mu per rule (the
# glossary: "the influences on a particular linguistic value of the output variable
# resulting from various rules are added together"); AND is the minimum.  FPLTEST's rules:
# 1 cold&low -> inlet (+100), 2 cold&high -> closed (0), 3 hot&low -> closed, 4 hot&high ->
# drainage (-100); cold = (27 - T)/24 on [3, 27], low = (95 - p)/40 on [55, 95].
@pytest.mark.parametrize(
    ("temp", "pressure", "valve"),
    [
        # cold .75, hot .25, low .75, high .25: inlet .75, closed .25 + .25, drainage .25
        # -> (75 + 0 - 25) / (.75 + .5 + .25) = 100/3 (by the maximum it would be 50/1.25 = 40)
        (9.0, 65.0, 100.0 / 3.0),
        # cold 1, low .5, high .5: inlet .5, closed .5 -> 50 / 1
        (3.0, 75.0, 50.0),
        # cold 7/24, hot 17/24, low 7/8, high 1/8: inlet 7/24, closed 1/8 + 17/24, drainage
        # 1/8 -> (700/24 - 12.5) / (7/24 + 20/24 + 3/24) = 40/3
        (20.0, 60.0, 40.0 / 3.0),
        # symmetric: every rule .5, closed 1 -> (50 - 50) / 2 = 0
        (15.0, 75.0, 0.0),
        # hot 1, high 1: drainage only
        (30.0, 100.0, -100.0),
        # cold 5/8, hot 3/8, low 3/8, high 5/8: inlet 3/8, closed 5/8 + 3/8, drainage 3/8
        # -> (37.5 - 37.5) / (3/8 + 1 + 3/8) = 0 (by the maximum also 0: symmetric)
        (12.0, 80.0, 0.0),
        # cold 11/12, hot 1/12, low 1/4, high 3/4: inlet 1/4, closed 3/4 + 1/12, drainage 1/12
        # -> (25 - 25/3) / (1/4 + 10/12 + 1/12) = (50/3) / (7/6) = 100/7
        (5.0, 85.0, 100.0 / 7.0),
    ],
)
def test_siemens_1_4_fpltest_adds_the_rules_of_one_term_as_computed_by_hand(
    temp: float, pressure: float, valve: float
) -> None:
    assert call(fpltest(), temp, pressure) == f32(valve)


def test_siemens_1_4_block_adds_whatever_the_program_s_accu() -> None:
    # The same rules written with ACCU : MAX still run as the block computes (1.4): the
    # block has no other accumulation.  The IEC engine keeps Table 5 for the program.
    import fuzzyctl

    text = (EXAMPLES / "siemens_fpltest.fcl").read_text().replace("ACCU : NSUM;", "ACCU : MAX;")
    program = parse_fcl(text)
    fb = FuzzyFB(program)
    assert any(d.code == "siemens-accumulation" for d in fb.diagnostics)
    assert call(fb, 9.0, 65.0) == f32(100 / 3)
    assert fuzzyctl.compile(program).evaluate({"Temp": 9.0, "Pressure": 65.0})["Valve"] == pytest.approx(40.0)


def test_siemens_1_3_fpltest_and_iec_figure_7() -> None:
    # Figure 7 differs from FPLTEST only by "WITH 0.8" on rule 2 (and DEFAULT := 0); run by
    # the block it adds 0.8 * rule 2 + rule 3 on "closed".  They agree where rule 2 is 0.
    figure7 = FuzzyFB(parse_fcl((EXAMPLES / "figure7.fcl").read_text()), check_profile=False)
    for temp, pressure in ((15, 50), (27, 90), (30, 100), (9, 55)):
        assert call(figure7, temp, pressure) == call(fpltest(), temp, pressure)
    # Temp 3, Pressure 75: inlet .5, closed .5 (FPLTEST) or .4 (figure 7) -> 50 / 0.9.
    assert call(figure7, 3.0, 75.0) == f32(50 / 0.9)
    assert call(fpltest(), 3.0, 75.0) == 50.0
    # Temp 9, Pressure 65: inlet .75, closed .8 * .25 + .25 = .45, drainage .25 -> 50 / 1.45
    assert call(figure7, 9.0, 65.0) == f32(50 / 1.45)


# ---------------------------------------------------------------- 3.1 INFO, START_STOP, ENO


def test_siemens_3_1_info_00_processed_and_real_outputs() -> None:
    fb = fpltest()
    assert fb.START_STOP == 0xFFFF  # enabled by the download, as the configuration tool does
    assert call(fb, 20.0, 60.0) == f32(40 / 3) != 40 / 3  # a REAL holds single precision
    assert fb.INFO == 0x00 and fb.ENO is True


def test_siemens_3_1_start_stop_0_gives_info_01_and_keeps_outputs() -> None:
    fb = fpltest()
    call(fb, 9.0, 65.0)
    fb.START_STOP = 0
    fb.set_inputs({"Temp": 30.0, "Pressure": 100.0})
    assert fb.execute() == Info.DISABLED == 0x01 and fb.ENO is False
    old = f32(100 / 3)
    assert fb.outputs[0] == old  # old value
    fb.START_STOP = 123  # any non-zero word processes
    assert fb.execute() == 0x00 and fb.OUTPUT1 == -100.0


def test_siemens_3_1_no_valid_application_gives_info_11() -> None:
    fb = FuzzyFB()
    assert fb.execute() == Info.NO_APPLICATION == 0x11 and not fb.ENO
    fb.START_STOP = 0  # 11 even on a fresh block whose START_STOP is 0
    assert fb.execute() == 0x11
    short = FuzzyFB(read_fpl((EXAMPLES / "fpltest.fpl").read_text()), db_length=1000)
    assert short.execute() == Info.DB_TOO_SHORT == 0x21 and short.OUTPUT1 == 0.0


def test_siemens_3_1_download_refuses_what_the_block_cannot_hold() -> None:
    figure7 = parse_fcl((EXAMPLES / "figure7.fcl").read_text())  # WITH 0.8
    with pytest.raises(DiagnosticError, match="no rule weights"):
        FuzzyFB(figure7)
    fb = FuzzyFB()
    fb.download(read_fpl((EXAMPLES / "fpltest.fpl").read_text()))
    assert fb.has_application and fb.input_names == ("Temp", "Pressure") and fb.output_names == ("Valve",)


# ---------------------------------------------------------------- 1.5 marginal cases

MARGINAL = """PROJECT marginal
VAR x TYPE float MIN 0 MAX 20
  MEMBER a POINTS 0,0 5,1 10,0 END
  MEMBER up POINTS 0,0 40,1 END
  MEMBER down POINTS 0,1 40,0 END
END
VAR y TYPE float MIN 0 MAX 100
  MEMBER lo POINTS -0.25,1 0.25,1 END
  MEMBER hi POINTS 99.75,1 100.25,1 END
END
VAR z TYPE float MIN 0 MAX 100
  MEMBER lo POINTS -0.25,1 0.25,1 END
  MEMBER hi POINTS 99.75,1 100.25,1 END
END
FUZZY r
RULE only_a IF (x is a) THEN y = hi END
RULE up IF (x is up) THEN z = hi END
RULE down IF (x is down) THEN z = lo END
END
CONNECT FROM x TO r END CONNECT FROM r TO y END CONNECT FROM r TO z END
END
"""


def test_siemens_1_5_input_clamped_to_limits() -> None:
    fb = FuzzyFB(read_fpl(MARGINAL))
    # "up"/"down" reach beyond MAX = 20: at the limit they are .5 each -> z = 50; were x = 40
    # used as is, "up" would be 1 and z = 100.
    fb.INPUT1 = 40.0
    fb.execute()
    assert fb.OUTPUT2 == 50.0
    assert fb.INPUT1 == 40.0  # the input parameter itself is left as written
    fb.INPUT1 = -30.0  # below MIN: as at 0 -> down 1 -> z = 0
    fb.execute()
    assert fb.OUTPUT2 == 0.0


def test_siemens_1_5_no_rule_fired_keeps_the_last_output_0_before() -> None:
    fb = FuzzyFB(read_fpl(MARGINAL))
    fb.INPUT1 = 15.0  # "a" is 0: no rule for y
    assert fb.execute() == 0x00 and fb.OUTPUT1 == 0.0  # no value yet: 0
    fb.INPUT1 = 5.0
    fb.execute()
    assert fb.OUTPUT1 == 100.0
    fb.INPUT1 = 15.0
    fb.execute()
    assert fb.OUTPUT1 == 100.0  # the last defined value
    assert fb.outputs[1] == f32(100 * 15 / 40)  # z still computed: up 3/8, down 5/8


def test_siemens_1_5_empty_if_part_acts_with_degree_1() -> None:
    src = MARGINAL.replace("END\nCONNECT", "RULE always THEN y = lo END\nEND\nCONNECT")
    fb = FuzzyFB(read_fpl(src))
    fb.INPUT1 = 5.0  # a = 1 (hi) and the empty-IF rule 1 (lo): (100 + 0) / 2
    fb.execute()
    assert fb.OUTPUT1 == 50.0
    fb.INPUT1 = 15.0  # only the empty-IF rule
    fb.execute()
    assert fb.OUTPUT1 == 0.0


def test_siemens_1_5_rule_without_then_part_has_no_influence() -> None:
    src = MARGINAL.replace("END\nCONNECT", "RULE test IF (x is down) END\nEND\nCONNECT")
    fb = FuzzyFB(read_fpl(src))
    fb.INPUT1 = 5.0
    fb.execute()
    assert fb.outputs[:2] == (100.0, f32(100 * 5 / 40))


def test_siemens_1_5_no_rules_at_all_outputs_stay_0() -> None:
    src = MARGINAL[: MARGINAL.index("FUZZY r")] + "FUZZY r END\nEND\n"
    fb = FuzzyFB(read_fpl(src))
    fb.INPUT1 = 5.0
    assert fb.execute() == 0x00 and fb.outputs == (0.0, 0.0, 0.0, 0.0)


def test_siemens_3_1_inputs_must_be_finite_reals() -> None:
    fb = fpltest()
    fb.INPUT2 = float("nan")
    with pytest.raises(InputError, match="INPUT2"):
        fb.execute()
    with pytest.raises(InputError, match="not an input"):
        fb.set_inputs({"Flow": 1.0})


# ---------------------------------------------------------------- 3.2 FUZZY_AI


def test_siemens_3_2_fuzzy_ai_unipolar_bipolar_thermocouple() -> None:
    fb = fpltest()  # Temp 0..30, Pressure 50..100
    # unipolar: (0 (27648 - 13824) + 30 * 13824) / 27648 = 15
    r = fuzzy_ai(fb, 13824, input_nr=1)
    assert (r.info, r.eno, r.value, fb.INPUT1) == (0x00, True, 15.0, 15.0)
    # bipolar: (50 (27648 - Xi) + 100 (Xi + 27648)) / (2 * 27648): -27648 -> 50, 0 -> 75, 27648 -> 100
    assert [fuzzy_ai(fb, xi, bipolar=True, input_nr=2).value for xi in (-27648, 0, 27648)] == [
        50.0,
        75.0,
        100.0,
    ]
    # 3.2 note: a bipolar signal needs symmetric MIN/MAX; Pressure 50..100 is not, and the
    # result says so (the value is the manual's formula all the same)
    bipolar = fuzzy_ai(fb, 0, bipolar=True, input_nr=2)
    assert bipolar.warning is not None and "MIN 50 and MAX 100 are not symmetric" in bipolar.warning
    assert fuzzy_ai(fb, 0, input_nr=2).warning is None  # unipolar: no such constraint
    # FACTOR and OFFSET: 75 * 2 - 10 = 140, written as is (the FB clamps, not FUZZY_AI)
    assert fuzzy_ai(fb, 0, bipolar=True, factor=2.0, offset=-10.0, input_nr=2).value == 140.0
    assert fb.INPUT2 == 140.0
    # thermocouple: tenths of a degree -> 853 / 10 * 1.5 + 2 = 129.95; BIPOLAR ignored
    r = fuzzy_ai(fb, 853, therm_el=True, bipolar=True, factor=1.5, offset=2.0, input_nr=3)
    assert r.value == pytest.approx(129.95) and fb.inputs[2] == f32(129.95)


def test_siemens_3_2_fuzzy_ai_info_codes() -> None:
    fb = fpltest()
    for nr in (0, 9, -1):
        r = fuzzy_ai(fb, 100, input_nr=nr)
        assert (r.info, r.eno, r.value) == (0x31, False, None)
    assert fb.inputs == (0.0,) * 8  # nothing written
    fb.START_STOP = 0
    assert fuzzy_ai(fb, 100).info == 0x01 and fb.INPUT1 == 0.0
    assert fuzzy_ai(FuzzyFB(), 100).info == 0x11
    assert fuzzy_ai(FuzzyFB(db_length=10), 100, input_nr=12).info == 0x21  # 21 first
    with pytest.raises(InputError, match="16-bit"):
        fuzzy_ai(fpltest(), 40000)
    # An input the application does not use has MIN = MAX = 0: only OFFSET remains.
    assert fuzzy_ai(fpltest(), 27648, offset=3.0, input_nr=5).value == 3.0


# ---------------------------------------------------------------- 3.3 FUZZY_AO


def test_siemens_3_3_fuzzy_ao_bipolar_unipolar() -> None:
    fb = fpltest()  # Valve -101..101
    call(fb, 9.0, 65.0)  # OUTPUT1 = 100/3 as a REAL
    out = f32(100 / 3)
    # bipolar: 27648 (2 * 33.33 - 101 + 101) / 202 = 9124.75 -> 9125
    r = fuzzy_ao(fb, bipolar=True)
    assert (r.info, r.eno, r.word) == (0x00, True, 9125) and r.value == pytest.approx(55296 * out / 202)
    assert r.warning is None  # -101..101 is symmetric
    # unipolar: 27648 (33.33 + 101) / 202 = 18386.38 -> 18386
    assert fuzzy_ao(fb).word == 18386
    # FACTOR 0.5, OFFSET 100: 9124.75 * 0.5 + 100 = 4662.38 -> 4662
    assert fuzzy_ao(fb, bipolar=True, factor=0.5, offset=100.0).word == 4662
    # saturated to the INT range
    assert fuzzy_ao(fb, factor=10.0).word == 32767


def test_siemens_3_3_fuzzy_ao_info_codes() -> None:
    fb = fpltest()
    assert [fuzzy_ao(fb, output_nr=n).info for n in (0, 5)] == [0x31, 0x31]
    fb.START_STOP = 0
    r = fuzzy_ao(fb)
    assert (r.info, r.eno, r.word) == (0x01, False, None)
    assert fuzzy_ao(FuzzyFB()).info == 0x11
    assert fuzzy_ao(FuzzyFB(db_length=2125)).info == 0x21
    assert fuzzy_ao(fpltest(), output_nr=2).info == 0x11  # unused output: MIN = MAX
