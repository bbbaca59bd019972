"""Writing an XFUZ table file in its JSON or CSV layout (the layouts are described in
:mod:`.reader`, which reads both): the writer's last step, and ``fuzzyctl blocks`` tables."""

from __future__ import annotations

import csv
import io
import json
import re
from collections.abc import Iterator

from fuzzyctl.formats.xfuz.names import FORMAT_TAG, constants_mapping
from fuzzyctl.formats.xfuz.tables import XfuzConstants, decode_kb, esv_offsets, slot_label

__all__ = ["write_tables"]


def _notes(c: XfuzConstants) -> dict[tuple[str, int], str]:
    notes: dict[tuple[str, int], str] = {}
    for slot in range(18):
        label = slot_label(slot)
        if slot < 8:
            notes[("ESV", 2 * slot)], notes[("ESV", 2 * slot + 1)] = f"{label} BorneInf", f"{label} BorneSup"
        else:
            base = 16 + 3 * (slot - 8) if slot < 14 else 34 + 3 * (slot - 14)
            for k, what in enumerate(("BorneInf", "BorneSup", "Discr")):
                notes[("ESV", base + k)] = f"{label} {what}"
            if slot >= 14:
                for k in range(4):
                    notes[("ESV", 46 + 4 * (slot - 14) + k)] = f"{label} Nom({2 * k + 1}-{2 * k + 2})"
    for n in range(64):
        for k, what in enumerate(
            ("Nom(1-2)", "Nom(3-4)", "Nom(5-6)", "Nom(7-8)", "Variable", "xA", "xB", "xC", "xD")
        ):
            notes[("FA", 9 * n + k)] = f"FA{n} {what}"
    for r in range(64):
        for k, what in enumerate(("Pred1", "Pred2", "Pred3", "Pred4", "Concl1", "Concl2")):
            notes[("RG", 6 * r + k)] = f"REG{r} {what}"
    return notes


def _used_ranges(c: XfuzConstants) -> Iterator[tuple[str, int]]:
    """The words worth writing: every non-zero word, whole records of used functions and
    rules, and the terminators."""
    kb = decode_kb(c)
    keep: set[tuple[str, int]] = set()
    for name, words in (("ESV", c.esv), ("FA", c.fa), ("RG", c.rg)):
        keep.update((name, k) for k, w in enumerate(words) if w)
    for v in kb.variables:
        keep.update(("ESV", k) for k in esv_offsets(v.slot) if k is not None)
    for mf in kb.memberships:
        keep.update(("FA", 9 * mf.number + k) for k in range(9))
    for rule in kb.rules:
        keep.update(("RG", 6 * rule.number + k) for k in range(6))
    order = {"ESV": 0, "FA": 1, "RG": 2}
    yield from sorted(keep, key=lambda t: (order[t[0]], t[1]))


def write_tables(constants: XfuzConstants, *, layout: str = "json") -> str:
    """Table file text in the ``json`` or ``csv`` layout."""
    if layout == "json":
        body = {
            "format": FORMAT_TAG,
            "version": 1,
            "constants": constants_mapping(constants),
            "ESV": list(constants.esv),
            "FA": list(constants.fa),
            "RG": list(constants.rg),
        }
        text = json.dumps(body, indent=1)
        # One table per line is easier to read and diff than one word per line.
        return (
            re.sub(r"\[\s+([-\d,\s]+?)\s+\]", lambda m: "[" + re.sub(r"\s+", " ", m.group(1)) + "]", text)
            + "\n"
        )
    if layout != "csv":
        raise ValueError(f"layout must be 'json' or 'csv', not {layout!r}")
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    w.writerow(["table", "index", "value", "note"])
    for key, value in constants_mapping(constants).items():
        w.writerow(["CONST", key, value, ""])
    notes = _notes(constants)
    tables = {"ESV": constants.esv, "FA": constants.fa, "RG": constants.rg}
    for table, index in _used_ranges(constants):
        w.writerow([table, index, tables[table][index], notes.get((table, index), "")])
    return out.getvalue()
