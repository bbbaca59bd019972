"""``fuzzyctl serve`` beside a PLC that holds a Siemens FUZZY instance DB (S7 Fuzzy Control
manual, Tables 3-1..3-3): bindings by parameter name, against a python-snap7 server whose
DB30 is laid out exactly as the tables say.  The layout is transcribed here from the
manual, with S7's encodings (REAL: IEEE single, WORD: 16-bit unsigned, BYTE; big-endian),
and never taken from fuzzyctl's own table."""

from __future__ import annotations

import re
import struct
from pathlib import Path

import pytest

from fuzzyctl.io.s7 import S7Point
from tests.conftest import shared_path
from tests.io.plcs import S7PLC, wait_until
from tests.runtime.helpers import FPLTEST_FCL, assert_log_complete, f32, make_runtime

# Tables 3-1, 3-2 and 3-3 as printed: byte, parameter, data type, default.
MANUAL_TABLES = """
0 INPUT1 REAL 0.0
4 INPUT2 REAL 0.0
8 INPUT3 REAL 0.0
12 INPUT4 REAL 0.0
16 INPUT5 REAL 0.0
20 INPUT6 REAL 0.0
24 INPUT7 REAL 0.0
28 INPUT8 REAL 0.0
32 OUTPUT1 REAL 0.0
36 OUTPUT2 REAL 0.0
40 OUTPUT3 REAL 0.0
44 OUTPUT4 REAL 0.0
48 INFO BYTE B#16#0
50 START_STOP WORD W#16#0
"""
INTERNAL = (52, 2126)  # "52 to 2126 FUZZY BYTE Internal area for the function block"
DB_LENGTH = 2126  # 3.4: "Block length at runtime 2126 bytes"
S7_FORMAT = {"REAL": ">f", "WORD": ">H", "BYTE": ">B"}  # S7 stores big-endian


def layout() -> dict[str, tuple[int, str]]:
    rows = [line.split() for line in MANUAL_TABLES.strip().splitlines()]
    return {name: (int(byte), S7_FORMAT[kind]) for byte, name, kind, _default in rows}


LAYOUT = layout()


def put(db: bytearray, name: str, value: float) -> None:
    offset, fmt = LAYOUT[name]
    struct.pack_into(fmt, db, offset, value)


def get(db: bytearray, name: str) -> float:
    offset, fmt = LAYOUT[name]
    return float(struct.unpack_from(fmt, db, offset)[0])


def test_siemens_3_1_parameter_names_address_the_manual_s_bytes() -> None:
    for name, (offset, fmt) in LAYOUT.items():
        point = S7Point.model_validate({"db": 30, "parameter": name.lower()})
        assert (point.parameter, point.offset, point.width) == (name, offset, struct.calcsize(fmt))
        assert point.describe().startswith(f"DB30.{name} (DB30.DB")
    first = S7Point.model_validate({"db": 30, "parameter": "FUZZY[0]"})
    last = S7Point.model_validate({"db": 30, "parameter": "FUZZY[2073]"})
    assert (first.offset, last.offset + last.width) == INTERNAL
    for bad in ("FUZZY[2074]", "INPUT9", "OUTPUT5", "ENO"):
        with pytest.raises(ValueError, match="not a parameter of a FUZZY instance DB"):
            S7Point.model_validate({"db": 30, "parameter": bad})
    with pytest.raises(ValueError, match="either parameter"):
        S7Point.model_validate({"db": 30, "parameter": "INFO", "offset": 48})
    # BYTE and WORD as S7 stores them: saturated, big-endian
    assert S7Point(db=1, offset=0, type="byte").encode(300) == b"\xff"
    assert S7Point.model_validate({"db": 1, "parameter": "START_STOP"}).encode(0xFFFF) == b"\xff\xff"
    assert S7Point.model_validate({"db": 1, "parameter": "START_STOP"}).decode(b"\x01\x02", 0) == 0x0102


@pytest.mark.extra("seeds")
def test_siemens_3_1_the_transcribed_tables_are_the_manual_s() -> None:
    text = shared_path("seeds", "003_9b3af9c2802d2be3.txt").read_text(encoding="utf-8")
    printed = {
        m.group(2): (int(m.group(1)), m.group(3), m.group(4))
        for m in re.finditer(
            r"^(\d+)\t(INPUT\d|OUTPUT\d|INFO|START_STOP)\t(REAL|BYTE|WORD)\t.*\t(\S+)$", text, re.M
        )
    }
    mine = {
        row.split()[1]: (int(row.split()[0]), row.split()[2], row.split()[3])
        for row in MANUAL_TABLES.split("\n")
        if row
    }
    assert printed == mine
    assert "52 to 2126\tFUZZY\tBYTE" in text and "Block length at runtime\t2126 bytes" in text


def test_serve_stands_in_for_fb30_in_a_fuzzy_instance_db(tmp_path: Path) -> None:
    data = bytearray(DB_LENGTH)
    first, end = INTERNAL
    pattern = bytes((7 * k + 3) % 256 for k in range(end - first))
    data[first:end] = pattern  # the PLC's internal area: serve must never touch it
    put(data, "INPUT1", 9.0)  # written by FUZZY_AI in the PLC
    put(data, "INPUT2", 65.0)
    put(data, "OUTPUT2", -7.5)  # not bound: must stay
    plc = S7PLC(db=30, data=data)
    rt = make_runtime(
        tmp_path,
        f"""
[connections.cpu]
type = "s7"
port = {plc.port}
poll_interval = 0.005

[instances.valve]
knowledge_base = "{FPLTEST_FCL}"
period = 0.01

[instances.valve.inputs]
Temp = {{ connection = "cpu", db = 30, parameter = "INPUT1" }}
Pressure = {{ connection = "cpu", db = 30, parameter = "INPUT2" }}

[instances.valve.outputs]
Valve = {{ connection = "cpu", db = 30, parameter = "OUTPUT1", safe = 0.0 }}
INFO = {{ connection = "cpu", db = 30, parameter = "INFO" }}

[instances.valve.parameters]
START_STOP = {{ connection = "cpu", db = 30, parameter = "START_STOP" }}
""",
    )
    try:
        rt.start()
        # A fresh DB has START_STOP = W#16#0 (Table 3-3); the download enables the block as
        # the configuration tool does (W#16#FFFF), and serve writes that into the DB.
        # OUTPUT1: FPLTEST at 9 / 65 by manual 1.4, (75 - 25) / 1.5 = 100/3 as a REAL.
        wait_until(lambda: get(data, "OUTPUT1") == f32(100 / 3) and get(data, "START_STOP") == 0xFFFF, 10)
        assert get(data, "INFO") == 0x00
        # The PLC program stops the block: INFO 01, OUTPUT1 keeps its old value.
        put(data, "START_STOP", 0)
        wait_until(lambda: get(data, "INFO") == 0x01, 10)
        put(data, "INPUT1", 30.0)
        wait_until(lambda: rt.instances["valve"].adapter.block.INPUT1 == 30.0, 10)
        assert get(data, "OUTPUT1") == f32(100 / 3)
        # ... and starts it again with any word other than 0: hot 1, low .75, high .25 ->
        # closed .75, drainage .25 -> -25.
        put(data, "START_STOP", 0x0123)
        wait_until(lambda: get(data, "OUTPUT1") == -25.0 and get(data, "INFO") == 0x00, 10)
        assert rt.instances["valve"].adapter.block.START_STOP == 0x0123
    finally:
        rt.stop()
        plc.close()
    assert data[first:end] == pattern
    assert get(data, "OUTPUT2") == -7.5 and get(data, "OUTPUT3") == 0.0 and data[49] == 0
    assert len(data) == DB_LENGTH
    assert_log_complete(rt, tmp_path / "events.jsonl")


def test_a_command_written_right_after_our_mirror_is_not_lost(tmp_path: Path) -> None:
    """The field changes START_STOP after serve wrote its mirror but before serve read the
    mirror back: the read differs from what the field last held (our write), so it is a
    command, even though it equals the value read before.  Driven by hand (no threads)."""
    from fuzzyctl.io.base import LinkState

    rt = make_runtime(
        tmp_path,
        f"""
[connections.cpu]
type = "s7"
port = 1

[instances.valve]
knowledge_base = "{FPLTEST_FCL}"
period = 0.01

[instances.valve.parameters]
START_STOP = {{ connection = "cpu", db = 30, parameter = "START_STOP" }}
""",
    )
    inst = rt.instances["valve"]
    (p,) = inst.params
    p.link.state = LinkState.UP
    block = inst.adapter.block
    assert block.START_STOP == 0xFFFF  # downloaded and enabled

    def read(value: float, stamp: float) -> None:
        p.cell.value, p.cell.stamp = value, stamp
        inst._param_from_field(p)

    read(0.0, 1.0)  # a fresh DB holds W#16#0: not a command
    assert block.START_STOP == 0xFFFF
    p.mirror.sent, p.mirror.last_send = 0xFFFF, (0xFFFF, 2.0)  # serve writes its mirror
    read(0.0, 1.5)  # a read older than our write: still the fresh DB, not a command
    assert block.START_STOP == 0xFFFF
    read(0.0, 3.0)  # the program wrote 0 between our write (2.0) and this read: stop
    assert block.START_STOP == 0
    p.mirror.sent, p.mirror.last_send = 0, (0, 4.0)
    read(0.0, 5.0)  # the echo of our mirror: nothing
    assert block.START_STOP == 0
    read(0x0123, 6.0)  # any word other than 0 starts it again
    assert block.START_STOP == 0x0123
    p.mirror.sent, p.mirror.last_send = 0x0123, (0x0123, 7.0)
    read(0x0123, 8.0)
    assert block.START_STOP == 0x0123
