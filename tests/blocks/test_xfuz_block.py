"""The XFUZ block (Schneider manual chapter 2): parameters of 2.3, STATUS/ERROR/INHIB of
2.4, COMMAND of 2.5, the modes of 2.6, forcing of 2.7, checks of 2.8 and the inference
of 2.2 on the worked example of 3.3 (numbers worked out by hand in the comments)."""

from __future__ import annotations

from dataclasses import replace

import pytest

from fuzzyctl.blocks.schneider import XfuzConstants, XfuzFB
from fuzzyctl.diagnostics import InputError
from fuzzyctl.formats.xfuz.tables import encode_name
from tests.blocks.manual_3_3 import ESV, FA, RG, words

ESV_DISCR6 = {**ESV, 24: 6}  # Ouverture 0..10 with Discr 6: 10 >= 2 * (6 - 1)


def example(esv: dict[int, int] | None = None, **changes: object) -> XfuzConstants:
    c = XfuzConstants(esv=words(esv or ESV_DISCR6, 62), fa=words(FA, 576), rg=words(RG, 384))
    return replace(c, **changes) if changes else c


def auto(fb: XfuzFB, pression: int, temperature: int) -> XfuzFB:
    """One inference on demand in AUTOMATIC mode."""
    fb.MAN_AUTO = 1
    fb["INP1"], fb["INP4"] = pression, temperature
    fb.CONT_ASK, fb.START = 1, 0
    fb.execute()
    fb.START = 1
    fb.execute()
    assert fb.inferred
    return fb


# ---------------------------------------------------------------- 3.3 worked example


def test_xfuz_3_3_block_computes_ouverture_through_debit() -> None:
    # Pression 0, Température -50: Pression faible = 1, Température élevée = 0 (non élevée 1),
    # so REG0 "-> Débit fort" has degree 1 and REG1, REG2 are 0.  Second inference: Débit
    # faible is incompatible with the set "fort" (they do not overlap): REG3 = 0; Débit fort
    # meets it at 1: REG4 = 1 -> Ouverture grande.  On the Discr 6 points 0,2,...,10,
    # grande = 0, 0, .25, .75, 1, 1: CoG = (4*.25 + 6*.75 + 8 + 10) / 3 = 23.5/3 = 7.83 -> 8.
    fb = auto(XfuzFB(example()), 0, -50)
    assert fb["OUT3"] == 8 and fb["O3_CALC"] == 8
    assert fb.DEGRE[:6] == [255, 0, 0, 0, 255, 0]
    assert fb.STATUS == 0 and not fb.ERROR


def test_xfuz_3_3_second_inference_uses_the_fuzzy_debit_not_a_number() -> None:
    # Pression 20: faible 0, moyenne (25-20)/10 = .5, forte 1.  Température 10: élevée
    # (10-1)/29 = 9/29.  REG0 = 0, REG1 = 1 (Débit faible), REG2 = min(9/29, .5) = 9/29
    # (Débit moyen).  Débit set F = max(faible, min(9/29, moyen)) on 20 points 800k/19.
    # REG3: Débit faible meets F at x=0: 1.  REG4: Débit fort meets F best at x=463.2 where
    # fort = .632 and F = 9/29: 9/29.  Ouverture on 0,2,..,10: petite 1,1,.75,.25,0,0 and
    # grande cut at 9/29: 0,0,.25,9/29,9/29,9/29 -> F = 1,1,.75,9/29,9/29,9/29.
    # CoG = (2 + 3 + 24*9/29) / (2.75 + 27/29) = 12.448/3.681 = 3.38 -> 3.
    fb = auto(XfuzFB(example()), 20, 10)
    assert fb["OUT3"] == 3
    assert fb.DEGRE[:5] == [0, 255, 79, 255, 79]  # 255 * 9/29 = 79.1
    assert fb.last_result is not None
    assert fb.last_result.outputs[3] == pytest.approx((2 + 3 + 24 * 9 / 29) / (2.75 + 27 / 29))


def test_xfuz_3_3_as_printed_is_blocked_by_the_discretisation_check() -> None:
    # The printed example gives Ouverture (0..10) Discr 20, but 3.2-2 wants
    # BorneSup - BorneInf >= 2 (Discr - 1) = 38: STATUS bit 9, ERROR, no inference.
    fb = XfuzFB(example(ESV))
    assert fb.status_bits == (9,) and fb.ERROR
    auto_attempt = XfuzFB(example(ESV))
    auto_attempt.MAN_AUTO, auto_attempt["INP1"], auto_attempt.START = 1, 0, 1
    auto_attempt.execute()
    assert not auto_attempt.inferred and auto_attempt["OUT3"] == 0


def test_xfuz_3_3_as_printed_with_the_span_rule_relaxed() -> None:
    # Same case as the first test on the printed 20 points 10k/19: grande = 0 up to 3,
    # (x-3)/4 up to 7, then 1: CoG = 7.5014 -> 8.
    fb = auto(XfuzFB(example(ESV), span_rule=False), 0, -50)
    xs = [10 * k / 19 for k in range(20)]
    grande = [0.0 if x <= 3 else 1.0 if x >= 7 else (x - 3) / 4 for x in xs]
    expected = sum(x * g for x, g in zip(xs, grande, strict=True)) / sum(grande)
    assert expected == pytest.approx(7.5014, abs=1e-4)
    assert fb.last_result is not None and fb.last_result.outputs[3] == pytest.approx(expected)
    assert fb["OUT3"] == 8 and fb.STATUS == 0
    # Second case on the same 20 points: max(petite, min(9/29, grande)) -> 3.578 -> 4.
    auto(fb, 20, 10)
    petite = [1.0 if x <= 3 else 0.0 if x >= 7 else (7 - x) / 4 for x in xs]
    f = [max(p, min(9 / 29, g)) for p, g in zip(petite, grande, strict=True)]
    expected = sum(x * v for x, v in zip(xs, f, strict=True)) / sum(f)
    assert expected == pytest.approx(3.5777, abs=1e-4)
    assert fb.last_result is not None and fb.last_result.outputs[3] == pytest.approx(expected)
    assert fb["OUT3"] == 4


def test_xfuz_2_2_3_product_for_and_and_implication() -> None:
    # OP_ET = OP_IMPL = 1 on the second case: REG2 = 9/29 * .5 = .1552; F = max(faible,
    # .1552 moyen); REG4 = best of min(F, fort) = at x=421.05: min(.1552*.7895, .2105) = .1225.
    # Ouverture: max(petite, .1225 grande) = 1,1,.75,.25,.1225,.1225 -> CoG 8.705/3.245 = 2.68.
    fb = auto(XfuzFB(example(op_et=1, op_impl=1)), 20, 10)
    reg4 = 9 / 58 * (500 - 8000 / 19) / 100
    assert fb.DEGRE[:5] == [0, 255, 40, 255, 31]
    assert fb.last_result is not None
    assert fb.last_result.degrees[4] == pytest.approx(reg4)
    assert fb.last_result.outputs[3] == pytest.approx((2 + 3 + 1.5 + 18 * reg4) / (3 + 2 * reg4))
    assert fb["OUT3"] == 3


def test_xfuz_2_2_5_mean_of_maxima() -> None:
    # First case with OP_DEFUZ = 1: grande at 1 on the points 8 and 10 -> 9.
    fb = auto(XfuzFB(example(op_defuz=1)), 0, -50)
    assert fb["OUT3"] == 9


def singleton_base(**changes: object) -> XfuzConstants:
    """INP1 (0..100) low (open left, C 20, D 60) / high (A 40, B 80, open right) ->
    OUT1 (0..1000) full (1000) / off (0)."""
    fa = [0] * 576
    fa[0:9] = (*encode_name("low"), 0, -32768, -32768, 20, 60)
    fa[9:18] = (*encode_name("high"), 0, 40, 80, 32767, 32767)
    fa[18:27] = (*encode_name("full"), 8, 1000, 1000, 1000, 1000)
    fa[27:36] = (*encode_name("off"), 8, -32768, 0, 9, 9)  # xB counts; xB=-32768 would take xC
    fa[40] = 999
    rg = [0] * 384
    rg[0:6] = (0, 999, 999, 999, 2, 999)
    rg[6:12] = (1, 999, 999, 999, 3, 999)
    rg[12:16] = (999,) * 4
    esv = [0] * 62
    esv[0:2] = (0, 100)
    esv[16:19] = (0, 1000, 20)
    c = XfuzConstants(out_pt=True, esv=tuple(esv), fa=tuple(fa), rg=tuple(rg))
    return replace(c, **changes) if changes else c


@pytest.mark.parametrize(("level", "pump"), [(50, 500), (30, 1000), (45, 750), (90, 0)])
def test_xfuz_3_2_3_singleton_outputs_with_out_pt(level: int, pump: int) -> None:
    # 50: low .25, high .25 -> 500; 30: low .75 -> 1000; 45: .375/.125 -> 750; 90: high 1 -> 0.
    fb = XfuzFB(singleton_base())
    fb.MAN_AUTO, fb["INP1"], fb.START = 1, level, 1
    fb.execute()
    assert fb["OUT1"] == pump


def test_xfuz_3_2_3_singleton_point_is_xc_when_xb_is_open() -> None:
    c = singleton_base()
    fa = list(c.fa)
    fa[18:27] = (*encode_name("full"), 8, -32768, -32768, 700, 32767)
    fb = XfuzFB(replace(c, fa=tuple(fa)))
    fb.MAN_AUTO, fb["INP1"], fb.START = 1, 30, 1
    fb.execute()
    assert fb["OUT1"] == 700


# ---------------------------------------------------------------- 2.3 parameters, 2.4 STATUS


def test_xfuz_2_3_words_are_16_bit_integers() -> None:
    fb = XfuzFB(example())
    with pytest.raises(InputError, match="INP2"):
        fb["INP2"] = 40000
    fb.arrays["INP"][2] = 1.5  # type: ignore[call-overload]
    with pytest.raises(InputError, match="INP3"):
        fb.execute()
    with pytest.raises(KeyError, match="read only"):
        fb["OUT1"] = 3
    with pytest.raises(InputError, match="a bit is 0 or 1"):
        fb["START"] = 2


def test_xfuz_2_3_man_auto_selects_manual_or_computed_outputs() -> None:
    fb = XfuzFB(example(o_def=(0, 0, 5, 0, 0, 0)))
    assert fb.MAN_AUTO == 0  # MANUAL by default
    fb["O3_MAN"] = 2
    fb["INP1"], fb["INP4"], fb.START = 0, -50, 1
    fb.execute()
    # O3_CALC is updated whatever MAN_AUTO is; OUT3 shows O3_MAN.
    assert fb["O3_CALC"] == 8 and fb["OUT3"] == 2
    fb.MAN_AUTO = 1
    fb.execute()
    assert fb["OUT3"] == 8
    fb.MAN_AUTO = 0
    fb.execute()
    assert fb["OUT3"] == 2


def test_xfuz_2_4_default_value_bits_0_to_5_and_no_rule_bit_6() -> None:
    # Singleton base plus OUT2 with one rule "high -> OUT2 on (50)".  Level 30: low .75,
    # high 0: OUT1 computed, nothing for OUT2 -> O2_DEF and STATUS bit 1 (information).
    c = singleton_base(o_def=(0, 4, 0, 0, 0, 0))
    fa, rg, esv = list(c.fa), list(c.rg), list(c.esv)
    fa[36:45] = (*encode_name("on"), 9, 50, 50, 50, 50)
    fa[49] = 999
    rg[12:18] = (1, 999, 999, 999, 4, 999)
    rg[18:22] = (999,) * 4
    esv[19:22] = (0, 100, 20)
    fb = XfuzFB(replace(c, fa=tuple(fa), rg=tuple(rg), esv=tuple(esv)))
    fb.MAN_AUTO, fb["INP1"], fb.START = 1, 30, 1
    fb.execute()
    assert (fb["OUT1"], fb["OUT2"]) == (1000, 4) and fb.status_bits == (1,) and not fb.ERROR
    fb["O2_DEF"] = 6  # the internal datum is what the block uses
    fb.START = 0
    fb.execute()
    fb.START = 1
    fb.execute()
    assert fb["OUT2"] == 6
    # 3.3 example, Pression 0 and Température 100: faible 1 but non élevée 0, moyenne and
    # forte 0: no rule at all -> O3_DEF (bit 2) and the "no active rule" alarm (bit 6).
    fb = auto(XfuzFB(example(o_def=(0, 0, 4, 0, 0, 0))), 0, 100)
    assert fb["OUT3"] == 4 and fb.status_bits == (2, 6) and not fb.ERROR  # alarm, not error
    fb.COMMAND = 1 << 8  # 2.5 bit 8: inhibits the "no active rule" alarm
    fb.execute()
    assert fb.status_bits == (2,)


def test_xfuz_2_4_error_bit_inhib_and_blocked_inference() -> None:
    fb = XfuzFB(example(ESV))  # bit 9 (see 3.3)
    assert fb.ERROR and fb.STATUS == 1 << 9
    fb.INHIB = 1
    fb.execute()
    assert not fb.ERROR and fb.STATUS == 1 << 9  # INHIB keeps ERROR down, STATUS still tells
    fb.INHIB = 0
    fb.execute()
    assert fb.ERROR


def test_xfuz_2_3_degre_holds_each_rule_activation() -> None:
    fb = auto(XfuzFB(example()), 20, 10)
    assert len(fb.DEGRE) == 64 and fb.DEGRE[:5] == [0, 255, 79, 255, 79] and set(fb.DEGRE[5:]) == {0}
    assert fb["DEGRE[2]"] == 79


# ---------------------------------------------------------------- 2.5 COMMAND, 2.7 forcing


def test_xfuz_2_7_command_bits_0_to_7_force_inputs_with_ii_sim() -> None:
    fb = XfuzFB(example())
    fb.MAN_AUTO = 1
    fb["INP1"], fb["INP4"] = 20, 10  # the real inputs give OUT3 = 3
    fb["I1_SIM"], fb["I4_SIM"] = 0, -50  # the forced ones give 8
    fb.COMMAND = 0b1001
    fb.START = 1
    fb.execute()
    assert fb["OUT3"] == 8
    fb.COMMAND = 0
    fb.START = 0
    fb.execute()
    fb.START = 1
    fb.execute()
    assert fb["OUT3"] == 3
    # Forcing works whatever MAN_AUTO, START and CONT_ASK are (2.3, "Rq"): only bit 3 now.
    fb.COMMAND = 0b1000
    fb.START = 0
    fb.execute()
    fb.START = 1
    fb.execute()
    # INP1 = 20 (forte 1, moyenne .5), INP4 forced to -50 (élevée 0): REG1 = 1 only, Débit
    # = faible, Ouverture = petite: (0 + 2 + 4*.75 + 6*.25) / 3 = 2.17 -> 2.
    assert fb["OUT3"] == 2


# ---------------------------------------------------------------- 2.6 modes


def test_xfuz_2_6_1_cold_restart_copies_the_dollar_constants() -> None:
    fb = XfuzFB(example(contask=False, t_ofb=50, o_def=(1, 2, 3, 4, 5, 6)))
    assert fb.CONT_ASK == 0 and fb.T_OFB == 50
    for i in range(1, 7):
        assert fb[f"OUT{i}"] == fb[f"O{i}_MAN"] == fb[f"O{i}_CALC"] == fb[f"O{i}_DEF"] == i
    assert (fb.MAN_AUTO, fb.START, fb.INIT, fb.REFRESH, fb.INHIB, fb.COMMAND, fb.MONITOR) == (0,) * 7
    assert fb.status_bits == () and fb.kb.rules and len(fb.kb.memberships) == 10


def test_xfuz_2_6_2_warm_restart_continues_where_it_was() -> None:
    fb = auto(XfuzFB(example()), 0, -50)
    before = (fb.snapshot(), fb.MAN_AUTO, fb.START, fb["I1_SIM"])
    fb.warm_restart()
    assert (fb.snapshot(), fb.MAN_AUTO, fb.START, fb["I1_SIM"]) == before


def test_xfuz_2_6_3_rising_edge_of_init() -> None:
    fb = auto(XfuzFB(example(o_def=(0, 0, 1, 0, 0, 0))), 0, -50)
    fb["O3_MAN"], fb["I1_SIM"], fb.COMMAND, fb.INHIB = 7, 3, 1, 1
    assert fb["OUT3"] == 8
    fb.INIT = 1
    snap = fb.execute()
    # As a cold restart: outputs at O3_DEF$, everything else 0, MANUAL mode.
    assert snap.out[2] == 1 and fb["O3_MAN"] == 1 and fb["O3_CALC"] == 1
    assert (fb.MAN_AUTO, fb.START, fb.COMMAND, fb.INHIB, fb["I1_SIM"], fb.INIT) == (0, 0, 0, 0, 0, 0)
    assert not snap.inferred and set(snap.degre) == {0}
    fb.INIT = 1  # a new edge initialises again
    fb["O3_MAN"] = 9
    fb.execute()
    assert fb["O3_MAN"] == 1


def test_xfuz_2_6_4_rising_edge_of_refresh() -> None:
    fb = auto(XfuzFB(example()), 0, -50)
    fb.CONT_ASK = 0  # continuous
    fb["I2_SIM"] = 11
    # New constants written "in constant mode": singleton base, other defaults.
    fb.constants = replace(singleton_base(), o_def=(3, 0, 0, 0, 0, 0), contask=True, t_ofb=30)
    fb.execute()
    assert fb.kb.memberships[0].name == "faible"  # not loaded yet: only INIT/REFRESH load
    fb.REFRESH = 1
    snap = fb.execute()
    assert not snap.inferred  # the Grafcet goes straight to OUT after the update
    assert fb.kb.memberships[0].name == "low" and fb["OUT1"] == 3 and fb["O1_MAN"] == 3
    assert fb.CONT_ASK == 1 and fb.T_OFB == 30  # $ constants copied
    assert (fb.MAN_AUTO, fb.START, fb["I2_SIM"], fb.REFRESH) == (1, 1, 11, 1)  # the rest is kept
    fb.execute()  # REFRESH still 1: no new edge, a nominal cycle
    fb["INP1"], fb.START = 30, 0
    fb.execute()
    fb.START = 1
    fb.execute()
    assert fb["OUT1"] == 1000


def test_xfuz_2_6_4_refresh_keeps_degre_and_status_bits_0_to_6() -> None:
    # 2.6-4: on REFRESH "all the other internal data keep their values" (2.6-1: on a cold
    # restart they are set to 0).  A gap between "low" (D 30) and "high" (A 40): at 35 no
    # rule is active -> OUT1 at its default (bit 0) and the "no active rule" alarm (bit 6).
    gap = list(singleton_base().fa)
    gap[0:9] = (*encode_name("low"), 0, -32768, -32768, 20, 30)
    with_gap = replace(singleton_base(), fa=tuple(gap), contask=True)
    no_gap = replace(singleton_base(), contask=True)

    def infer(fb: XfuzFB, level: int) -> None:
        fb["INP1"], fb.START = level, 0
        fb.execute()
        fb.START = 1
        fb.execute()
        assert fb.inferred

    def refresh(fb: XfuzFB, constants: XfuzConstants) -> None:
        fb.constants, fb.REFRESH = constants, 1
        snap = fb.execute()
        assert not snap.inferred and fb.kb.memberships[0].points[3] == (30 if constants is with_gap else 60)
        fb.REFRESH = 0

    fb = XfuzFB(with_gap)
    fb.MAN_AUTO = 1
    infer(fb, 25)  # low (30 - 25) / 10 = .5 -> 255 * .5 = 127.5 -> 128
    assert fb.DEGRE[:2] == [128, 0] and fb.status_bits == ()
    refresh(fb, no_gap)  # a new knowledge base: DEGRE stays until the next inference
    assert fb.DEGRE[:2] == [128, 0] and fb.snapshot().degre[:2] == (128, 0)
    infer(fb, 35)  # now low (60 - 35) / 40 = .625 -> 159.4 -> 159
    assert fb.DEGRE[:2] == [159, 0]

    refresh(fb, with_gap)
    infer(fb, 35)
    assert fb.DEGRE[:2] == [0, 0] and fb.status_bits == (0, 6)
    refresh(fb, no_gap)  # bits 0-6 of the last inference stay (bits 7-14: the new base's checks)
    assert fb.status_bits == (0, 6) and not fb.ERROR
    infer(fb, 35)
    assert fb.status_bits == () and fb.DEGRE[:2] == [159, 0]
    refresh(fb, with_gap)
    infer(fb, 35)
    assert fb.status_bits == (0, 6)
    fb.INIT = 1  # cold restart: set to 0
    fb.execute()
    fb.START = 0
    fb.execute()
    infer(fb, 25)
    fb.INIT = 1
    fb.execute()
    assert fb.DEGRE == [0] * 64 and fb.status_bits == ()


def test_xfuz_2_6_5_on_demand_infers_on_each_rising_edge_of_start() -> None:
    fb = XfuzFB(example())  # CONTASK$ = 1 by default
    fb.MAN_AUTO, fb["INP1"], fb["INP4"] = 1, 0, -50
    runs = []
    for start in (0, 1, 1, 1, 0, 1, 0, 0, 1):
        fb.START = start
        runs.append(fb.execute().inferred)
    assert runs == [False, True, False, False, False, True, False, False, True]


def test_xfuz_2_6_5_continuous_mode_every_t_ofb_rounded_to_the_task_period() -> None:
    # T_OFB$ = 7 hundredths in a 20 ms task: 3.5 periods, rounded to 4 -> T_OFB = 8.
    fb = XfuzFB(example(contask=False, t_ofb=7), task_period=0.02)
    fb.MAN_AUTO, fb["INP1"], fb["INP4"], fb.START = 1, 0, -50, 1
    runs = [fb.execute().inferred for _ in range(12)]
    assert fb.T_OFB == 8
    assert [i for i, r in enumerate(runs) if r] == [3, 7, 11]
    fb.START = 0
    assert not any(fb.execute().inferred for _ in range(8))
    fb.T_OFB = 0  # zero rounds up to one task period: every cycle
    fb.START = 1
    assert all(fb.execute().inferred for _ in range(3)) and fb.T_OFB == 2


def test_xfuz_2_8_checks_only_on_cold_restart_init_and_refresh() -> None:
    fb = XfuzFB(example())
    fb.MAN_AUTO = 1
    # Switching to singleton outputs with a second inference "in constant mode" goes unseen...
    fb.constants = replace(fb.constants, out_pt=True)
    fb.START = 1
    fb["INP1"], fb["INP4"] = 0, -50
    fb.execute()
    assert fb.STATUS & (1 << 14) == 0 and fb.inferred
    # ... until REFRESH: bit 14, ERROR, inferences blocked (bit 2, OUT3 at its default in
    # the last inference, is information REFRESH keeps, 2.6-4).
    fb.REFRESH = 1
    fb.execute()
    assert fb.status_bits == (2, 14) and fb.ERROR
    fb.REFRESH = fb.START = 0
    fb.execute()
    fb.START = 1
    assert not fb.execute().inferred


def test_xfuz_2_8_mean_of_maxima_in_singleton_mode_falls_back_to_the_centre_of_gravity() -> None:
    # Set without REFRESH (2.8 remark): "defuzzification is always by centre of gravity".
    fb = XfuzFB(singleton_base())
    fb.constants = replace(fb.constants, op_defuz=1)
    fb.MAN_AUTO, fb["INP1"], fb.START = 1, 45, 1
    fb.execute()
    assert fb["OUT1"] == 750
