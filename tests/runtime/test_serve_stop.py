"""Stopping safely (docs/runtime.md, "Stopping"): `fuzzyctl serve` as a real process
against real protocol peers on loopback (a pymodbus server, an asyncua server).  It runs
until the peers hold the block's normal values, then gets SIGTERM or Ctrl-C (SIGINT): the
peers must then hold the configured safe values with INFO 16#41 (the safe INFO of the
docs' Safety table), and the process must have exited 0 within its stop bound.  A peer
that does not answer at stop time must not keep the process from exiting (its link's
`stop_timeout`, not the protocol's `timeout`), and a second Ctrl-C exits at once."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest

from tests.conftest import EXAMPLES, ROOT
from tests.io.plcs import S7PLC, FreezableProxy, ModbusPLC, OpcUaPLC, wait_until
from tests.runtime.helpers import FPLTEST_FCL, close, fpltest_reference, make_runtime

INFO_SAFE = 0x41  # docs/runtime.md, Safety: INFO in the state `safe` (written literally: the docs' number)
SAFE_VALVE = -1.0
SAFE_VALVE_UA = 7.5
SAFE_VALVE_S7 = 55.5
# What the stop may cost beyond the links' stop_timeout: the cycle thread's last cycle, the
# event file, the interpreter's exit, on a shared, loaded machine.  Far below the protocol
# timeouts used below (10 s), so an exit within it shows the stop_timeout was what bounded it.
SLACK = 4.0


def modbus_connection(name: str, port: int, stop_timeout: float | None = None, timeout: float = 10.0) -> str:
    extra = "" if stop_timeout is None else f"stop_timeout = {stop_timeout}\n"
    return f"""
[connections.{name}]
type = "modbus"
port = {port}
timeout = {timeout}
poll_interval = 0.01
reconnect_min = 0.05
reconnect_max = 0.2
{extra}"""


def modbus_instance(name: str, connection: str) -> str:
    return f"""
[instances.{name}]
knowledge_base = "{FPLTEST_FCL}"
period = 0.01
hold_time = 0.3

[instances.{name}.inputs]
Temp = {{ connection = "{connection}", address = 0 }}
Pressure = {{ connection = "{connection}", address = 2 }}

[instances.{name}.outputs]
Valve = {{ connection = "{connection}", address = 10, safe = {SAFE_VALVE} }}
INFO = {{ connection = "{connection}", address = 12, type = "uint16" }}
"""


def opcua_part(plc: OpcUaPLC) -> str:
    ns = OpcUaPLC.NAMESPACE
    return f"""
[connections.ua]
type = "opcua"
url = "{plc.url}"
timeout = 10.0
poll_interval = 0.01
reconnect_min = 0.05
reconnect_max = 0.2

[instances.ua_valve]
knowledge_base = "{FPLTEST_FCL}"
period = 0.01
hold_time = 0.3

[instances.ua_valve.inputs]
Temp = {{ connection = "ua", node = "s=Plant.Temp", namespace = "{ns}" }}
Pressure = {{ connection = "ua", node = "s=Plant.Pressure", namespace = "{ns}" }}

[instances.ua_valve.outputs]
Valve = {{ connection = "ua", node = "s=Plant.Valve", namespace = "{ns}", safe = {SAFE_VALVE_UA} }}
INFO = {{ connection = "ua", node = "s=Plant.INFO", namespace = "{ns}" }}
"""


def s7_part(name: str, port: int, stop_timeout: float | None = None) -> str:
    extra = "" if stop_timeout is None else f"stop_timeout = {stop_timeout}\n"
    return f"""
[connections.{name}]
type = "s7"
port = {port}
timeout = 10.0
poll_interval = 0.01
reconnect_min = 0.05
reconnect_max = 0.2
{extra}
[instances.{name}_valve]
knowledge_base = "{FPLTEST_FCL}"
period = 0.01
hold_time = 0.3

[instances.{name}_valve.inputs]
Temp = {{ connection = "{name}", db = 1, offset = 0 }}
Pressure = {{ connection = "{name}", db = 1, offset = 4 }}

[instances.{name}_valve.outputs]
Valve = {{ connection = "{name}", db = 1, offset = 8, safe = {SAFE_VALVE_S7} }}
INFO = {{ connection = "{name}", db = 1, offset = 12, type = "int" }}
"""


def s7_running(plc: S7PLC, temp: float = 2.0, pressure: float = 96.5) -> float:
    plc.set_real(0, temp)
    plc.set_real(4, pressure)
    return fpltest_reference(temp, pressure)


class Serve:
    """`fuzzyctl serve CONFIG --no-api --no-table` in a process of its own (this worktree's
    sources first on the path); its output goes to files, so a full pipe never blocks it."""

    def __init__(self, tmp_path: Path, toml: str) -> None:
        self.dir = tmp_path
        config = tmp_path / "serve.toml"
        config.write_text(f'[runtime]\nstate_dir = "{tmp_path}"\n' + toml, encoding="utf-8")
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), str(ROOT), env.get("PYTHONPATH", "")])
        self.out = (tmp_path / "stdout.txt").open("w")
        self.err = (tmp_path / "stderr.txt").open("w")
        code = "from fuzzyctl.cli.entry import run; run()"
        self.proc = subprocess.Popen(
            [sys.executable, "-c", code, "serve", str(config), "--no-api", "--no-table"],
            stdout=self.out,
            stderr=self.err,
            env=env,
            cwd=tmp_path,
        )

    def stop(self, signum: int, timeout: float = 60.0) -> tuple[int, float]:
        """Send ``signum``; the exit code and the seconds until the process was gone."""
        t0 = time.monotonic()
        self.proc.send_signal(signum)
        rc = self.proc.wait(timeout)
        return rc, time.monotonic() - t0

    def stderr(self) -> str:
        return (self.dir / "stderr.txt").read_text(encoding="utf-8")

    def events(self) -> list[dict[str, Any]]:
        path = self.dir / "events.jsonl"
        return [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()]

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(10)
        self.out.close()
        self.err.close()


def running(plc: ModbusPLC, want: float) -> bool:
    """The PLC holds the block's value and INFO 0 (normal operation)."""
    return close(plc.float(10), want) and plc.registers(12, 1) == [0]


def running_values(plc: ModbusPLC, temp: float = 9.0, pressure: float = 65.0) -> float:
    """Put process values in a PLC's registers; the block's answer (the engine's)."""
    plc.set_float(0, temp)
    plc.set_float(2, pressure)
    return fpltest_reference(temp, pressure)


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_a_stopped_serve_leaves_the_safe_values_and_the_safe_info_in_its_peers(
    tmp_path: Path, signum: int
) -> None:
    plc = ModbusPLC()
    ua = OpcUaPLC(["Temp", "Pressure", "Valve", "INFO"])
    cpu = S7PLC()
    serve = None
    try:
        want = running_values(plc)
        ua.set("Temp", 18.0)
        ua.set("Pressure", 80.0)
        want_ua = fpltest_reference(18.0, 80.0)
        want_s7 = s7_running(cpu)
        serve = Serve(
            tmp_path,
            modbus_connection("plc", plc.port)
            + modbus_instance("valve", "plc")
            + opcua_part(ua)
            + s7_part("cpu", cpu.port),
        )
        # Normal operation first: every peer holds the block's values and INFO 0.
        wait_until(lambda: running(plc, want), 60)
        wait_until(lambda: close(ua.get("Valve"), want_ua) and ua.get("INFO") == 0.0, 60)
        wait_until(lambda: close(cpu.real(8), want_s7) and cpu.int(12) == 0, 60)
        assert serve.proc.poll() is None
        rc, took = serve.stop(signum)
        assert rc == 0, serve.stderr()
        # Default stop_timeout 1 s per link, links in parallel.
        assert took < 1.0 + SLACK, took
        assert plc.float(10) == SAFE_VALVE
        assert plc.registers(12, 1) == [INFO_SAFE]
        assert ua.get("Valve") == SAFE_VALVE_UA
        assert ua.get("INFO") == float(INFO_SAFE)
        assert cpu.real(8) == SAFE_VALVE_S7 and cpu.int(12) == INFO_SAFE
        events = serve.events()
        # What was written is logged, per link, before the runtime-stop event.
        writes = {e["link"]: e for e in events if e["kind"] == "stop-write"}
        assert set(writes) == {"plc", "ua", "cpu"}, [e["kind"] for e in events]
        assert all(e["data"]["written"] for e in writes.values())
        assert any(
            e["kind"] == "safe-enter" and e["instance"] == "valve" and e["data"]["reason"] == "stop"
            for e in events
        )
        assert events[-1]["kind"] == "runtime-stop"
    finally:
        if serve is not None:
            serve.close()
        plc.close()
        ua.close()
        cpu.close()


def test_a_peer_that_does_not_answer_at_stop_delays_the_exit_only_by_its_stop_timeout(
    tmp_path: Path,
) -> None:
    """Three Modbus peers: one frozen just before the stop (connection open, nothing
    answers: the write hangs until the protocol's 10 s timeout), one stopped (refused),
    one healthy; and a frozen S7 CPU (python-snap7 blocks a thread until its socket
    timeout).  The process is gone within the 0.5 s stop_timeout (plus the slack), far
    before 10 s, and the healthy peer still got its safe values (the links are written in
    parallel, not one after the other)."""
    frozen, gone, healthy = ModbusPLC(), ModbusPLC(), ModbusPLC()
    proxy = FreezableProxy(frozen.port)
    cpu = S7PLC()
    cpu_proxy = FreezableProxy(cpu.port)
    serve = None
    try:
        want = {name: running_values(plc) for name, plc in [("a", frozen), ("b", gone), ("c", healthy)]}
        want_s7 = s7_running(cpu)
        toml = (
            modbus_connection("a", proxy.port, stop_timeout=0.5)
            + modbus_connection("b", gone.port, stop_timeout=0.5)
            + modbus_connection("c", healthy.port, stop_timeout=0.5)
            + modbus_instance("va", "a")
            + modbus_instance("vb", "b")
            + modbus_instance("vc", "c")
            + s7_part("cpu", cpu_proxy.port, stop_timeout=0.5)
        )
        serve = Serve(tmp_path, toml)
        for name, plc in [("a", frozen), ("b", gone), ("c", healthy)]:
            wait_until(lambda p=plc, w=want[name]: running(p, w), 60)  # type: ignore[misc]
        wait_until(lambda: close(cpu.real(8), want_s7) and cpu.int(12) == 0, 60)
        gone.stop()
        proxy.freeze()
        cpu_proxy.freeze()
        rc, took = serve.stop(signal.SIGTERM)
        assert rc == 0, serve.stderr()
        assert took < 0.5 + SLACK, took  # not the 10 s protocol timeout
        assert healthy.float(10) == SAFE_VALVE and healthy.registers(12, 1) == [INFO_SAFE]
        assert close(frozen.float(10), want["a"])  # nothing reached it: the last value stays
        writes = {e["link"]: e for e in serve.events() if e["kind"] == "stop-write"}
        assert writes["c"]["data"]["written"] and writes["c"]["level"] == "info"
        assert close(cpu.real(8), want_s7) and cpu.int(12) == 0
        for name in ("a", "b", "cpu"):
            assert not writes[name]["data"]["written"] and writes[name]["level"] == "error", writes[name]
    finally:
        if serve is not None:
            serve.close()
        proxy.close()
        cpu_proxy.close()
        cpu.close()
        for plc in (frozen, gone, healthy):
            plc.close()


def test_a_second_ctrl_c_exits_at_once(tmp_path: Path) -> None:
    """A stop that waits for a frozen peer (stop_timeout 20 s): the first Ctrl-C starts
    it, the second ends the process at once (exit 130, as an interrupted command)."""
    plc = ModbusPLC()
    proxy = FreezableProxy(plc.port)
    serve = None
    try:
        want = running_values(plc)
        serve = Serve(
            tmp_path,
            modbus_connection("plc", proxy.port, stop_timeout=20.0, timeout=30.0)
            + modbus_instance("valve", "plc"),
        )
        wait_until(lambda: close(plc.float(10), want), 60)
        proxy.freeze()
        serve.proc.send_signal(signal.SIGINT)
        wait_until(lambda: "again" in serve.stderr(), 15)  # the stop has begun and says so
        assert serve.proc.poll() is None  # still waiting for the frozen peer
        rc, took = serve.stop(signal.SIGINT)
        assert rc == 130
        assert took < SLACK, took
    finally:
        if serve is not None:
            serve.close()
        proxy.close()
        plc.close()


# ---------------------------------------------------------------------------- in process
# The same stop through Runtime.stop() (what `serve` calls), for what a process test
# would only make slower: the XFUZ status word, stop_timeout = 0, a link down at the stop.


def xfuz_config(port: int, extra: str = "") -> str:
    return f"""
[connections.plc]
type = "modbus"
port = {port}
poll_interval = 0.005
reconnect_min = 0.05
reconnect_max = 0.1
{extra}
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
OUT3 = {{ connection = "plc", address = 10, type = "int16", safe = -7 }}
STATUS = {{ connection = "plc", address = 11, type = "int16" }}
ERROR = {{ connection = "plc", address = 12, type = "uint16" }}
"""


def test_a_stopped_xfuz_instance_leaves_its_safe_word_status_bit_15_and_error(tmp_path: Path) -> None:
    """docs/runtime.md, Safety: XFUZ in `safe` sets STATUS bit 15 (the runtime's
    addition) and ERROR = 1.  The manual's example 3.3 (Pression 0, Temperature -50)
    gives Ouverture 8 with STATUS 0 while running."""
    plc = ModbusPLC()
    rt = make_runtime(tmp_path, xfuz_config(plc.port))
    try:
        rt.start()
        plc.set_registers(0, [0, (-50) & 0xFFFF])
        wait_until(lambda: plc.registers(10, 3) == [8, 0, 0], 10)
        rt.stop()
        assert plc.registers(10, 3) == [(-7) & 0xFFFF, 0x8000, 1]
    finally:
        rt.stop()
        plc.close()


def test_stop_timeout_0_leaves_the_field_as_it_was(tmp_path: Path) -> None:
    plc = ModbusPLC()
    rt = make_runtime(tmp_path, xfuz_config(plc.port, "stop_timeout = 0"))
    try:
        rt.start()
        plc.set_registers(0, [0, (-50) & 0xFFFF])
        wait_until(lambda: plc.registers(10, 3) == [8, 0, 0], 10)
        rt.stop()
        assert plc.registers(10, 3) == [8, 0, 0]
        (write,) = [e for e in rt.events.since(0) if e.kind == "stop-write"]
        assert write.level == "warning" and write.data["written"] == {}
    finally:
        rt.stop()
        plc.close()


def test_a_link_that_is_down_at_the_stop_connects_once_to_write_the_safe_values(tmp_path: Path) -> None:
    """The PLC restarts while the link waits 30 s before its next attempt: at the stop the
    link is down, connects once, and the restarted PLC (fresh registers) gets the safe
    values and INFO 16#41."""
    plc = ModbusPLC()
    toml = modbus_connection("plc", plc.port, timeout=0.5).replace(
        "reconnect_min = 0.05\nreconnect_max = 0.2", "reconnect_min = 30\nreconnect_max = 30"
    ) + modbus_instance("valve", "plc")
    rt = make_runtime(tmp_path, toml)
    try:
        rt.start()
        want = running_values(plc)
        wait_until(lambda: running(plc, want), 30)
        plc.stop()
        # Down, and waiting out its 30 s back-off (not in the middle of an attempt).
        wait_until(lambda: any(e.kind == "link-retry" for e in rt.events.since(0)), 15)
        assert rt.links["plc"].state.value == "down"
        plc.start()  # same port, registers 0
        assert plc.registers(10, 3) == [0, 0, 0]
        rt.stop()
        assert plc.float(10) == SAFE_VALVE and plc.registers(12, 1) == [INFO_SAFE]
    finally:
        rt.stop()
        plc.close()


def test_an_instance_whose_block_cannot_compute_stops_with_info_42(tmp_path: Path) -> None:
    """Already `safe` by a block error (an inlet singleton of 1E39 makes OUTPUT1 +inf at
    cold and low): the stop keeps the block-fault code 16#42, no second safe-enter."""
    kb = tmp_path / "huge.fcl"
    kb.write_text(FPLTEST_FCL.read_text().replace("TERM inlet := 100;", "TERM inlet := 1E39;"))
    plc = ModbusPLC()
    toml = modbus_connection("plc", plc.port, timeout=0.5) + modbus_instance("valve", "plc").replace(
        str(FPLTEST_FCL), str(kb)
    )
    rt = make_runtime(tmp_path, toml)
    try:
        rt.start()
        plc.set_float(0, 1.0)  # cold
        plc.set_float(2, 55.0)  # low
        wait_until(lambda: plc.float(10) == SAFE_VALVE and plc.registers(12, 1) == [0x42], 10)
        plc.set_registers(10, [0, 0, 0])  # so that the stop has to write them again
        rt.stop()
        assert plc.float(10) == SAFE_VALVE and plc.registers(12, 1) == [0x42]
        reasons = [e.data["reason"] for e in rt.events.since(0) if e.kind == "safe-enter"]
        assert "stop" not in reasons, reasons
    finally:
        rt.stop()
        plc.close()


def test_a_link_down_at_the_stop_whose_peer_then_hangs_gives_up_at_its_stop_timeout(tmp_path: Path) -> None:
    """The PLC is not there at the start (the link waits out a 30 s back-off), then is,
    behind a proxy that accepts the connection and answers nothing: the stop's connection
    attempt and write are cut at stop_timeout (0.3 s), not at the protocol's timeout
    (3 s: the write would wait 3.5 s), and the log says so.  (The proxy makes the first
    attempt fail only at that timeout, hence not 10 s here.)"""
    plc = ModbusPLC()
    plc.stop()
    proxy = FreezableProxy(plc.port)
    toml = modbus_connection("plc", proxy.port, stop_timeout=0.3, timeout=3.0).replace(
        "reconnect_min = 0.05\nreconnect_max = 0.2", "reconnect_min = 30\nreconnect_max = 30"
    ) + modbus_instance("valve", "plc")
    rt = make_runtime(tmp_path, toml)
    try:
        rt.start()
        wait_until(lambda: any(e.kind == "link-retry" for e in rt.events.since(0)), 15)
        plc.start()
        proxy.freeze()
        t0 = time.monotonic()
        rt.stop()
        took = time.monotonic() - t0
        assert took < 2.0, took  # in process: no interpreter to start or end
        assert plc.registers(10, 3) == [0, 0, 0]  # nothing arrived
        (write,) = [e for e in rt.events.since(0) if e.kind == "stop-write"]
        assert write.level == "error", write.message
        assert "connect and write: no answer within 0.3 s" in write.message, write.message
    finally:
        rt.stop()
        proxy.close()
        plc.close()
