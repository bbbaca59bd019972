"""Acceptance with a python-snap7 server standing in for an S7 PLC (REALs in DB1), and the
safety chain across two links: inputs from the S7 PLC, outputs to a Modbus PLC that sees
the safe values when the S7 PLC goes away, and computed values again when it is back."""

from __future__ import annotations

import time
from pathlib import Path

from tests.io.plcs import S7PLC, ModbusPLC, wait_until
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


def test_s7_plc_outputs_match_the_engine(tmp_path: Path) -> None:
    plc = S7PLC()
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
Temp = {{ connection = "cpu", db = 1, offset = 0 }}
Pressure = {{ connection = "cpu", db = 1, offset = 4 }}

[instances.valve.outputs]
Valve = {{ connection = "cpu", db = 1, offset = 8, safe = 0.0 }}
INFO = {{ connection = "cpu", db = 1, offset = 12, type = "int" }}
""",
    )
    try:
        rt.start()
        for temp, pressure in [(9.0, 65.0), (27.5, 52.0), (0.5, 94.0), (31.0, 49.0)]:
            plc.set_real(0, temp)
            plc.set_real(4, pressure)
            want = fpltest_reference(temp, pressure)
            wait_until(lambda w=want: close(plc.real(8), w), 10)
        assert plc.int(12) == 0
    finally:
        rt.stop()
        plc.close()
    assert_log_complete(rt, tmp_path / "events.jsonl")


def test_losing_the_input_plc_puts_safe_values_on_the_output_plc_and_recovers(tmp_path: Path) -> None:
    cpu, out = S7PLC(), ModbusPLC()
    rt = make_runtime(
        tmp_path,
        f"""
[connections.cpu]
type = "s7"
port = {cpu.port}
poll_interval = 0.005
timeout = 0.5
reconnect_min = 0.05
reconnect_max = 0.2

[connections.out]
type = "modbus"
port = {out.port}
poll_interval = 0.005

[instances.valve]
knowledge_base = "{FPLTEST_FCL}"
period = 0.01
hold_time = 0.25

[instances.valve.inputs]
Temp = {{ connection = "cpu", db = 1, offset = 0 }}
Pressure = {{ connection = "cpu", db = 1, offset = 4 }}

[instances.valve.outputs]
Valve = {{ connection = "out", address = 0, safe = 55.5 }}
INFO = {{ connection = "out", address = 2, type = "uint16" }}
""",
    )
    try:
        rt.start()
        cpu.set_real(0, 9.0)
        cpu.set_real(4, 65.0)
        wait_until(lambda: close(out.float(0), FPLTEST_9_65), 10)
        stopped_at = time.monotonic()
        cpu.stop()
        wait_until(
            lambda: out.float(0) == 55.5 and out.registers(2, 1) == [0x41], 10
        )  # safe value, INFO 16#41
        cpu.start()  # same port, the DB still holds the process values
        wait_until(lambda: close(out.float(0), FPLTEST_9_65) and out.registers(2, 1) == [0], 15)
    finally:
        rt.stop()
        cpu.close()
        out.close()
    events = until_stop(assert_log_complete(rt, tmp_path / "events.jsonl"))
    # From the stop on (a slow first answer at start-up may already have been lost and retried).
    seq = safety_sequence([e for e in events if e.mono >= stopped_at], instance="valve", link="cpu")
    assert seq == ["link-lost", "hold-start", "safe-enter", "link-up", "safe-exit"]
    assert fpltest_reference(9.0, 65.0) == FPLTEST_9_65
