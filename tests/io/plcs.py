"""PLC stand-ins for the tests: real protocol servers on loopback (ephemeral ports), each
in its own thread, that a test can write process values into, read controller outputs
from, stop and restart on the same port."""

from __future__ import annotations

import asyncio
import math
import struct
import threading
import time
from collections.abc import Callable, Coroutine
from typing import Any

from fuzzyctl.io.codec import float32_from_registers, float32_to_registers


def wait_until(predicate: Callable[[], Any], timeout: float = 10.0, interval: float = 0.01) -> Any:
    """Poll until ``predicate()`` is truthy (returns it) or fail after ``timeout``."""
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"condition not met within {timeout} s")
        time.sleep(interval)


class _LoopThread:
    """An asyncio loop in a daemon thread."""

    def __init__(self) -> None:
        self.loop = asyncio.new_event_loop()
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.thread.start()

    def run(self, coro: Coroutine[Any, Any, Any], timeout: float = 20.0) -> Any:
        return asyncio.run_coroutine_threadsafe(coro, self.loop).result(timeout)

    def close(self) -> None:
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(5)


class ModbusPLC:
    """A pymodbus TCP server with 1000 holding and 1000 input registers."""

    def __init__(self) -> None:
        self._lt = _LoopThread()
        self.port = 0
        self._server: Any = None
        self.start()

    def start(self) -> None:
        from pymodbus.server import ModbusTcpServer
        from pymodbus.simulator import DataType, SimData, SimDevice

        async def go() -> int:
            regs = [SimData(0, count=1000, values=0, datatype=DataType.REGISTERS)]
            bits = [SimData(0, count=1, values=False, datatype=DataType.BITS)]
            device = SimDevice(id=0, simdata=(bits, list(bits), regs, list(regs)))
            self._server = ModbusTcpServer(device, address=("127.0.0.1", self.port))
            await self._server.serve_forever(background=True)
            return int(self._server.transport.sockets[0].getsockname()[1])

        # Building a server (asyncua: its whole standard address space) is slow on a loaded machine.
        self.port = self._lt.run(go(), timeout=60.0)

    def stop(self) -> None:
        if self._server is not None:
            self._lt.run(self._server.shutdown())
            self._server = None

    def close(self) -> None:
        self.stop()
        self._lt.close()

    def set_registers(self, address: int, regs: list[int], table: str = "holding") -> None:
        self._lt.run(self._server.async_setValues(0, 16 if table == "holding" else 4, address, regs))

    def registers(self, address: int, count: int, table: str = "holding") -> list[int]:
        return list(
            self._lt.run(self._server.async_getValues(0, 3 if table == "holding" else 4, address, count))
        )

    def set_float(self, address: int, value: float, word_order: str = "big", table: str = "holding") -> None:
        self.set_registers(address, list(float32_to_registers(value, word_order)), table)  # type: ignore[arg-type]

    def float(self, address: int, word_order: str = "big") -> float:
        r = self.registers(address, 2)
        return float32_from_registers(r[0], r[1], word_order)  # type: ignore[arg-type]


class S7PLC:
    """A python-snap7 server with one data block: DB1 of 256 bytes, or ``db``/``data`` (the
    bytearray the server serves and the test reads and writes in place)."""

    def __init__(self, db: int = 1, data: bytearray | None = None) -> None:
        self.number = db
        self.db = bytearray(256) if data is None else data
        self.port = 0
        self._server: Any = None
        self.start()

    def start(self) -> None:
        import snap7

        server = snap7.Server(log=False)
        server.register_area(snap7.SrvArea.DB, self.number, self.db)
        server.start_to("127.0.0.1", self.port)
        self.port = server.server_socket.getsockname()[1]
        self._server = server

    def stop(self) -> None:
        if self._server is not None:
            self._server.stop()
            self._server = None

    close = stop

    def set_real(self, offset: int, value: float) -> None:
        struct.pack_into(">f", self.db, offset, value)

    def real(self, offset: int) -> float:
        return float(struct.unpack_from(">f", self.db, offset)[0])

    def set_int(self, offset: int, value: int) -> None:
        struct.pack_into(">h", self.db, offset, value)

    def int(self, offset: int) -> int:
        return int(struct.unpack_from(">h", self.db, offset)[0])


class OpcUaPLC:
    """An asyncua server with Float variables ``ns=<idx>;s=Plant.<name>``."""

    NAMESPACE = "urn:test:plc"

    def __init__(self, names: list[str]) -> None:
        self._lt = _LoopThread()
        self.names = names
        self.port = 0
        self.idx = 0
        self._server: Any = None
        self.nodes: dict[str, Any] = {}
        self.start()

    def start(self) -> None:
        from asyncua import ua
        from asyncua.server.server import Server

        values = {n: (self._lt.run(self.nodes[n].read_value()) if self._server else 0.0) for n in self.names}
        self.stop()

        async def go() -> int:
            server = Server()
            await server.init()
            server.set_endpoint(f"opc.tcp://127.0.0.1:{self.port}/plc")
            self.idx = await server.register_namespace(self.NAMESPACE)
            plant = await server.nodes.objects.add_object(self.idx, "Plant")
            for n in self.names:
                node = await plant.add_variable(
                    ua.NodeId(f"Plant.{n}", self.idx),
                    n,
                    ua.Variant(float(values.get(n, 0.0)), ua.VariantType.Float),
                )
                await node.set_writable()
                self.nodes[n] = node
            await server.start()
            self._server = server
            return int(server.bserver._server.sockets[0].getsockname()[1])

        # Building a server (asyncua: its whole standard address space) is slow on a loaded machine.
        self.port = self._lt.run(go(), timeout=60.0)

    def stop(self) -> None:
        if self._server is not None:
            self._lt.run(self._server.stop())
            self._server = None

    def close(self) -> None:
        self.stop()
        self._lt.close()

    @property
    def url(self) -> str:
        return f"opc.tcp://127.0.0.1:{self.port}/plc"

    def set(self, name: str, value: float) -> None:
        from asyncua import ua

        self._lt.run(self.nodes[name].write_value(ua.Variant(float(value), ua.VariantType.Float)))

    def get(self, name: str) -> float:
        v = self._lt.run(self.nodes[name].read_value())
        return float(v) if v is not None else math.nan


class FreezableProxy:
    """A TCP proxy on loopback in front of a PLC stand-in.  ``freeze()`` stops forwarding
    in both directions while keeping every connection open: to the runtime, the peer is
    alive but answers nothing (a hung PLC, a switch that drops traffic)."""

    def __init__(self, target_port: int) -> None:
        self._lt = _LoopThread()
        self.target_port = target_port
        self._flowing: asyncio.Event | None = None
        self.port = self._lt.run(self._start())

    async def _start(self) -> int:
        self._clients: set[asyncio.Task[None]] = set()
        self._flowing = asyncio.Event()
        self._flowing.set()
        self._server = await asyncio.start_server(self._client, "127.0.0.1", 0)
        return int(self._server.sockets[0].getsockname()[1])

    async def _pump(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        assert self._flowing is not None
        try:
            while data := await reader.read(65536):
                await self._flowing.wait()
                writer.write(data)
                await writer.drain()
        except (ConnectionError, OSError):
            pass
        finally:
            writer.close()

    async def _client(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        task = asyncio.current_task()
        assert task is not None
        self._clients.add(task)
        task.add_done_callback(self._clients.discard)
        try:
            up_reader, up_writer = await asyncio.open_connection("127.0.0.1", self.target_port)
        except OSError:
            writer.close()
            return
        await asyncio.gather(self._pump(reader, up_writer), self._pump(up_reader, writer))

    def freeze(self) -> None:
        assert self._flowing is not None
        self._lt.loop.call_soon_threadsafe(self._flowing.clear)

    def thaw(self) -> None:
        assert self._flowing is not None
        self._lt.loop.call_soon_threadsafe(self._flowing.set)

    async def _close(self) -> None:
        self._server.close()
        # Connections still open (a peer that froze and was never thawed): ended here, not
        # left pending when the loop stops.
        for task in list(self._clients):
            task.cancel()
        await asyncio.gather(*self._clients, return_exceptions=True)

    def close(self) -> None:
        self.thaw()
        self._lt.run(self._close())
        self._lt.close()
