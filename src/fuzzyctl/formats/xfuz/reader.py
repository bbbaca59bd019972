"""Schneider XFUZ knowledge-base tables as files, and their translation to and from the
fuzzyctl model (hence FCL).

Two file layouts hold the same content, the constants of the block and the three arrays:

A ``.xfuz`` file holds either; the reader tells them apart by the first character.

JSON::

    {"format": "xfuz-tables", "version": 1,
     "constants": {"OP_CONJ": 0, "OP_ET": 0, "OP_IMPL": 0, "OP_AGREG": 0, "OP_DEFUZ": 0,
                   "OUT_PT": 0, "CONTASK$": 1, "T_OFB$": 200, "O1_DEF$": 0, ...},
     "ESV": [62 words], "FA": [576 words], "RG": [384 words]}

CSV, one word per row like the manual's "ligne N : value" listings::

    table,index,value,note
    CONST,OP_ET,0,
    ESV,0,0,INP1 BorneInf
    FA,0,24934,FA0 Nom(1-2)

Missing words are 0 and missing constants take the manual's defaults; shorter arrays are
padded with 0.  The ``note`` column is ignored on reading.

Model mapping: INPi/OUTj become VAR_INPUT/VAR_OUTPUT ``INPi``/``OUTj`` of type INT (the
tables carry no names for them), VARk a local VAR named by its ESV name.  Each FA record is
a term (``(xC,1) (xD,0)`` for a left-open half trapezoid, ``(xA,0) (xB,1)`` for a right-open
one, a triangle or trapezoid otherwise; a singleton when OUT_PT = 1), each RG record a rule
``RULE n`` of AND-ed predicates (NOT for +100).  OP_ET, OP_IMPL and OP_DEFUZ become AND,
ACT and METHOD (COG, MOM; COGS when OUT_PT = 1); Oi_DEF$ the DEFAULT.  What FCL has no place
for (Discr, the slot of a renamed variable, CONTASK$, T_OFB$) goes in an OPTIONS block as
``XFUZ key value;`` lines, so that tables -> FCL -> tables gives back the same words.
"""

from __future__ import annotations

import csv
import io
import re
from collections.abc import Iterator
from dataclasses import replace
from typing import Any

from fuzzyctl import model as m
from fuzzyctl.diagnostics import Diagnostic, DiagnosticError, Severity, error, warning
from fuzzyctl.fcl.identifiers import fcl_name
from fuzzyctl.formats import Loaded
from fuzzyctl.formats.xfuz.names import CONSTANT_KEYS, DEFAULTS, FORMAT_TAG
from fuzzyctl.formats.xfuz.tables import (
    ESV_SIZE,
    FA_SIZE,
    OPEN_HIGH,
    OPEN_LOW,
    RG_SIZE,
    KnowledgeBase,
    SlotKind,
    StatusBit,
    XfuzConstants,
    XMembership,
    decode_kb,
    slot_kind,
)
from fuzzyctl.limits import shorten

# --------------------------------------------------------------------------- table files


def _constants_from_mapping(values: dict[str, int], tables: dict[str, list[int]]) -> XfuzConstants:
    def get(key: str) -> int:
        return values.get(key, DEFAULTS.get(key, 0))

    # A table that is not given at all keeps the block's default (an empty base).
    given = {name.lower(): tuple(words) for name, words in tables.items()}
    return XfuzConstants(
        op_conj=get("OP_CONJ"),
        op_et=get("OP_ET"),
        op_impl=get("OP_IMPL"),
        op_agreg=get("OP_AGREG"),
        op_defuz=get("OP_DEFUZ"),
        out_pt=bool(get("OUT_PT")),
        contask=bool(get("CONTASK$")),
        t_ofb=get("T_OFB$"),
        o_def=tuple(get(f"O{i}_DEF$") for i in range(1, 7)),
        **given,
    )


def _is_int(v: Any) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _read_json(text: str, path: str | None) -> XfuzConstants:
    from fuzzyctl.limits import load_json

    data = load_json(text, path, "xfuz-json")  # the nesting and number limits of every reader
    diags: list[Diagnostic] = []
    if not isinstance(data, dict):
        raise DiagnosticError(
            [error("expected a JSON object with ESV, FA and RG", code="xfuz-json", file=path)]
        )
    if data.get("format", FORMAT_TAG) != FORMAT_TAG:
        diags.append(
            error(f"format is {data.get('format')!r}, expected {FORMAT_TAG!r}", code="xfuz-json", file=path)
        )
    consts = data.get("constants", {})
    if not isinstance(consts, dict):
        diags.append(error("constants must be an object", code="xfuz-json", file=path))
        consts = {}
    for key, value in consts.items():
        if key not in CONSTANT_KEYS:
            diags.append(
                error(
                    f"unknown constant {key!r} (known: {', '.join(CONSTANT_KEYS)})",
                    code="xfuz-json",
                    file=path,
                )
            )
        elif not _is_int(value):
            diags.append(
                error(f"constant {key} must be an integer, got {value!r}", code="xfuz-json", file=path)
            )
    tables: dict[str, list[int]] = {}
    for name, size in (("ESV", ESV_SIZE), ("FA", FA_SIZE), ("RG", RG_SIZE)):
        if name not in data:
            continue
        words = data[name]
        if not isinstance(words, list) or not all(_is_int(w) for w in words):
            diags.append(error(f"{name} must be an array of integers", code="xfuz-json", file=path))
            continue
        if len(words) > size:
            diags.append(
                error(f"{name} has {len(words)} words; the table holds {size}", code="xfuz-json", file=path)
            )
        tables[name] = words
    for key in data:
        if key not in ("format", "version", "constants", "ESV", "FA", "RG", "comment"):
            diags.append(warning(f"unknown key {key!r} ignored", code="xfuz-json", file=path))
    return _finish(consts, tables, diags, text, path)


def _finish(
    consts: dict[str, int], tables: dict[str, list[int]], diags: list[Diagnostic], text: str, path: str | None
) -> XfuzConstants:
    if any(d.is_error for d in diags):
        raise DiagnosticError(diags, text)
    try:
        return _constants_from_mapping(consts, tables)
    except ValueError as exc:
        raise DiagnosticError([*diags, error(str(exc), code="xfuz-value", file=path)], text) from None


def _read_csv(text: str, path: str | None) -> XfuzConstants:
    diags: list[Diagnostic] = []
    consts: dict[str, int] = {}
    sizes = {"ESV": ESV_SIZE, "FA": FA_SIZE, "RG": RG_SIZE}
    tables: dict[str, list[int]] = {name: [0] * size for name, size in sizes.items()}
    seen: dict[tuple[str, str], int] = {}
    for lineno, row in _csv_rows(text, path, diags):
        if not row or not "".join(row).strip() or row[0].lstrip().startswith("#"):
            continue
        cells = [c.strip() for c in row]
        if cells[0].lower() == "table" and len(cells) > 2 and cells[2].lower() == "value":
            continue  # the header row
        span = m.Span(lineno, 1)
        if len(cells) < 3:
            diags.append(error("expected table,index,value[,note]", span, code="xfuz-csv", file=path))
            continue
        table, index, value = cells[0].upper(), cells[1], cells[2]
        try:
            number = int(value, 0) if value.lower().startswith(("0x", "-0x")) else int(value)
        except ValueError:
            message = f"value {shorten(value)!r} is not an integer"
            diags.append(error(message, span, code="xfuz-csv", file=path))
            continue
        key = (table, index.upper())
        if key in seen:
            diags.append(
                error(
                    f"{table} {index} is given twice (first on line {seen[key]})",
                    span,
                    code="xfuz-csv",
                    file=path,
                )
            )
            continue
        seen[key] = lineno
        if table == "CONST":
            if index.upper() not in CONSTANT_KEYS:
                diags.append(error(f"unknown constant {index!r}", span, code="xfuz-csv", file=path))
            else:
                consts[index.upper()] = number
        elif table in sizes:
            if not (index.isascii() and index.isdigit() and len(index) <= 6) or int(index) >= sizes[table]:
                diags.append(
                    error(
                        f"{table} index {shorten(index)!r} is not 0..{sizes[table] - 1}",
                        span,
                        code="xfuz-csv",
                        file=path,
                    )
                )
            else:
                tables[table][int(index)] = number
        else:
            diags.append(
                error(f"table {cells[0]!r} is not CONST, ESV, FA or RG", span, code="xfuz-csv", file=path)
            )
    return _finish(consts, tables, diags, text, path)


def _csv_rows(text: str, path: str | None, diags: list[Diagnostic]) -> Iterator[tuple[int, list[str]]]:
    """(line, cells) of each CSV row; any line ending (LF, CRLF, CR alone) ends a row, and
    what the csv module refuses (a field over its 131,072 characters, a NUL) is an error at
    its line instead of an exception."""
    normalised = text.replace("\r\n", "\n").replace("\r", "\n")
    reader = csv.reader(io.StringIO(normalised, newline="\n"))
    while True:
        start = reader.line_num + 1
        try:
            row = next(reader)
        except StopIteration:
            return
        except csv.Error as exc:
            diags.append(error(f"not a CSV row: {exc}", m.Span(start, 1), code="xfuz-csv", file=path))
            continue
        yield start, row


def read_tables(text: str, *, path: str | None = None) -> XfuzConstants:
    """Read a table file: JSON when it starts with ``{``, else CSV."""
    if text.lstrip().startswith("{"):
        return _read_json(text, path)
    return _read_csv(text, path)


__all__ = ["model_from_constants", "read", "read_tables", "read_xfuz"]


# --------------------------------------------------------------------------- tables -> model


def _mf_model(mf: XMembership, singleton: bool) -> m.MembershipFunction:
    if singleton:
        return m.SingletonMF(float(mf.singleton()))
    a, b, c, d = (float(x) for x in mf.points)
    left_open, right_open = mf.a == OPEN_LOW and mf.b == OPEN_LOW, mf.c == OPEN_HIGH and mf.d == OPEN_HIGH
    pts: list[tuple[float, float]]
    if left_open and right_open:
        pts = [(float(OPEN_LOW), 1.0), (float(OPEN_HIGH), 1.0)]
    elif left_open:
        pts = [(c, 1.0), (d, 0.0)]
    elif right_open:
        pts = [(a, 0.0), (b, 1.0)]
    elif b == c:
        pts = [(a, 0.0), (b, 1.0), (d, 0.0)]
    else:
        pts = [(a, 0.0), (b, 1.0), (c, 1.0), (d, 0.0)]
    return m.PointsMF(tuple(m.Point(float(x), y) for x, y in pts))


def _options_text(c: XfuzConstants, renamed: list[tuple[str, str]], discr: list[tuple[str, int]]) -> str:
    lines = ["(* XFUZ data with no FCL equivalent; read back by fuzzyctl's XFUZ writer *)"]
    lines += [f"XFUZ SLOT {name} {label};" for name, label in renamed]
    lines += [f"XFUZ DISCR {name} {n};" for name, n in discr]
    lines += [f"XFUZ CONTASK$ {int(c.contask)};", f"XFUZ T_OFB$ {c.t_ofb};"]
    return "\n".join(lines)


def model_from_constants(c: XfuzConstants, *, name: str = "xfuz") -> tuple[m.FunctionBlock, list[Diagnostic]]:
    """Decode the tables into a function block.  Errors (a table that cannot be decoded)
    and warnings (what the block would flag in STATUS, what changes on the way) come back
    as diagnostics; the block is only meaningful when there is no error."""
    kb = decode_kb(c)
    diags: list[Diagnostic] = []
    for issue in kb.issues:
        # Rules pointing nowhere and functions of non-existent variables cannot be decoded;
        # everything else can, and is what the block itself would flag in STATUS.
        fatal = issue.bit == StatusBit.RULE_REFERENCE or (
            issue.bit == StatusBit.MF_ORDER and "does not exist" in issue.message
        )
        text = f"{issue.location}: {issue.message} (XFUZ STATUS bit {issue.bit})".lstrip(": ")
        diags.append(
            error(text, code=f"xfuz-status-{issue.bit}")
            if fatal
            else warning(text, code=f"xfuz-status-{issue.bit}")
        )
    names: dict[int, str] = {}
    renamed: list[tuple[str, str]] = []
    for v in kb.variables:
        label = v.label
        if v.kind is SlotKind.INTERMEDIATE and v.name and v.name != label:
            taken = {w.label.lower() for w in kb.variables} | {n.lower() for n in names.values()}
            if v.name.lower() in taken:
                # Two slots under one name cannot both be referred to in FCL; keep the label.
                diags.append(
                    warning(
                        f"{label}: name {v.name!r} is already used by another variable; "
                        f"the variable is called {label} and the name is dropped",
                        code="xfuz-name",
                    )
                )
                names[v.slot] = label
            elif fcl_name(v.name):
                names[v.slot] = v.name
                renamed.append((v.name, label))
            else:
                diags.append(
                    warning(
                        f"{label}: name {v.name!r} cannot be an FCL name; renamed {label}",
                        code="xfuz-name",
                    )
                )
                names[v.slot] = label
        else:
            names[v.slot] = label
    # Variables in the order their functions appear in FA, then the ones without functions.
    order = list(
        dict.fromkeys(
            [ms.slot for ms in kb.memberships if 0 <= ms.slot < 18] + [v.slot for v in kb.variables]
        )
    )
    term_names: dict[int, str] = {}
    terms: dict[int, list[m.Term]] = {slot: [] for slot in order}
    last_slot, regrouped = -1, False
    for mf in kb.memberships:
        if not 0 <= mf.slot < 18:
            continue
        regrouped |= mf.slot != last_slot and bool(terms[mf.slot])
        last_slot = mf.slot
        tname = mf.name if mf.name and fcl_name(mf.name) else f"FA{mf.number}"
        if tname != mf.name:
            diags.append(
                warning(
                    f"FA{mf.number}: name {mf.name!r} cannot be an FCL name; renamed {tname}",
                    code="xfuz-name",
                )
            )
        if any(t.name == tname for t in terms[mf.slot]):
            diags.append(
                warning(
                    f"FA{mf.number}: {names[mf.slot]} already has a term {tname}; this one is "
                    f"called {tname}_{mf.number}",
                    code="xfuz-name",
                )
            )
            tname = f"{tname}_{mf.number}"
        term_names[mf.number] = tname
        singleton = c.out_pt and slot_kind(mf.slot) is SlotKind.OUTPUT
        if singleton and len(set(mf.points)) > 1:
            diags.append(
                warning(
                    f"FA{mf.number}: singleton mode keeps the point {mf.singleton()}; the other "
                    "abscissae are not kept",
                    code="xfuz-singleton",
                )
            )
        terms[mf.slot].append(m.Term(tname, _mf_model(mf, singleton)))
    if regrouped:
        diags.append(
            warning(
                "the functions of a variable are not contiguous in FA; writing the tables back "
                "groups them and renumbers the rules' references",
                code="xfuz-order",
            )
        )

    as_predicate = {
        kb.memberships[n].slot for r in kb.rules for n, _ in r.predicates if 0 <= n < len(kb.memberships)
    }
    method = "COGS" if c.out_pt else ("MOM" if c.op_defuz == 1 else "COG")
    variables: list[m.Variable] = []
    fuzzify: list[m.FuzzifyBlock] = []
    defuzzify: list[m.DefuzzifyBlock] = []
    discr: list[tuple[str, int]] = []
    for slot in order:
        v = kb.variable(slot)
        kind = slot_kind(slot)
        vname = names[slot]
        rng = m.Range(float(v.low), float(v.high)) if (v.low, v.high) != (0, 0) else None
        vk = {SlotKind.INPUT: m.VarKind.INPUT, SlotKind.OUTPUT: m.VarKind.OUTPUT}.get(kind, m.VarKind.LOCAL)
        variables.append(m.Variable(vname, vk, "INT", range=rng))
        tt = tuple(terms[slot])
        if (kind is SlotKind.INPUT or slot in as_predicate) and tt:
            fuzzify.append(m.FuzzifyBlock(vname, tt))
        if kind is not SlotKind.INPUT:
            discr.append((vname, v.discr))
            if tt:
                default = m.Default(float(c.o_def[slot - 8])) if kind is SlotKind.OUTPUT else None
                defuzzify.append(m.DefuzzifyBlock(vname, tt, range=rng, method=method, default=default))
    rules: list[m.Rule] = []
    for rule in kb.rules:
        conds: list[m.Condition] = []
        for number, negated in rule.predicates:
            pred_mf = kb.membership(number)
            if pred_mf is None or not 0 <= pred_mf.slot < 18:
                continue
            conds.append(m.Is(names[pred_mf.slot], term_names[number], negated=negated))
        concl = tuple(
            m.Conclusion(names[kb.memberships[n].slot], term_names[n])
            for n in rule.conclusions
            if 0 <= n < len(kb.memberships) and n in term_names
        )
        cond: m.Condition | None = conds[0] if len(conds) == 1 else (m.And(tuple(conds)) if conds else None)
        rules.append(m.Rule(str(rule.number), cond, concl))
    rules, fuzzify = _rules_without_if(kb, rules, fuzzify, term_names)
    ops = {0: "MIN", 1: "PROD"}
    block = m.FunctionBlock(
        name,
        tuple(variables),
        tuple(fuzzify),
        tuple(defuzzify),
        (m.RuleBlock("xfuz", tuple(rules), and_op=ops[c.op_et], act=ops[c.op_impl], accu="MAX"),),
        (m.OptionsBlock(_options_text(c, renamed, discr)),),
    )
    return block, diags


def _rules_without_if(
    kb: KnowledgeBase, rules: list[m.Rule], fuzzify: list[m.FuzzifyBlock], term_names: dict[int, str]
) -> tuple[list[m.Rule], list[m.FuzzifyBlock]]:
    """The form the writer gives a rule without an IF part (Siemens 1.5), read back: a rule
    whose only predicate is an input function named ``ALWAYS`` (``ALWAYS2``, ...) open on both
    sides (1 for every input word) has no IF part; the function goes when no rule is left
    that names it."""
    always = {
        term_names[mf.number]
        for mf in kb.memberships
        if mf.number in term_names
        and slot_kind(mf.slot) is SlotKind.INPUT
        and re.fullmatch(r"ALWAYS\d*", mf.name or "")
        and (mf.a, mf.b, mf.c, mf.d) == (OPEN_LOW, OPEN_LOW, OPEN_HIGH, OPEN_HIGH)
    }

    def bare(cond: m.Condition | None) -> bool:
        return isinstance(cond, m.Is) and not cond.negated and cond.term in always

    if not any(bare(r.condition) for r in rules):
        return rules, fuzzify
    carried = {
        (r.condition.variable, r.condition.term)
        for r in rules
        if isinstance(r.condition, m.Is) and bare(r.condition)
    }
    rules = [replace(r, condition=None) if bare(r.condition) else r for r in rules]
    still = {(leaf.variable, leaf.term) for r in rules for leaf in _predicates(r.condition)}
    fuzzify = [
        replace(f, terms=tuple(t for t in f.terms if (f.variable, t.name) not in carried - still))
        for f in fuzzify
    ]
    return rules, [f for f in fuzzify if f.terms]


def _predicates(cond: m.Condition | None) -> Iterator[m.Is]:
    if isinstance(cond, m.Is):
        yield cond
    elif isinstance(cond, m.And):
        for c in cond.operands:
            yield from _predicates(c)


def _decode(text: str, path: str | None) -> tuple[m.Document, list[Diagnostic]]:
    constants = read_tables(text, path=path)
    stem = (path or "xfuz").replace("\\", "/").rsplit("/", 1)[-1].split(".", 1)[0]
    block, diags = model_from_constants(constants, name=stem if fcl_name(stem) else "xfuz")
    if not constants.out_pt or block.locals:
        diags.append(
            Diagnostic(
                Severity.NOTE,
                "evaluated as FCL (fuzzyctl eval) this program has IEC semantics: an exact centre of "
                "gravity and crisp values through intermediate variables; the XFUZ block (fuzzyctl "
                "blocks xfuz) computes on the Discr points and chains fuzzy sets (manual 2.2)",
                code="xfuz-semantics",
            )
        )
    diags = [replace(d, file=path) for d in diags]
    if any(d.is_error for d in diags):
        raise DiagnosticError(diags, text)
    return m.Document((block,), path=path), diags


def read_xfuz(text: str, *, path: str | None = None) -> m.Document:
    """Read a table file into a Document (raises DiagnosticError when it cannot be decoded)."""
    return _decode(text, path)[0]


def read(text: str, path: str | None = None) -> Loaded:
    """The registry's reader: the model and the warnings of decoding it."""
    document, diags = _decode(text, path)
    return Loaded(document, tuple(diags))
