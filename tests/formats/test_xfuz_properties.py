"""Random XFUZ knowledge bases: words -> structure -> words, and tables -> model (FCL) ->
tables, give back the same words."""

from __future__ import annotations

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fuzzyctl.fcl import parse_fcl, write
from fuzzyctl.fcl.identifiers import fcl_name
from fuzzyctl.formats.xfuz.reader import model_from_constants
from fuzzyctl.formats.xfuz.tables import (
    KnowledgeBase,
    XfuzConstants,
    XMembership,
    XRule,
    XVariable,
    decode_kb,
    encode_kb,
)
from fuzzyctl.formats.xfuz.writer import constants_from_model
from fuzzyctl.model import Document

# Names that are FCL keywords ("if", "is", "term", ...) are left out: the XFUZ reader renames
# them (FCL could not read them back), so their words would not come back unchanged.
NAMES = st.text(alphabet="abcdefghijklmnopqrstuvwxyzé", min_size=1, max_size=8).filter(fcl_name)


@st.composite
def knowledge_bases(draw: st.DrawFn) -> tuple[KnowledgeBase, bool]:
    inputs = draw(st.lists(st.integers(0, 7), min_size=1, max_size=4, unique=True))
    outputs = draw(st.lists(st.integers(8, 13), min_size=1, max_size=3, unique=True))
    out_pt = draw(st.booleans())
    intermediates = [] if out_pt else draw(st.lists(st.integers(14, 17), max_size=2, unique=True))
    variables = []
    # Intermediate names are distinct: two slots under one name cannot be told apart in FCL
    # (the reader keeps the label then; tested in test_xfuz_format).
    intermediate_names = iter(draw(st.lists(NAMES, min_size=2, max_size=2, unique_by=str.lower)))
    for slot in sorted(inputs):
        low = draw(st.integers(-1000, 1000))
        variables.append(XVariable(slot, low, low + draw(st.integers(1, 1000))))
    for slot in sorted(outputs + intermediates):
        low = draw(st.integers(-1000, 1000))
        discr = draw(st.integers(3, 20))
        name = next(intermediate_names) if slot >= 14 else ""
        variables.append(XVariable(slot, low, low + 2 * (discr - 1) + draw(st.integers(0, 500)), discr, name))
    mfs: list[XMembership] = []
    for slot in [*sorted(inputs), *sorted(outputs + intermediates)]:
        names: set[str] = set()
        for _ in range(draw(st.integers(1, 3))):
            name = draw(NAMES.filter(lambda n, used=names: n not in used))  # type: ignore[misc]
            names.add(name)
            if out_pt and 8 <= slot < 14:
                p = draw(st.integers(-2000, 2000))
                pts = [p, p, p, p]
            else:
                pts = sorted(draw(st.lists(st.integers(-2000, 2000), min_size=4, max_size=4)))
                if draw(st.booleans()):
                    pts[0] = pts[1] = -32768
                elif draw(st.booleans()):
                    pts[2] = pts[3] = 32767
            mfs.append(XMembership(len(mfs), name, slot, *pts))
    inputs_mf = [m.number for m in mfs if m.slot < 8]
    concl_mf = [m.number for m in mfs if m.slot >= 8]
    var_mf = [m.number for m in mfs if m.slot >= 14]
    rules = []
    for _ in range(draw(st.integers(1, 8))):
        preds = draw(st.lists(st.sampled_from(inputs_mf), min_size=1, max_size=4))
        if var_mf and draw(st.booleans()):  # a second-level rule on an intermediate variable
            preds = [*preds[:3], draw(st.sampled_from(var_mf))]
            targets = [m for m in concl_mf if 8 <= mfs[m].slot < 14]
        else:
            targets = concl_mf
        concl = draw(st.lists(st.sampled_from(targets), min_size=1, max_size=2))
        rules.append(XRule(len(rules), tuple((p, draw(st.booleans())) for p in preds), tuple(concl)))
    return KnowledgeBase(tuple(variables), tuple(mfs), tuple(rules)), out_pt


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(knowledge_bases(), st.integers(0, 1), st.integers(0, 1))
def test_xfuz_tables_round_trip_through_the_model_and_fcl(
    kb_and_mode: tuple[KnowledgeBase, bool], op_et: int, op_defuz: int
) -> None:
    kb, out_pt = kb_and_mode
    esv, fa, rg = encode_kb(kb)
    constants = XfuzConstants(
        op_et=op_et, op_defuz=0 if out_pt else op_defuz, out_pt=out_pt, esv=esv, fa=fa, rg=rg
    )
    decoded = decode_kb(constants)
    assert decoded.memberships == kb.memberships and decoded.rules == kb.rules
    assert decoded.issues == () or all(i.bit == 13 for i in decoded.issues)
    block, diags = model_from_constants(constants)
    assert not [d for d in diags if d.is_error]
    again, diags = constants_from_model(block)
    assert not [d for d in diags if d.is_error]
    assert again == constants
    via_text, _ = constants_from_model(parse_fcl(write(Document((block,)))))
    assert via_text == constants
