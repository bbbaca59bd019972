"""Block styles, invalid inputs and online download, through the runtime's own Modbus
server (a test client plays the master)."""

from __future__ import annotations

import math
from pathlib import Path

from pymodbus.client import ModbusTcpClient

from fuzzyctl.io.codec import float32_from_registers, float32_to_registers, int16_to_register
from fuzzyctl.runtime.adapters import INFO_BLOCK_FAULT, INFO_HOLD, INFO_SAFE, STATUS_IO_FAULT_BIT
from fuzzyctl.runtime.kb import KnowledgeBaseSource
from tests.conftest import EXAMPLES
from tests.io.plcs import wait_until
from tests.runtime.helpers import (
    FPLTEST_9_65,
    FPLTEST_FCL,
    assert_log_complete,
    close,
    fpltest_reference,
    make_runtime,
    safety_sequence,
    until_stop,
)


def master(rt) -> ModbusTcpClient:  # type: ignore[no-untyped-def]
    wait_until(lambda: rt.links["mb"].up, 10)
    client = ModbusTcpClient("127.0.0.1", port=rt.links["mb"].connector.port, timeout=2)
    assert client.connect()
    return client


def test_xfuz_instance_computes_the_manual_3_3_values_over_int16_registers(tmp_path: Path) -> None:
    rt = make_runtime(
        tmp_path,
        f"""
[connections.mb]
type = "modbus-server"
port = 0
poll_interval = 0.005

[instances.debit]
style = "xfuz"
knowledge_base = "{EXAMPLES / "xfuz_3_3.xfuz"}"
span_rule = false
period = 0.01
params = {{ MAN_AUTO = 1, START = 1, CONT_ASK = 0, T_OFB = 0 }}

[instances.debit.inputs]
INP1 = {{ connection = "mb", address = 0, type = "int16" }}
INP4 = {{ connection = "mb", address = 1, type = "int16" }}

[instances.debit.outputs]
OUT3 = {{ connection = "mb", table = "input", address = 0, type = "int16", safe = -1 }}
STATUS = {{ connection = "mb", table = "input", address = 1, type = "int16" }}
""",
    )
    try:
        rt.start()
        mb = master(rt)
        # Hand-computed in docs/blocks.md (manual 3.3): Pression 0, Temperature -50 -> 8
        # (7.50 before rounding with 20 points).
        for pression, temperature, want in [(0, -50, 8)]:
            mb.write_registers(0, [int16_to_register(pression), int16_to_register(temperature)])
            wait_until(lambda w=want: mb.read_input_registers(0, count=2).registers == [w, 0], 10)
        mb.close()
    finally:
        rt.stop()
    assert_log_complete(rt, tmp_path / "events.jsonl")


SIEMENS_SERVER = f"""
[connections.mb]
type = "modbus-server"
port = 0
poll_interval = 0.005

[instances.valve]
knowledge_base = "{FPLTEST_FCL}"
period = 0.01
hold_time = 0.2

[instances.valve.inputs]
Temp = {{ connection = "mb", address = 0 }}
Pressure = {{ connection = "mb", address = 2 }}

[instances.valve.outputs]
Valve = {{ connection = "mb", address = 10, safe = 12.5 }}
INFO = {{ connection = "mb", address = 12, type = "uint16" }}
"""


def test_a_nan_input_is_never_propagated_hold_then_safe_then_recovery(tmp_path: Path) -> None:
    rt = make_runtime(tmp_path, SIEMENS_SERVER)
    try:
        rt.start()
        mb = master(rt)

        def valve() -> float:
            r = mb.read_holding_registers(10, count=3).registers
            return float32_from_registers(r[0], r[1])

        def info() -> int:
            return int(mb.read_holding_registers(12, count=1).registers[0])

        mb.write_registers(0, [*float32_to_registers(9.0), *float32_to_registers(65.0)])
        wait_until(lambda: close(valve(), FPLTEST_9_65) and info() == 0, 10)
        mb.write_registers(0, list(float32_to_registers(math.nan)))
        wait_until(lambda: info() == INFO_HOLD, 10)
        # hold: the last good Temp (9.0) is used, NaN never reaches the block
        assert close(valve(), FPLTEST_9_65)
        wait_until(lambda: info() == INFO_SAFE and valve() == 12.5, 10)
        assert rt.instances["valve"].adapter.block.INPUT1 == 9.0
        mb.write_registers(0, list(float32_to_registers(25.0)))
        want = fpltest_reference(25.0, 65.0)
        wait_until(lambda: close(valve(), want) and info() == 0, 10)
        mb.write_registers(0, list(float32_to_registers(1e6)))  # out of range: clamped to MAX (1.5)
        wait_until(lambda: close(valve(), fpltest_reference(30.0, 65.0)), 10)
        mb.close()
    finally:
        rt.stop()
    events = assert_log_complete(rt, tmp_path / "events.jsonl")
    kinds = safety_sequence(events, instance="valve")
    i = kinds.index("input-invalid")
    assert kinds[i : i + 5] == ["input-invalid", "hold-start", "safe-enter", "input-valid", "safe-exit"]


def test_online_download_switches_between_two_cycles_and_is_logged(tmp_path: Path) -> None:
    """Two knowledge bases that differ only in the inlet singleton (100 vs 60): every cycle
    must show the output of the knowledge base it ran with, never a mixture."""
    rt = make_runtime(
        tmp_path,
        f"""
[instances.valve]
knowledge_base = "{FPLTEST_FCL}"
period = 0.002
""",
    )
    text_a = FPLTEST_FCL.read_text(encoding="utf-8")
    text_b = text_a.replace("TERM inlet := 100;", "TERM inlet := 60;")
    assert text_a != text_b
    inst = rt.instances["valve"]
    seen: list[tuple[str, float, int]] = []
    # Inputs are unbound: INPUT1 = 0, INPUT2 = 0 -> clamped to Temp 0, Pressure 50: cold AND low -> inlet.
    inst.task.add(
        lambda ctx: seen.append(
            (inst.adapter.kb.source.sha256, inst.adapter.block.OUTPUT1, inst.adapter.block.INFO)
        )
    )
    try:
        rt.start()
        wait_until(lambda: len(seen) > 5)
        for k in range(20):
            result = rt.download("valve", text_b if k % 2 == 0 else text_a, "fcl")
            assert result["procedure"].startswith("START_STOP = 0")
            n = len(seen)
            wait_until(lambda n=n: len(seen) > n + 2)
    finally:
        rt.stop()
    sha_a = KnowledgeBaseSource(text_a, "fcl", "").sha256
    sha_b = KnowledgeBaseSource(text_b, "fcl", "").sha256
    expected = {sha_a: 100.0, sha_b: 60.0}  # the configuration's file is text A
    assert {sha for sha, _, _ in seen} == {sha_a, sha_b}
    for sha, out, info in seen:
        assert out == expected[sha] and info == 0, (sha, out, info)
    events = assert_log_complete(rt, tmp_path / "events.jsonl")
    assert [e.kind for e in events].count("download") == 20
    assert [e.kind for e in events].count("download-applied") == 20


def test_xfuz_download_takes_effect_through_refresh(tmp_path: Path) -> None:
    import fuzzyctl
    from fuzzyctl.formats import convert

    tables = EXAMPLES / "xfuz_3_3.xfuz"
    rt = make_runtime(
        tmp_path,
        f"""
[instances.debit]
style = "xfuz"
knowledge_base = "{tables}"
span_rule = false
period = 0.005
params = {{ MAN_AUTO = 1, START = 1, CONT_ASK = 0, T_OFB = 0 }}
""",
    )
    inst = rt.instances["debit"]
    inst.adapter.block["INP4"] = -50  # Pression (INP1) 0, Temperature -50 -> OUT3 = 8
    log: list[tuple[int, bool, int]] = []
    inst.task.add(
        lambda ctx: log.append((inst.adapter.block["OUT3"], inst.adapter.block.inferred, inst.downloads))
    )
    fcl_text, _ = convert(fuzzyctl.load(tables), "fcl", lossy=True)
    try:
        rt.start()
        wait_until(lambda: any(o == 8 for o, _, _ in log))
        rt.download("debit", fcl_text, "fcl")
        wait_until(lambda: any(e.kind == "download-applied" for e in rt.events.since(0)))
        n = len(log)
        wait_until(lambda: len(log) > n + 3)
    finally:
        rt.stop()
    after = [entry for entry in log if entry[2] == 1]
    # The REFRESH call loads the base and does not infer (manual 2.6-4): OUT3 back at O3_DEF$.
    switch = next(i for i, (_, inferred, _) in enumerate(after) if not inferred)
    assert after[switch][0] == 0
    assert all(o == 8 for o, inferred, _ in after[switch + 1 :] if inferred)


def test_xfuz_lost_link_raises_status_bit_15_and_error_and_puts_safe_words_out(tmp_path: Path) -> None:
    from tests.io.plcs import ModbusPLC

    plc, out = ModbusPLC(), ModbusPLC()
    rt = make_runtime(
        tmp_path,
        f"""
[connections.plc]
type = "modbus"
port = {plc.port}
timeout = 0.3
poll_interval = 0.005
reconnect_min = 0.05
reconnect_max = 0.1

[connections.out]
type = "modbus"
port = {out.port}
poll_interval = 0.005

[instances.debit]
style = "xfuz"
knowledge_base = "{EXAMPLES / "xfuz_3_3.xfuz"}"
span_rule = false
period = 0.01
hold_time = 0.1
params = {{ MAN_AUTO = 1, START = 1, CONT_ASK = 0, T_OFB = 0 }}

[instances.debit.inputs]
INP1 = {{ connection = "plc", address = 0, type = "int16" }}
INP4 = {{ connection = "plc", address = 1, type = "int16" }}

[instances.debit.outputs]
OUT3 = {{ connection = "out", address = 0, type = "int16", safe = -7 }}
STATUS = {{ connection = "out", address = 1, type = "int16" }}
ERROR = {{ connection = "out", address = 2, type = "uint16" }}
""",
    )
    try:
        rt.start()
        plc.set_registers(0, [0, int16_to_register(-50)])
        wait_until(lambda: out.registers(0, 3) == [8, 0, 0], 10)
        plc.stop()
        fault = int16_to_register(-(1 << STATUS_IO_FAULT_BIT))  # bit 15 of a signed word
        wait_until(lambda: out.registers(0, 3) == [int16_to_register(-7), fault, 1], 10)
        snap = rt.instances["debit"].snapshot()
        assert snap["state"] == "safe" and snap["status"] == {"STATUS": -32768, "ERROR": 1}
        assert snap["outputs"] == {"OUT3": 8.0}  # the block still holds its own value
    finally:
        rt.stop()
        plc.close()
        out.close()


def test_a_block_that_cannot_compute_puts_the_safe_value_and_info_42_in_the_field(tmp_path: Path) -> None:
    """A controller whose inlet singleton (1E39) is beyond the REAL range: cold and low
    make the block compute +inf.  The master must read the safe value with INFO 16#42 and
    the instance must say ``safe`` with the reason, until the block computes again."""
    kb = tmp_path / "huge.fcl"
    kb.write_text(FPLTEST_FCL.read_text().replace("TERM inlet := 100;", "TERM inlet := 1E39;"))
    rt = make_runtime(tmp_path, SIEMENS_SERVER.replace(str(FPLTEST_FCL), str(kb)))
    inst = rt.instances["valve"]
    try:
        rt.start()
        mb = master(rt)

        def field() -> tuple[float, int]:
            r = mb.read_holding_registers(10, count=3).registers
            return float32_from_registers(r[0], r[1]), int(r[2])

        mb.write_registers(0, [*float32_to_registers(29.0), *float32_to_registers(99.0)])  # hot, high
        wait_until(lambda: field() == (-100.0, 0) and inst.snapshot()["state"] == "run", 10)
        mb.write_registers(0, [*float32_to_registers(1.0), *float32_to_registers(52.0)])  # cold, low
        wait_until(lambda: field() == (12.5, INFO_BLOCK_FAULT), 10)
        snap = inst.snapshot()
        assert snap["state"] == "safe" and "OUTPUT1 = inf" in snap["problems"]["block"][0]
        assert snap["field_outputs"]["Valve"] == 12.5 and snap["status"]["INFO"] == INFO_BLOCK_FAULT
        mb.write_registers(0, [*float32_to_registers(29.0), *float32_to_registers(99.0)])
        wait_until(lambda: field() == (-100.0, 0) and inst.snapshot()["state"] == "run", 10)
        assert inst.snapshot()["problems"]["block"] == []
        mb.close()
    finally:
        rt.stop()
    events = until_stop(assert_log_complete(rt, tmp_path / "events.jsonl"))
    wanted = {"error", "error-cleared", "safe-enter", "safe-exit", "hold-start", "hold-end"}
    kinds = [e.kind for e in events if e.instance == "valve" and e.kind in wanted]
    # (The registers hold 0, 0 before the master writes: cold and low, a first episode.)
    assert kinds[-4:] == ["error", "safe-enter", "error-cleared", "safe-exit"], kinds
    last_safe = [e for e in events if e.kind == "safe-enter"][-1]
    assert last_safe.data["reason"] == "block error" and "OUTPUT1 = inf" in last_safe.data["error"]


def test_a_parameter_the_field_writes_out_of_range_is_refused_and_the_block_runs_on(tmp_path: Path) -> None:
    rt = make_runtime(
        tmp_path,
        f"""
[connections.mb]
type = "modbus-server"
port = 0
poll_interval = 0.005

[instances.debit]
style = "xfuz"
knowledge_base = "{EXAMPLES / "xfuz_3_3.xfuz"}"
span_rule = false
period = 0.01
params = {{ MAN_AUTO = 1, START = 1, CONT_ASK = 0, T_OFB = 0 }}

[instances.debit.inputs]
INP1 = {{ connection = "mb", address = 0, type = "int16" }}
INP4 = {{ connection = "mb", address = 1, type = "int16" }}

[instances.debit.outputs]
OUT3 = {{ connection = "mb", table = "input", address = 0, type = "int16", safe = -1 }}

[instances.debit.parameters]
T_OFB = {{ connection = "mb", address = 5, type = "int16" }}
""",
    )
    inst = rt.instances["debit"]
    try:
        rt.start()
        mb = master(rt)
        mb.write_registers(0, [int16_to_register(0), int16_to_register(-50)])
        wait_until(lambda: mb.read_input_registers(0, count=1).registers == [8], 10)
        t_ofb = inst.snapshot()["parameters"]["T_OFB"]
        mb.write_registers(5, [int16_to_register(-5)])  # T_OFB is 0..32767
        wait_until(lambda: any(e.kind == "parameter-refused" for e in rt.events.since(0)), 10)
        cycles = inst.task.stats.count
        wait_until(lambda: inst.task.stats.count > cycles + 5, 10)
        snap = inst.snapshot()
        assert snap["state"] == "run" and snap["error"] is None and snap["parameters"]["T_OFB"] == t_ofb
        assert mb.read_input_registers(0, count=1).registers == [8]
        mb.close()
    finally:
        rt.stop()
    assert not any(e.kind == "error" for e in rt.events.since(0))


def test_an_internal_error_in_one_instance_puts_it_safe_and_the_others_run_on(tmp_path: Path) -> None:
    two = (
        SIEMENS_SERVER
        + f"""
[instances.other]
knowledge_base = "{FPLTEST_FCL}"
period = 0.01
"""
    )
    rt = make_runtime(tmp_path, two)
    valve, other = rt.instances["valve"], rt.instances["other"]

    def broken(period: float) -> None:
        raise ZeroDivisionError("a bug")

    try:
        rt.start()
        mb = master(rt)
        mb.write_registers(0, [*float32_to_registers(9.0), *float32_to_registers(65.0)])
        wait_until(lambda: valve.snapshot()["state"] == "run", 10)
        valve.adapter.execute = broken  # type: ignore[method-assign]
        wait_until(lambda: valve.snapshot()["state"] == "safe", 10)

        def field_safe() -> bool:  # the next cycle of the link puts the safe value out
            r = mb.read_holding_registers(10, count=3).registers
            return float32_from_registers(r[0], r[1]) == 12.5 and r[2] == INFO_BLOCK_FAULT

        wait_until(field_safe, 10)
        assert "internal error: ZeroDivisionError: a bug" in valve.snapshot()["error"]
        cycles = other.task.stats.count
        wait_until(lambda: other.task.stats.count > cycles + 10, 10)  # the cycle thread lives on
        assert rt.scheduler.alive and other.snapshot()["state"] == "run"
        mb.close()
    finally:
        rt.stop()
