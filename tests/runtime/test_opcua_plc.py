"""OPC UA both ways: an asyncua server as the PLC (the runtime is a client), and the
runtime's own OPC UA server exposing an instance's parameters to a client."""

from __future__ import annotations

import asyncio
import math
from pathlib import Path

from tests.io.plcs import OpcUaPLC, wait_until
from tests.runtime.helpers import (
    FPLTEST_9_65,
    FPLTEST_FCL,
    assert_log_complete,
    close,
    fpltest_reference,
    make_runtime,
)


def test_opcua_plc_outputs_match_the_engine(tmp_path: Path) -> None:
    plc = OpcUaPLC(["Temp", "Pressure", "Valve"])
    ns = OpcUaPLC.NAMESPACE
    rt = make_runtime(
        tmp_path,
        f"""
[connections.plc]
type = "opcua"
url = "{plc.url}"
poll_interval = 0.01

[instances.valve]
knowledge_base = "{FPLTEST_FCL}"
period = 0.01

[instances.valve.inputs]
Temp = {{ connection = "plc", node = "s=Plant.Temp", namespace = "{ns}" }}
Pressure = {{ connection = "plc", node = "ns={plc.idx};s=Plant.Pressure" }}

[instances.valve.outputs]
Valve = {{ connection = "plc", node = "s=Plant.Valve", namespace = "{ns}", safe = 0.0 }}
""",
    )
    try:
        rt.start()
        for temp, pressure in [(9.0, 65.0), (18.0, 80.0), (2.0, 96.5)]:
            plc.set("Temp", temp)
            plc.set("Pressure", pressure)
            want = fpltest_reference(temp, pressure)
            wait_until(lambda w=want: close(plc.get("Valve"), w), 15)
    finally:
        rt.stop()
        plc.close()
    assert_log_complete(rt, tmp_path / "events.jsonl")


def test_runtime_opcua_server_exposes_inputs_outputs_info_and_start_stop(tmp_path: Path) -> None:
    from asyncua import ua
    from asyncua.client.client import Client

    rt = make_runtime(
        tmp_path,
        f"""
[connections.ua]
type = "opcua-server"
url = "opc.tcp://127.0.0.1:0/fuzzyctl"
namespace = "urn:test:runtime"
poll_interval = 0.01

[instances.valve]
knowledge_base = "{FPLTEST_FCL}"
period = 0.01
expose = ["ua"]
""",
    )

    async def client_session(url: str) -> dict[str, float]:
        client = Client(url, timeout=3)
        await client.connect()
        try:
            idx = await client.get_namespace_index("urn:test:runtime")

            def node(name: str):  # type: ignore[no-untyped-def]
                return client.get_node(f"ns={idx};s=valve.{name}")

            await node("Temp").write_value(ua.Variant(9.0, ua.VariantType.Float))
            await node("Pressure").write_value(ua.Variant(65.0, ua.VariantType.Float))
            seen: dict[str, float] = {}
            # polled for up to 30 s: a cycle and two OPC UA round trips each time (6 s of 300
            # polls ran out once with two whole test suites sharing the 2 cores)
            loop = asyncio.get_running_loop()
            until = loop.time() + 30
            while loop.time() < until:
                seen["Valve"] = await node("Valve").read_value()
                seen["INFO"] = await node("INFO").read_value()
                if close(seen["Valve"], FPLTEST_9_65) and seen["INFO"] == 0:
                    break
                await asyncio.sleep(0.02)
            # START_STOP written by the client is applied to the block (a parameter node)
            await node("START_STOP").write_value(ua.Variant(0, ua.VariantType.UInt16))
            for _ in range(300):
                seen["INFO_stopped"] = await node("INFO").read_value()
                if seen["INFO_stopped"] == 1:
                    break
                await asyncio.sleep(0.02)
            return seen
        finally:
            await client.disconnect()

    try:
        rt.start()
        wait_until(lambda: rt.links["ua"].up, 20)
        url = rt.links["ua"].connector.endpoint()
        seen = asyncio.run(client_session(url))
        assert close(seen["Valve"], fpltest_reference(9.0, 65.0)) and seen["INFO"] == 0
        assert seen["INFO_stopped"] == 1  # INFO 01: START_STOP = 0, nothing recalculated
        assert rt.instances["valve"].adapter.get_param("START_STOP") == 0
    finally:
        rt.stop()
    events = assert_log_complete(rt, tmp_path / "events.jsonl")
    assert any(e.kind == "parameter" and e.data.get("source") == "field:ua" for e in events)
    assert not math.isnan(rt.instances["valve"].snapshot()["inputs"]["Temp"])
