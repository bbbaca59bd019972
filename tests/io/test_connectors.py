"""Each connector against a real server of its protocol on loopback."""

from __future__ import annotations

import asyncio
import math

import pytest

from fuzzyctl.io import LinkError, create_connector
from fuzzyctl.io.modbus import ModbusPoint
from fuzzyctl.io.opcua import OpcUaPoint, OpcUaServerPoint
from fuzzyctl.io.s7 import S7Point
from tests.io.plcs import S7PLC, ModbusPLC, OpcUaPLC


def run(coro):  # type: ignore[no-untyped-def]
    return asyncio.run(coro)


def test_modbus_client_reads_and_writes_float32_in_both_word_orders_and_scaled_int16() -> None:
    plc = ModbusPLC()
    try:
        plc.set_float(0, 21.5)
        plc.set_float(2, -7.25, word_order="little")
        plc.set_registers(4, [0xFF38])  # -200 as INT16
        plc.set_float(10, 3.0, table="input")

        async def go() -> list[float]:
            c = create_connector("modbus", "plc", {"port": plc.port, "timeout": 1})
            await c.connect()
            pts = [
                ModbusPoint(address=0),
                ModbusPoint(address=2, word_order="little"),
                ModbusPoint(address=4, type="int16", scale=0.1, offset=1.0),
                ModbusPoint(table="input", address=10),
            ]
            values = await c.read(pts)
            await c.write(
                [ModbusPoint(address=20), ModbusPoint(address=22, type="int16", scale=0.5)], [99.5, -3.0]
            )
            await c.close()
            return values

        assert run(go()) == [21.5, -7.25, pytest.approx(-19.0), 3.0]
        assert plc.float(20) == 99.5 and plc.registers(22, 1) == [0xFFFA]  # -3 / 0.5 = -6
    finally:
        plc.close()


def test_modbus_client_raises_link_error_when_the_server_goes_away() -> None:
    plc = ModbusPLC()

    async def go() -> None:
        c = create_connector("modbus", "plc", {"port": plc.port, "timeout": 0.5})
        await c.connect()
        assert await c.read([ModbusPoint(address=0)]) == [0.0]
        await asyncio.to_thread(plc.stop)
        with pytest.raises(LinkError):
            for _ in range(5):  # the first request may still be answered by a closing socket
                await c.read([ModbusPoint(address=0)])
        await c.close()
        with pytest.raises(LinkError, match=r"refused|timed out|Connect"):
            await c.connect()

    try:
        run(go())
    finally:
        plc.close()


def test_s7_client_reads_and_writes_reals_and_ints_in_a_data_block() -> None:
    plc = S7PLC()
    try:
        plc.set_real(0, 12.5)
        plc.set_real(8, -0.125)
        plc.set_int(20, -1234)

        async def go() -> list[float]:
            c = create_connector("s7", "plc", {"port": plc.port, "slot": 1})
            await c.connect()
            values = await c.read(
                [S7Point(db=1, offset=0), S7Point(db=1, offset=8), S7Point(db=1, offset=20, type="int")]
            )
            await c.write([S7Point(db=1, offset=40), S7Point(db=1, offset=44, type="int")], [6.75, 301.6])
            await c.close()
            return values

        assert run(go()) == [12.5, -0.125, -1234.0]
        assert plc.real(40) == 6.75 and plc.int(44) == 302
    finally:
        plc.close()


def test_opcua_client_reads_and_writes_float_nodes_by_namespace_uri_or_index() -> None:
    plc = OpcUaPLC(["Temp", "Valve"])
    try:
        plc.set("Temp", 17.25)

        async def go() -> list[float]:
            c = create_connector("opcua", "plc", {"url": plc.url, "timeout": 2})
            await c.connect()
            by_uri = OpcUaPoint(node="s=Plant.Temp", namespace=OpcUaPLC.NAMESPACE)
            by_index = OpcUaPoint(node=f"ns={plc.idx};s=Plant.Temp")
            values = await c.read([by_uri, by_index])
            await c.write([OpcUaPoint(node="s=Plant.Valve", namespace=OpcUaPLC.NAMESPACE)], [-42.5])
            await c.close()
            return values

        assert run(go()) == [17.25, 17.25]
        assert plc.get("Valve") == -42.5
    finally:
        plc.close()


def test_opcua_server_exposes_nodes_that_a_client_writes_and_reads() -> None:
    from asyncua import ua
    from asyncua.client.client import Client

    async def go() -> tuple[list[float], float, bool]:
        srv = create_connector(
            "opcua-server", "ua", {"url": "opc.tcp://127.0.0.1:0/fz", "namespace": "urn:t"}
        )
        await srv.connect()
        inp = OpcUaServerPoint(node="tank.Level", writable=True)
        out = OpcUaServerPoint(node="tank.Valve")
        await srv.ensure([inp, out])  # type: ignore[attr-defined]
        await srv.write([out], [12.5])
        before = await srv.read([inp])
        client = Client(srv.endpoint(), timeout=2)
        await client.connect()
        idx = await client.get_namespace_index("urn:t")
        await client.get_node(f"ns={idx};s=tank.Level").write_value(ua.Variant(3.5, ua.VariantType.Float))
        seen = await client.get_node(f"ns={idx};s=tank.Valve").read_value()
        refused = False
        try:
            await client.get_node(f"ns={idx};s=tank.Valve").write_value(ua.Variant(1.0, ua.VariantType.Float))
        except ua.UaStatusCodeError:
            refused = True  # outputs are read-only for clients
        after = await srv.read([inp])
        await client.disconnect()
        await srv.close()
        return [before[0], after[0]], seen, refused

    values, seen, refused = run(go())
    assert math.isnan(values[0]) and values[1] == 3.5  # NaN until a client writes
    assert seen == 12.5 and refused
