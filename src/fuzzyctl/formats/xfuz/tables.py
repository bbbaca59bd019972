"""The knowledge base of the Schneider XFUZ block: the constant tables ESV[62], FA[576] and
RG[384] (manual chapter 3.2), their decoding into a structure, the consistency checks of
section 2.8 with the STATUS bit each one raises, and the encoding back into words.

This sits in ``formats`` because both the XFUZ table reader/writer (``formats/xfuz/reader.py``)
and the XFUZ block (``blocks/schneider``) need it, and imports point down the stack.

Word layout (3.2):

* ESV: INPi bounds at ``2(i-1)``, ``2(i-1)+1`` (display only); OUTj ``BorneInf, BorneSup,
  Discr`` at ``16+3(j-1)``; VARk the same at ``34+3(k-1)``; VARk name (8 characters in 4
  words) at ``46+4(k-1)``.
* FA: 64 records of 9 words: name (4 words), variable (0-7 INP1-8, 8-13 OUT1-6, 14-17
  VAR1-4, 999 ends the list), xA, xB, xC, xD.  ``xA = xB = -32768`` opens the left side,
  ``xC = xD = 32767`` the right side.
* RG: 64 records of 6 words: 4 predicates, 2 conclusions, each an FA number, ``+100``
  negates a predicate, 999 is unused; 999 in all 4 predicates ends the list.
* Names: two characters per word, ``second * 256 + first``, in code page 850 (the manual's
  "Dé" is H'8244': 0x82 is é in CP850/CP437).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import IntEnum

__all__ = [
    "ESV_SIZE",
    "FA_SIZE",
    "OPEN_HIGH",
    "OPEN_LOW",
    "RG_SIZE",
    "UNUSED",
    "KbIssue",
    "KnowledgeBase",
    "SlotKind",
    "StatusBit",
    "XMembership",
    "XRule",
    "XVariable",
    "XfuzConstants",
    "check_kb",
    "decode_kb",
    "decode_name",
    "encode_kb",
    "encode_name",
    "esv_offsets",
    "slot_kind",
    "slot_label",
]

ESV_SIZE, FA_SIZE, RG_SIZE = 62, 576, 384
MF_WORDS, RULE_WORDS = 9, 6
RULE_PREDICATES, RULE_CONCLUSIONS = 4, 2  # the 6 words of an RG record (3.2)
MAX_MF, MAX_RULES = 64, 64
N_INPUTS, N_OUTPUTS, N_VARS = 8, 6, 4
UNUSED = 999
NEGATION = 100
OPEN_LOW, OPEN_HIGH = -32768, 32767
DISCR_MIN, DISCR_MAX = 3, 20
NAME_WORDS = 4
CODEPAGE = "cp850"
INT16_MIN, INT16_MAX = -32768, 32767


class StatusBit(IntEnum):
    """Bits of the STATUS word (2.4).  0-5: default value on OUT1-6 (information)."""

    NO_ACTIVE_RULE = 6  # alarm
    WRONG_PROCESSOR = 7  # error
    EMPTY_BASE = 8  # no membership function or no rule
    DISCRETISATION = 9  # Discr < 3, Discr > 20 or BorneSup - BorneInf < 2 (Discr - 1)
    MF_ORDER = 10  # input MFs after output MFs, or MF of a variable that does not exist
    MF_POINTS = 11  # xA <= xB <= xC <= xD violated
    RULE_REFERENCE = 12  # rule -> missing MF, or input MF as conclusion
    SECOND_INFERENCE = 13  # 2nd-inference output used as predicate, or VAR concluded in 2nd inference
    SINGLETON_MODE = 14  # OUT_PT=1 with a 2nd inference or with mean of maxima


ERROR_BITS = frozenset(range(7, 15))
"""STATUS bits that are errors (they raise ERROR unless INHIB); the others are information
(0-5) and alarm (6)."""


class SlotKind(IntEnum):
    INPUT = 0
    OUTPUT = 1
    INTERMEDIATE = 2


def slot_kind(slot: int) -> SlotKind:
    """0-7 inputs, 8-13 outputs, 14-17 intermediate variables (FA "variable" numbers)."""
    if 0 <= slot < 8:
        return SlotKind.INPUT
    if 8 <= slot < 14:
        return SlotKind.OUTPUT
    if 14 <= slot < 18:
        return SlotKind.INTERMEDIATE
    raise ValueError(f"variable number {slot} is not 0-17")


def slot_label(slot: int) -> str:
    """``INP1``..``INP8``, ``OUT1``..``OUT6``, ``VAR1``..``VAR4``."""
    kind = slot_kind(slot)
    if kind is SlotKind.INPUT:
        return f"INP{slot + 1}"
    if kind is SlotKind.OUTPUT:
        return f"OUT{slot - 7}"
    return f"VAR{slot - 13}"


def _int16(value: int) -> int:
    return value - 0x10000 if value >= 0x8000 else value


def encode_name(text: str, words: int = NAME_WORDS) -> tuple[int, ...]:
    """Name -> ``words`` signed 16-bit words, two CP850 characters per word (3.2-1).

    Raises ValueError when the name is longer than ``2 * words`` characters or has a
    character CP850 lacks."""
    raw = text.encode(CODEPAGE)
    if len(raw) > 2 * words:
        raise ValueError(f"name {text!r} is longer than {2 * words} characters")
    raw = raw.ljust(2 * words, b"\0")
    return tuple(_int16(raw[2 * k + 1] * 256 + raw[2 * k]) for k in range(words))


def decode_name(words: Sequence[int]) -> str:
    """Words -> name, up to the first NUL character."""
    raw = bytearray()
    for w in words:
        u = w & 0xFFFF
        raw += bytes((u & 0xFF, u >> 8))
    return raw.split(b"\0", 1)[0].decode(CODEPAGE)


# --------------------------------------------------------------------------- constants


def _check_words(name: str, words: Sequence[int], size: int) -> tuple[int, ...]:
    if len(words) > size:
        raise ValueError(f"{name} has {len(words)} words; the table holds {size}")
    out = []
    for k, w in enumerate(words):
        if isinstance(w, bool) or not isinstance(w, int) or not INT16_MIN <= w <= INT16_MAX:
            raise ValueError(f"{name}[{k}] = {w!r} is not a 16-bit integer word")
        out.append(w)
    return tuple(out) + (0,) * (size - len(out))


EMPTY_FA = (0, 0, 0, 0, UNUSED) + (0,) * (FA_SIZE - 5)
"""FA holding no membership function (the block's default): 999 in FA0's variable word."""
EMPTY_RG = (UNUSED,) * 4 + (0,) * (RG_SIZE - 4)
"""RG holding no rule (the block's default): 999 in REG0's four predicates."""


@dataclass(frozen=True)
class XfuzConstants:
    """The internal constants of an XFUZ instance (2.3): structure operators, the
    initialisation constants ending in ``$`` and the knowledge base tables.

    By default the base is empty (2.3: "no membership function", "no rule"), which takes
    the 999 terminators.  Shorter tables are padded with 0, as the manual's "values not
    given are left at 0" (3.3-3)."""

    op_conj: int = 0
    op_et: int = 0
    op_impl: int = 0
    op_agreg: int = 0
    op_defuz: int = 0
    out_pt: bool = False
    contask: bool = True
    t_ofb: int = 200
    o_def: tuple[int, ...] = (0,) * N_OUTPUTS
    esv: tuple[int, ...] = (0,) * ESV_SIZE
    fa: tuple[int, ...] = EMPTY_FA
    rg: tuple[int, ...] = EMPTY_RG

    def __post_init__(self) -> None:
        for name, value, allowed in (
            ("OP_CONJ", self.op_conj, (0,)),
            ("OP_ET", self.op_et, (0, 1)),
            ("OP_IMPL", self.op_impl, (0, 1)),
            ("OP_AGREG", self.op_agreg, (0,)),
            ("OP_DEFUZ", self.op_defuz, (0, 1)),
        ):
            if value not in allowed:
                raise ValueError(f"{name} = {value!r}: allowed values are {', '.join(map(str, allowed))}")
        if not 0 <= self.t_ofb <= INT16_MAX:
            raise ValueError(f"T_OFB$ = {self.t_ofb} is outside 0..32767")
        object.__setattr__(self, "out_pt", bool(self.out_pt))
        object.__setattr__(self, "contask", bool(self.contask))
        o_def = tuple(self.o_def)
        if len(o_def) != N_OUTPUTS:
            raise ValueError(f"O1_DEF$..O6_DEF$: expected {N_OUTPUTS} values, got {len(o_def)}")
        object.__setattr__(self, "o_def", _check_words("Oi_DEF$", o_def, N_OUTPUTS))
        object.__setattr__(self, "esv", _check_words("ESV", self.esv, ESV_SIZE))
        object.__setattr__(self, "fa", _check_words("FA", self.fa, FA_SIZE))
        object.__setattr__(self, "rg", _check_words("RG", self.rg, RG_SIZE))


# --------------------------------------------------------------------------- decoded structure


@dataclass(frozen=True)
class XVariable:
    """An input, output or intermediate variable: its ESV words."""

    slot: int
    low: int = 0
    high: int = 0
    discr: int = 0  # outputs and intermediate variables only
    name: str = ""  # intermediate variables only (ESV 46-61)

    @property
    def kind(self) -> SlotKind:
        return slot_kind(self.slot)

    @property
    def label(self) -> str:
        return slot_label(self.slot)


@dataclass(frozen=True)
class XMembership:
    """One FA record: term name, variable number and the abscissae of A, B, C, D."""

    number: int
    name: str
    slot: int
    a: int
    b: int
    c: int
    d: int

    @property
    def points(self) -> tuple[int, int, int, int]:
        return (self.a, self.b, self.c, self.d)

    def singleton(self) -> int:
        """The point of a singleton output term (3.2-3): xB, or xC when xB is -32768."""
        return self.c if self.b == OPEN_LOW else self.b


@dataclass(frozen=True)
class XRule:
    """One RG record: predicates as (FA number, negated), conclusions as FA numbers."""

    number: int
    predicates: tuple[tuple[int, bool], ...]
    conclusions: tuple[int, ...]


@dataclass(frozen=True)
class KbIssue:
    """A finding of the 2.8 checks: the STATUS bit it raises and where it comes from."""

    bit: int
    message: str
    table: str = ""  # "ESV", "FA", "RG" or "" for the constants
    index: int | None = None  # word index in the table

    @property
    def location(self) -> str:
        return f"{self.table}[{self.index}]" if self.table and self.index is not None else self.table


@dataclass(frozen=True)
class KnowledgeBase:
    """The decoded tables.  ``variables`` holds every slot whose ESV words are not all 0 or
    that a membership function refers to."""

    variables: tuple[XVariable, ...] = ()
    memberships: tuple[XMembership, ...] = ()
    rules: tuple[XRule, ...] = ()
    issues: tuple[KbIssue, ...] = field(default=(), compare=False)

    def variable(self, slot: int) -> XVariable:
        return next((v for v in self.variables if v.slot == slot), XVariable(slot))

    def membership(self, number: int) -> XMembership | None:
        return self.memberships[number] if 0 <= number < len(self.memberships) else None

    def rule_level(self, rule: XRule) -> int:
        """1 when every predicate is about an input, else 2 (2.2-1)."""
        for number, _ in rule.predicates:
            mf = self.membership(number)
            if mf is not None and 0 <= mf.slot < 18 and slot_kind(mf.slot) is not SlotKind.INPUT:
                return 2
        return 1

    @property
    def error_bits(self) -> frozenset[int]:
        return frozenset(i.bit for i in self.issues if i.bit in ERROR_BITS)


def esv_offsets(slot: int) -> tuple[int, int, int | None]:
    """ESV indices of a slot's BorneInf, BorneSup and Discr (None for inputs)."""
    kind = slot_kind(slot)
    if kind is SlotKind.INPUT:
        return 2 * slot, 2 * slot + 1, None
    base = 16 + 3 * (slot - 8) if kind is SlotKind.OUTPUT else 34 + 3 * (slot - 14)
    return base, base + 1, base + 2


def _name_offset(slot: int) -> int:
    return 46 + NAME_WORDS * (slot - 14)


def decode_kb(constants: XfuzConstants, *, span_rule: bool = True) -> KnowledgeBase:
    """Decode ESV/FA/RG and run every check of 2.8 (see :func:`check_kb`)."""
    fa, rg, esv = constants.fa, constants.rg, constants.esv
    mfs: list[XMembership] = []
    for n in range(MAX_MF):
        rec = fa[MF_WORDS * n : MF_WORDS * (n + 1)]
        if rec[4] == UNUSED:
            break
        mfs.append(XMembership(n, decode_name(rec[:4]), rec[4], rec[5], rec[6], rec[7], rec[8]))
    rules: list[XRule] = []
    for r in range(MAX_RULES):
        rec = rg[RULE_WORDS * r : RULE_WORDS * (r + 1)]
        if all(w == UNUSED for w in rec[:4]):
            break
        preds = tuple(
            (w - NEGATION, True) if NEGATION <= w < UNUSED else (w, False) for w in rec[:4] if w != UNUSED
        )
        concl = tuple(w for w in rec[4:] if w != UNUSED)
        rules.append(XRule(r, preds, concl))
    variables: list[XVariable] = []
    used = {m.slot for m in mfs}
    for slot in range(18):
        lo, hi, dz = esv_offsets(slot)
        words = [esv[lo], esv[hi]] + ([esv[dz]] if dz is not None else [])
        name = decode_name(esv[_name_offset(slot) : _name_offset(slot) + NAME_WORDS]) if slot >= 14 else ""
        if slot in used or any(words) or name:
            variables.append(XVariable(slot, esv[lo], esv[hi], esv[dz] if dz is not None else 0, name))
    kb = KnowledgeBase(tuple(variables), tuple(mfs), tuple(rules))
    issues = check_kb(kb, out_pt=constants.out_pt, op_defuz=constants.op_defuz, span_rule=span_rule)
    return KnowledgeBase(kb.variables, kb.memberships, kb.rules, tuple(issues))


def check_kb(
    kb: KnowledgeBase, *, out_pt: bool = False, op_defuz: int = 0, span_rule: bool = True
) -> list[KbIssue]:
    """The consistency checks of 2.8, each reported with the STATUS bit of 2.4.

    ``span_rule=False`` leaves out "BorneSup - BorneInf >= 2 (Discr - 1)", which the
    manual's own worked example (3.3, Ouverture 0..10 with Discr 20) does not meet."""
    issues: list[KbIssue] = []
    add = issues.append
    if not kb.memberships:
        add(KbIssue(StatusBit.EMPTY_BASE, "no membership function in the base (FA[4] is 999)", "FA", 4))
    if not kb.rules:
        add(KbIssue(StatusBit.EMPTY_BASE, "no rule in the base (RG[0..3] are 999)", "RG", 0))

    seen_non_input = False
    for mf in kb.memberships:
        at = MF_WORDS * mf.number
        if not 0 <= mf.slot < 18:
            add(
                KbIssue(
                    StatusBit.MF_ORDER,
                    f"FA{mf.number} refers to variable {mf.slot}, which does not "
                    "exist (0-7 inputs, 8-13 outputs, 14-17 intermediate, 999 ends the list)",
                    "FA",
                    at + 4,
                )
            )
            continue
        if slot_kind(mf.slot) is SlotKind.INPUT:
            if seen_non_input:
                add(
                    KbIssue(
                        StatusBit.MF_ORDER,
                        f"FA{mf.number} ({slot_label(mf.slot)}) comes after output or "
                        "intermediate membership functions; input ones must come first",
                        "FA",
                        at + 4,
                    )
                )
        else:
            seen_non_input = True
        if not mf.a <= mf.b <= mf.c <= mf.d:
            add(
                KbIssue(
                    StatusBit.MF_POINTS,
                    f"FA{mf.number}: points must satisfy xA <= xB <= xC <= xD, got "
                    f"{mf.a}, {mf.b}, {mf.c}, {mf.d}",
                    "FA",
                    at + 5,
                )
            )

    for v in kb.variables:
        if v.kind is SlotKind.INPUT or not any(m.slot == v.slot for m in kb.memberships):
            continue
        lo, _, dz = esv_offsets(v.slot)
        if not DISCR_MIN <= v.discr <= DISCR_MAX:
            add(
                KbIssue(StatusBit.DISCRETISATION, f"{v.label}: Discr = {v.discr} is outside 3..20", "ESV", dz)
            )
        elif v.high - v.low < 2 * (v.discr - 1) and (span_rule or v.high <= v.low):
            add(
                KbIssue(
                    StatusBit.DISCRETISATION,
                    f"{v.label}: BorneSup - BorneInf = {v.high - v.low} is below "
                    f"2 * (Discr - 1) = {2 * (v.discr - 1)}",
                    "ESV",
                    lo,
                )
            )

    second_outputs: set[int] = set()
    predicate_slots: dict[int, int] = {}
    n_mf = len(kb.memberships)
    for rule in kb.rules:
        at = RULE_WORDS * rule.number
        valid = True
        for k, (number, negated) in enumerate(rule.predicates):
            pred_mf = kb.membership(number)
            if pred_mf is None or number >= n_mf:
                code = number + NEGATION if negated else number
                add(
                    KbIssue(
                        StatusBit.RULE_REFERENCE,
                        f"REG{rule.number}: predicate {code} refers to no "
                        f"membership function (there are {n_mf})",
                        "RG",
                        at + k,
                    )
                )
                valid = False
            elif 0 <= pred_mf.slot < 18:
                predicate_slots.setdefault(pred_mf.slot, at + k)
        for k, number in enumerate(rule.conclusions):
            concl_mf = kb.membership(number)
            where = at + 4 + k
            if concl_mf is None:
                add(
                    KbIssue(
                        StatusBit.RULE_REFERENCE,
                        f"REG{rule.number}: conclusion {number} refers to no "
                        f"membership function (there are {n_mf})",
                        "RG",
                        where,
                    )
                )
                valid = False
            elif 0 <= concl_mf.slot < 18 and slot_kind(concl_mf.slot) is SlotKind.INPUT:
                add(
                    KbIssue(
                        StatusBit.RULE_REFERENCE,
                        f"REG{rule.number}: conclusion FA{number} is an input "
                        f"membership function ({slot_label(concl_mf.slot)})",
                        "RG",
                        where,
                    )
                )
                valid = False
        if not valid or kb.rule_level(rule) == 1:
            continue
        for k, number in enumerate(rule.conclusions):
            mf = kb.memberships[number]
            if not 0 <= mf.slot < 18:
                continue
            if slot_kind(mf.slot) is SlotKind.INTERMEDIATE:
                add(
                    KbIssue(
                        StatusBit.SECOND_INFERENCE,
                        f"REG{rule.number}: second-inference rule concludes on "
                        f"intermediate variable {slot_label(mf.slot)}",
                        "RG",
                        at + 4 + k,
                    )
                )
            else:
                second_outputs.add(mf.slot)
    for slot in sorted(second_outputs & predicate_slots.keys()):
        add(
            KbIssue(
                StatusBit.SECOND_INFERENCE,
                f"{slot_label(slot)} is computed by a second-inference rule and used as a rule predicate",
                "RG",
                predicate_slots[slot],
            )
        )

    if out_pt:
        second = [r for r in kb.rules if kb.rule_level(r) == 2]
        if second:
            add(
                KbIssue(
                    StatusBit.SINGLETON_MODE,
                    f"REG{second[0].number}: second inference is impossible in "
                    "singleton output mode (OUT_PT = 1)",
                    "RG",
                    RULE_WORDS * second[0].number,
                )
            )
        if op_defuz == 1:
            add(
                KbIssue(
                    StatusBit.SINGLETON_MODE,
                    "mean of maxima (OP_DEFUZ = 1) is impossible in singleton output mode (OUT_PT = 1)",
                )
            )
    return issues


# --------------------------------------------------------------------------- encoding


def encode_kb(kb: KnowledgeBase) -> tuple[tuple[int, ...], tuple[int, ...], tuple[int, ...]]:
    """Structure -> (ESV, FA, RG) words, terminators included.

    Raises ValueError when the structure does not fit the tables (more than 64 functions
    or rules, names longer than 8 characters, more than 4 predicates or 2 conclusions)."""
    if len(kb.memberships) > MAX_MF:
        raise ValueError(f"{len(kb.memberships)} membership functions; XFUZ holds {MAX_MF}")
    if len(kb.rules) > MAX_RULES:
        raise ValueError(f"{len(kb.rules)} rules; XFUZ holds {MAX_RULES}")
    esv = [0] * ESV_SIZE
    for v in kb.variables:
        lo, hi, dz = esv_offsets(v.slot)
        esv[lo], esv[hi] = v.low, v.high
        if dz is not None:
            esv[dz] = v.discr
        if v.name and v.kind is SlotKind.INTERMEDIATE:
            at = _name_offset(v.slot)
            esv[at : at + NAME_WORDS] = encode_name(v.name)
    fa = [0] * FA_SIZE
    for n, mf in enumerate(kb.memberships):
        fa[MF_WORDS * n : MF_WORDS * (n + 1)] = (*encode_name(mf.name), mf.slot, mf.a, mf.b, mf.c, mf.d)
    if len(kb.memberships) < MAX_MF:
        fa[MF_WORDS * len(kb.memberships) + 4] = UNUSED
    rg = [0] * RG_SIZE
    for r, rule in enumerate(kb.rules):
        if len(rule.predicates) > 4 or len(rule.conclusions) > 2:
            raise ValueError(f"rule {r}: XFUZ rules have at most 4 predicates and 2 conclusions")
        preds = [n + NEGATION if neg else n for n, neg in rule.predicates]
        concl = list(rule.conclusions)
        rg[RULE_WORDS * r : RULE_WORDS * (r + 1)] = (
            preds + [UNUSED] * (4 - len(preds)) + concl + [UNUSED] * (2 - len(concl))
        )
    if len(kb.rules) < MAX_RULES:
        at = RULE_WORDS * len(kb.rules)
        rg[at : at + 4] = [UNUSED] * 4
    for table, words in (("ESV", esv), ("FA", fa), ("RG", rg)):
        _check_words(table, words, len(words))
    return tuple(esv), tuple(fa), tuple(rg)
