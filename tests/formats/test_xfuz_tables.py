"""XFUZ knowledge-base tables (Schneider manual 3.2, 2.8, 3.3): word encoding, every
consistency check with its STATUS bit, the worked example 3.3 decoded, re-encoded and
read from the documented JSON/CSV layouts."""

from __future__ import annotations

from dataclasses import replace

import pytest

from fuzzyctl.diagnostics import DiagnosticError
from fuzzyctl.formats.xfuz.reader import model_from_constants, read_tables, read_xfuz
from fuzzyctl.formats.xfuz.tablefile import write_tables
from fuzzyctl.formats.xfuz.tables import (
    StatusBit,
    XfuzConstants,
    decode_kb,
    decode_name,
    encode_name,
)
from fuzzyctl.formats.xfuz.writer import constants_from_model, write_xfuz
from fuzzyctl.model import (
    And,
    Conclusion,
    Default,
    DefuzzifyBlock,
    Document,
    FunctionBlock,
    FuzzifyBlock,
    Is,
    Point,
    PointsMF,
    Range,
    Rule,
    RuleBlock,
    SingletonMF,
    Term,
    Variable,
    VarKind,
)
from tests.blocks.manual_3_3 import ESV, FA, RG, words
from tests.conftest import EXAMPLES


def manual_constants(**changes: object) -> XfuzConstants:
    c = XfuzConstants(esv=words(ESV, 62), fa=words(FA, 576), rg=words(RG, 384))
    return replace(c, **changes) if changes else c


def pts(*xy: tuple[float, float]) -> PointsMF:
    return PointsMF(tuple(Point(float(x), float(y)) for x, y in xy))


# ---------------------------------------------------------------- 3.2-1 ASCII strings


def test_xfuz_3_2_1_two_characters_per_word_second_times_256_plus_first() -> None:
    assert encode_name("faible") == (0x6166, 0x6269, 0x656C, 0)
    assert encode_name("moyen") == (0x6F6D, 0x6579, 0x006E, 0)
    # The manual's "Dé" is H'8244' (é is 0x82 in the PC code page), -32188 as a signed word.
    assert encode_name("Débit") == (-32188, 26978, 116, 0)
    assert decode_name((-32188, 26978, 116, 0)) == "Débit"
    assert decode_name((27778, 30309, 25986, 0)) == "élevée"
    with pytest.raises(ValueError, match="longer than 8"):
        encode_name("tropgrande")


# ---------------------------------------------------------------- 3.3 worked example

EXPECTED_3_3 = FunctionBlock(
    "xfuz",
    variables=(
        Variable("INP1", VarKind.INPUT, "INT", range=Range(0, 35)),  # Pression
        Variable("INP4", VarKind.INPUT, "INT", range=Range(-50, 100)),  # Température
        Variable("OUT3", VarKind.OUTPUT, "INT", range=Range(0, 10)),  # Ouverture
        Variable("Débit", VarKind.LOCAL, "INT", range=Range(0, 800)),
    ),
    fuzzify=(
        FuzzifyBlock(
            "INP1",
            (
                Term("faible", pts((3, 1), (10, 0))),
                Term("moyenne", pts((1, 0), (15, 1), (25, 0))),
                Term("forte", pts((18, 0), (18, 1))),
            ),
        ),
        FuzzifyBlock("INP4", (Term("basse", pts((-10, 1), (20, 0))), Term("élevée", pts((1, 0), (30, 1))))),
        FuzzifyBlock(
            "Débit",
            (
                Term("faible", pts((100, 1), (200, 0))),
                Term("moyen", pts((100, 0), (200, 1), (400, 1), (500, 0))),
                Term("fort", pts((400, 0), (500, 1))),
            ),
        ),
    ),
    defuzzify=(
        DefuzzifyBlock(
            "OUT3",
            (Term("petite", pts((3, 1), (7, 0))), Term("grande", pts((3, 0), (7, 1)))),
            range=Range(0, 10),
            method="COG",
            default=Default(0.0),
        ),
        DefuzzifyBlock(
            "Débit",
            (
                Term("faible", pts((100, 1), (200, 0))),
                Term("moyen", pts((100, 0), (200, 1), (400, 1), (500, 0))),
                Term("fort", pts((400, 0), (500, 1))),
            ),
            range=Range(0, 800),
            method="COG",
        ),
    ),
    rule_blocks=(
        RuleBlock(
            "xfuz",
            (
                # Si Pression faible et Température non élevée alors Débit fort.
                Rule(
                    "0",
                    And((Is("INP1", "faible"), Is("INP4", "élevée", negated=True))),
                    (Conclusion("Débit", "fort"),),
                ),
                # Si Pression forte alors Débit faible.
                Rule("1", Is("INP1", "forte"), (Conclusion("Débit", "faible"),)),
                # Si Température élevée et Pression moyenne alors Débit moyen.
                Rule(
                    "2", And((Is("INP4", "élevée"), Is("INP1", "moyenne"))), (Conclusion("Débit", "moyen"),)
                ),
                # Si Débit faible alors Ouverture petite. / Si Débit fort alors Ouverture grande.
                Rule("3", Is("Débit", "faible"), (Conclusion("OUT3", "petite"),)),
                Rule("4", Is("Débit", "fort"), (Conclusion("OUT3", "grande"),)),
            ),
            and_op="MIN",
            act="MIN",
            accu="MAX",
        ),
    ),
)


def test_xfuz_3_3_printed_tables_decode_to_the_expected_program() -> None:
    block, diags = model_from_constants(manual_constants())
    assert replace(block, options=()) == EXPECTED_3_3
    # Discr 20 on a 0..10 output breaks the 3.2-2 rule: reported, not fatal for decoding.
    assert [d.code for d in diags] == ["xfuz-status-9"] and not diags[0].is_error
    text = block.options[0].text
    assert (
        "XFUZ SLOT Débit VAR1;" in text and "XFUZ DISCR OUT3 20;" in text and "XFUZ DISCR Débit 20;" in text
    )


def test_xfuz_3_3_program_re_encodes_to_the_same_words() -> None:
    original = manual_constants()
    block, _ = model_from_constants(original)
    again, diags = constants_from_model(block)
    assert not [d for d in diags if d.is_error]
    assert again.esv == original.esv
    assert again.fa == original.fa
    assert again.rg == original.rg
    assert again == original


def test_xfuz_3_3_example_files_hold_the_printed_tables() -> None:
    for name in ("xfuz_3_3.csv.xfuz", "xfuz_3_3.xfuz"):
        path = EXAMPLES / name
        assert read_tables(path.read_text(encoding="utf-8"), path=str(path)) == manual_constants(), name


@pytest.mark.parametrize("layout", ["json", "csv"])
def test_xfuz_table_files_round_trip(layout: str) -> None:
    c = manual_constants(op_et=1, op_defuz=1, contask=False, t_ofb=35, o_def=(1, -2, 3, 0, 0, 32767))
    text = write_tables(c, layout=layout)
    assert read_tables(text, path=f"kb.xfuz.{layout}") == c
    assert read_tables(text) == c  # detected by content


def test_xfuz_csv_layout_is_sparse_and_errors_name_the_line() -> None:
    c = read_tables("table,index,value,note\nCONST,OP_ET,1,\nESV,1,35,\nFA,4,999,\nRG,0,999\n")
    assert c.op_et == 1 and c.esv[1] == 35 and c.fa[4] == 999 and c.t_ofb == 200 and c.contask
    with pytest.raises(DiagnosticError) as info:
        read_tables("table,index,value\nESV,1,35\nFA,600,1\nESV,1,36\nRG,x,y\n", path="kb.xfuz.csv")
    found = [(d.span.line if d.span else None, d.message) for d in info.value.diagnostics]
    assert [line for line, _ in found] == [3, 4, 5]
    assert (
        "FA index '600'" in found[0][1] and "given twice" in found[1][1] and "not an integer" in found[2][1]
    )
    with pytest.raises(DiagnosticError, match="16-bit"):
        read_tables('{"ESV": [70000]}')
    with pytest.raises(DiagnosticError, match="OP_ET"):
        read_tables('{"constants": {"OP_ET": 2}}')


def test_xfuz_reader_gives_a_document_and_refuses_undecodable_tables() -> None:
    path = EXAMPLES / "xfuz_3_3.xfuz"
    doc = read_xfuz(path.read_text(encoding="utf-8"), path=str(path))
    assert replace(doc.main, options=(), name="xfuz") == EXPECTED_3_3
    assert doc.main.name == "xfuz_3_3"
    rg = dict(RG)
    rg[4] = 42  # a conclusion on a function that does not exist
    with pytest.raises(DiagnosticError, match="bit 12"):
        read_xfuz(write_tables(manual_constants(rg=words(rg, 384))))


# ---------------------------------------------------------------- 2.8 checks, one per STATUS bit


def issues(c: XfuzConstants) -> list[tuple[int, str | None]]:
    return [(int(i.bit), i.location) for i in decode_kb(c).issues]


def test_xfuz_2_8_printed_example_only_breaks_the_discretisation_span() -> None:
    assert issues(manual_constants()) == [(9, "ESV[22]")]
    esv = dict(ESV)
    esv[24] = 6  # 10 >= 2 * (6 - 1)
    assert issues(manual_constants(esv=words(esv, 62))) == []
    assert issues(manual_constants()) and decode_kb(manual_constants(), span_rule=False).issues == ()


def test_xfuz_2_8_bit_8_empty_base() -> None:
    assert issues(XfuzConstants()) == [(8, "FA[4]"), (8, "RG[0]")]  # the block's default base
    no_rule = manual_constants(rg=(999, 999, 999, 999))
    assert (8, "RG[0]") in issues(no_rule)


@pytest.mark.parametrize(
    ("discr", "low", "high", "ok"),
    [
        (2, 0, 800, False),
        (3, 0, 4, True),
        (3, 0, 3, False),
        (20, 0, 38, True),
        (20, 0, 37, False),
        (21, 0, 800, False),
    ],
)
def test_xfuz_2_8_bit_9_discretisation(discr: int, low: int, high: int, ok: bool) -> None:
    esv = dict(ESV)
    esv.update({34: low, 35: high, 36: discr, 24: 6})
    found = issues(manual_constants(esv=words(esv, 62)))
    assert found == ([] if ok else [(9, "ESV[36]" if not 3 <= discr <= 20 else "ESV[34]")])


def test_xfuz_2_8_bit_10_order_and_unknown_variables() -> None:
    esv = dict(ESV)
    esv[24] = 6
    swapped = dict(FA)
    swapped[22] = 10  # FA2 on OUT3: FA3 and FA4 (inputs) now follow an output function
    found = issues(manual_constants(esv=words(esv, 62), fa=words(swapped, 576)))
    # ... and REG1 ("FA2 -> Débit faible") becomes a second-inference rule concluding on VAR1.
    # OUT3, computed in second inference, is now a predicate of REG1 as well.
    assert found == [(10, "FA[31]"), (10, "FA[40]"), (13, "RG[10]"), (13, "RG[6]")]
    unknown = dict(FA)
    unknown[85] = 18  # FA9 on variable 18, which does not exist
    found = issues(manual_constants(esv=words(esv, 62), fa=words(unknown, 576)))
    assert found == [(10, "FA[85]")]


def test_xfuz_2_8_bit_11_points_out_of_order() -> None:
    esv = dict(ESV)
    esv[24] = 6
    fa = dict(FA)
    fa[79], fa[80] = 500, 400  # FA8: xC > xD
    assert issues(manual_constants(esv=words(esv, 62), fa=words(fa, 576))) == [(11, "FA[77]")]


def test_xfuz_2_8_bit_12_rule_references() -> None:
    esv = dict(ESV)
    esv[24] = 6
    rg = dict(RG)
    rg[1] = 110  # negated FA10, which does not exist
    rg[10] = 3  # REG1 concludes on FA3, an input function
    rg[16] = 108  # negation is not allowed in a conclusion
    found = issues(manual_constants(esv=words(esv, 62), rg=words(rg, 384)))
    assert found == [(12, "RG[1]"), (12, "RG[10]"), (12, "RG[16]")]


def test_xfuz_2_8_bit_13_second_inference() -> None:
    esv = dict(ESV)
    esv[24] = 6
    rg = dict(RG)
    rg[23] = 8  # REG3 (second inference) also concludes Débit moyen
    found = issues(manual_constants(esv=words(esv, 62), rg=words(rg, 384)))
    assert found == [(13, "RG[23]")]
    rg = dict(RG)
    rg.update({30: 5, 31: 999, 32: 999, 33: 999, 34: 7, 35: 999, 36: 999, 37: 999, 38: 999, 39: 999})
    # REG5: "Ouverture petite -> Débit faible": OUT3 is computed in second inference and used
    # as a predicate (and REG5 concludes on an intermediate variable in second inference).
    found = issues(manual_constants(esv=words(esv, 62), rg=words(rg, 384)))
    assert sorted(found) == [(13, "RG[30]"), (13, "RG[34]")]


def test_xfuz_2_8_bit_14_singleton_mode() -> None:
    esv = dict(ESV)
    esv[24] = 6
    found = issues(manual_constants(esv=words(esv, 62), out_pt=True, op_defuz=1))
    assert found == [(14, "RG[18]"), (14, "")]


def test_xfuz_status_bits_are_numbered_as_in_2_4() -> None:
    assert [b.value for b in StatusBit] == list(range(6, 15))


# ---------------------------------------------------------------- model -> tables


def test_xfuz_writer_encodes_a_singleton_program_and_reports_what_does_not_fit() -> None:
    fb = FunctionBlock(
        "sing",
        variables=(
            Variable("level", VarKind.INPUT, range=Range(0, 100)),
            Variable("pump", VarKind.OUTPUT, range=Range(0, 1000)),
        ),
        fuzzify=(
            FuzzifyBlock("level", (Term("low", pts((20, 1), (40, 0))), Term("high", pts((30, 0), (60, 1))))),
        ),
        defuzzify=(
            DefuzzifyBlock(
                "pump",
                (Term("off", SingletonMF(0.0)), Term("full", SingletonMF(900.0))),
                range=Range(0, 1000),
                method="COGS",
                default=Default(5.0),
            ),
        ),
        rule_blocks=(
            RuleBlock(
                "r",
                (
                    Rule("1", Is("level", "low"), (Conclusion("pump", "full"),)),
                    Rule("2", Is("level", "high"), (Conclusion("pump", "off"),)),
                ),
                and_op="PROD",
            ),
        ),
    )
    c, diags = constants_from_model(fb)
    assert [d for d in diags if d.is_error] == []
    assert c.out_pt and c.op_et == 1 and c.o_def[0] == 5
    assert c.fa[:9] == (*encode_name("low"), 0, -32768, -32768, 20, 40)
    assert c.fa[18:27] == (*encode_name("off"), 8, 0, 0, 0, 0)
    assert c.fa[40] == 999  # FA4 ends the list
    assert c.esv[16:19] == (0, 1000, 20)  # Discr defaults to the largest allowed value
    assert c.rg[:12] == (0, 999, 999, 999, 3, 999, 1, 999, 999, 999, 2, 999) and c.rg[12:16] == (999,) * 4
    back, _ = model_from_constants(c, name="sing")
    assert back.defuzzify_block("OUT1") == DefuzzifyBlock(
        "OUT1",
        (Term("off", SingletonMF(0.0)), Term("full", SingletonMF(900.0))),
        range=Range(0, 1000),
        method="COGS",
        default=Default(5.0),
    )

    too_much = replace(
        fb,
        defuzzify=(replace(fb.defuzzify[0], method="COA"),),
        rule_blocks=(
            RuleBlock("r", (Rule("1", Is("level", "low"), (Conclusion("pump", "full", weight=0.5),)),)),
        ),
    )
    codes = sorted(d.code for d in constants_from_model(too_much)[1] if d.is_error)
    assert {"xfuz-expr-method", "xfuz-expr-weight"} <= set(codes)
    with pytest.raises(DiagnosticError):
        write_xfuz(too_much)
    fractional = replace(fb, fuzzify=(FuzzifyBlock("level", (Term("low", pts((20.5, 1), (40, 0))),)),))
    assert any("16-bit integer" in d.message for d in constants_from_model(fractional)[1])


def test_xfuz_3_3_tables_to_fcl_text_and_back_give_the_same_words() -> None:
    from fuzzyctl.fcl import parse_fcl, write

    block, _ = model_from_constants(manual_constants())
    text = write(Document((block,)))
    assert "RULE 0 : IF INP1 IS faible AND INP4 IS NOT élevée THEN Débit IS fort;" in text
    again, diags = constants_from_model(parse_fcl(text))
    assert not [d for d in diags if d.is_error]
    assert again == manual_constants()


def test_xfuz_two_intermediate_variables_under_one_name_keep_their_labels() -> None:
    from fuzzyctl.formats.xfuz.tables import KnowledgeBase, XMembership, XRule, XVariable, encode_kb

    kb = KnowledgeBase(
        (
            XVariable(0, 0, 10),
            XVariable(8, 0, 20, 5),
            XVariable(14, 0, 20, 5, "level"),
            XVariable(15, 0, 20, 5, "LEVEL"),
        ),
        (
            XMembership(0, "low", 0, 0, 0, 2, 6),
            XMembership(1, "small", 8, 0, 0, 5, 10),
            XMembership(2, "a", 14, 0, 0, 5, 10),
            XMembership(3, "b", 15, 0, 0, 5, 10),
        ),
        (XRule(0, ((0, False),), (2, 3)), XRule(1, ((0, False),), (1,))),
    )
    esv, fa, rg = encode_kb(kb)
    block, diags = model_from_constants(XfuzConstants(esv=esv, fa=fa, rg=rg))
    assert not [d for d in diags if d.is_error]
    dropped = [d for d in diags if d.code == "xfuz-name"]
    assert len(dropped) == 1 and "LEVEL" in dropped[0].message and "already used" in dropped[0].message
    local = [v.name for v in block.variables if v.kind is VarKind.LOCAL]
    assert len(local) == 2 and len({n.lower() for n in local}) == 2 and "level" in local
