"""Acceptance with a pymodbus server standing in for the PLC: the test writes process
values into its registers, the runtime computes, the test reads the controller's output
back and checks it against the engine; then the PLC goes away and comes back."""

from __future__ import annotations

import time
from pathlib import Path

from fuzzyctl.runtime.adapters import INFO_SAFE
from tests.io.plcs import FreezableProxy, ModbusPLC, wait_until
from tests.runtime.helpers import (
    FPLTEST_FCL,
    SAFETY_KINDS,
    assert_log_complete,
    close,
    fpltest_reference,
    make_runtime,
    until_stop,
)


def config(port: int, hold: float = 0.3, timeout: float = 0.5, deadline: str = "") -> str:
    return f"""
[connections.plc]
type = "modbus"
port = {port}
timeout = {timeout}
{deadline}
poll_interval = 0.005
reconnect_min = 0.05
reconnect_max = 0.2

[instances.valve]
style = "siemens"
knowledge_base = "{FPLTEST_FCL}"
period = 0.01
hold_time = {hold}

[instances.valve.inputs]
Temp = {{ connection = "plc", address = 0 }}
Pressure = {{ connection = "plc", address = 2, word_order = "little" }}

[instances.valve.outputs]
Valve = {{ connection = "plc", address = 10, safe = -1.0 }}
INFO = {{ connection = "plc", address = 12, type = "uint16" }}
"""


def test_modbus_plc_outputs_match_the_engine_and_survive_a_plc_restart(tmp_path: Path) -> None:
    plc = ModbusPLC()
    rt = make_runtime(tmp_path, config(plc.port))
    try:
        rt.start()
        # Process values in and out of range (the block clamps to MIN/MAX, manual 1.5).
        for temp, pressure in [(9.0, 65.0), (25.0, 90.0), (3.3, 99.1), (-40.0, 170.0), (14.2, 51.7)]:
            plc.set_float(0, temp)
            plc.set_float(2, pressure, word_order="little")
            want = fpltest_reference(temp, pressure)
            wait_until(lambda w=want: close(plc.float(10), w) and plc.registers(12, 1) == [0], 10)
        assert rt.instances["valve"].snapshot()["state"] == "run"
        last = plc.float(10)

        stopped_at = time.monotonic()
        plc.stop()  # the PLC goes away mid-run
        inst = rt.instances["valve"]
        wait_until(lambda: inst.snapshot()["state"] == "hold", 10)
        snap = inst.snapshot()
        assert snap["field_outputs"]["Valve"] == last  # holding: still computed from the last good inputs
        wait_until(lambda: inst.snapshot()["state"] == "safe", 10)
        snap = inst.snapshot()
        assert snap["field_outputs"]["Valve"] == -1.0 and snap["status"]["INFO"] == INFO_SAFE

        plc.start()  # same port, fresh registers (a restarted PLC)
        plc.set_float(0, 20.0)
        plc.set_float(2, 60.0, word_order="little")
        want = fpltest_reference(20.0, 60.0)
        wait_until(lambda: close(plc.float(10), want) and plc.registers(12, 1) == [0], 15)
        wait_until(lambda: inst.snapshot()["state"] == "run", 5)
        rt.stop()  # running, with the PLC there: the stop leaves the safe value and INFO 16#41
        assert plc.float(10) == -1.0 and plc.registers(12, 1) == [INFO_SAFE]
    finally:
        rt.stop()
        plc.close()
    events = until_stop(assert_log_complete(rt, tmp_path / "events.jsonl"))
    # From the stop on: on a loaded machine the first connection may already have been
    # lost and retried at start-up (a slow first answer), which is not what this checks.
    about = [
        e
        for e in events
        if e.mono >= stopped_at and e.kind in SAFETY_KINDS and (e.instance == "valve" or e.link == "plc")
    ]
    # The stopped server answers nothing: the hold starts at the link's deadline (0.25 s)
    # or when the connection is seen lost, whichever comes first.
    tail = [e.kind for e in about]
    assert sorted(tail) == sorted(["link-lost", "hold-start", "safe-enter", "link-up", "safe-exit"]), tail
    for before, after in [
        ("hold-start", "safe-enter"),
        ("link-lost", "link-up"),
        ("safe-enter", "safe-exit"),
    ]:
        assert tail.index(before) < tail.index(after), tail
    hold_start = next(e for e in about if e.kind == "hold-start")
    safe_enter = next(e for e in about if e.kind == "safe-enter")
    assert safe_enter.mono - hold_start.mono >= 0.3 - 0.02  # not before the hold time
    assert any(e.kind == "link-retry" and e.link == "plc" for e in events)  # reconnect attempts are logged
    assert rt.events.since(0)[-1].kind == "runtime-stop"


def test_a_frozen_plc_holds_from_the_missed_deadline_not_from_the_timeout(tmp_path: Path) -> None:
    """A peer that stops answering without closing: the hold starts when the link misses
    its deadline (0.2 s), the safe values come hold_time later, long before the protocol's
    timeout (5 s) would even declare the link lost."""
    plc = ModbusPLC()
    proxy = FreezableProxy(plc.port)
    rt = make_runtime(tmp_path, config(proxy.port, hold=0.3, timeout=5.0, deadline="deadline = 0.2"))
    inst = rt.instances["valve"]
    try:
        rt.start()
        plc.set_float(0, 9.0)
        plc.set_float(2, 65.0, word_order="little")
        want = fpltest_reference(9.0, 65.0)
        wait_until(lambda: close(plc.float(10), want) and inst.snapshot()["state"] == "run", 10)
        frozen_at = time.monotonic()
        proxy.freeze()
        wait_until(lambda: inst.snapshot()["state"] == "safe", 4.5)
        snap = inst.snapshot()
        # Still within the timeout: the link is up (nothing failed yet), but late.
        assert rt.links["plc"].state.value == "up" and snap["problems"]["late"] == ["plc"]
        assert snap["field_outputs"]["Valve"] == -1.0 and snap["status"]["INFO"] == INFO_SAFE
        proxy.thaw()
        wait_until(lambda: inst.snapshot()["state"] == "run", 10)
    finally:
        rt.stop()
        proxy.close()
        plc.close()
    events = [e for e in rt.events.since(0) if e.mono >= frozen_at and e.instance == "valve"]
    kinds = [e.kind for e in events if e.kind in SAFETY_KINDS]
    assert kinds[:3] == ["hold-start", "safe-enter", "safe-exit"], kinds
    # Other events (an overrun on a loaded machine) may come between: pick the safety ones.
    hold_start = next(e for e in events if e.kind == "hold-start")
    safe_enter = next(e for e in events if e.kind == "safe-enter")
    assert hold_start.data["links"] == ["plc"]
    assert hold_start.mono - frozen_at >= 0.2 - 0.02  # not before the deadline
    assert safe_enter.mono - hold_start.mono >= 0.3 - 0.02  # then the hold time
    assert not any(e.kind == "link-lost" and e.mono >= frozen_at for e in rt.events.since(0))  # no timeout
