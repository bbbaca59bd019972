"""Names the XFUZ table reader and writer share: the tag of a JSON table file, and the block
constants besides the tables (manual 3.2)."""

from __future__ import annotations

from fuzzyctl.formats.xfuz.tables import XfuzConstants

FORMAT_TAG = "xfuz-tables"

CONSTANT_KEYS = (
    "OP_CONJ",
    "OP_ET",
    "OP_IMPL",
    "OP_AGREG",
    "OP_DEFUZ",
    "OUT_PT",
    "CONTASK$",
    "T_OFB$",
    *(f"O{i}_DEF$" for i in range(1, 7)),
)
DEFAULTS = {"CONTASK$": 1, "T_OFB$": 200}


def constants_mapping(c: XfuzConstants) -> dict[str, int]:
    values = {
        "OP_CONJ": c.op_conj,
        "OP_ET": c.op_et,
        "OP_IMPL": c.op_impl,
        "OP_AGREG": c.op_agreg,
        "OP_DEFUZ": c.op_defuz,
        "OUT_PT": int(c.out_pt),
        "CONTASK$": int(c.contask),
        "T_OFB$": c.t_ofb,
    }
    values.update({f"O{i + 1}_DEF$": v for i, v in enumerate(c.o_def)})
    return values
