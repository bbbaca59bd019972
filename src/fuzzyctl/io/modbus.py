"""Modbus TCP: a client (the runtime polls a PLC or I/O device) and a server (a master
writes the controller's inputs into our registers and reads its outputs).

Points are holding or input registers holding a FLOAT32 (two registers, configurable word
order) or a 16-bit integer scaled to engineering units (``raw * scale + offset``).  The
client groups the points of a batch into as few requests as it can (contiguous spans of at
most 125 registers, gaps of up to ``max_gap`` registers read through).

pymodbus is pinned to one minor version in pyproject.toml: its server datastore API
changes between minor versions (3.16 moved to ``SimData``/``SimDevice``).
"""

from __future__ import annotations

import contextlib
import functools
import logging
import math
from collections.abc import Awaitable, Callable, Sequence
from dataclasses import dataclass
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from fuzzyctl.io.base import Connector, LinkError, Point, bounded
from fuzzyctl.io.codec import (
    WordOrder,
    float32_from_registers,
    float32_to_registers,
    int16_from_register,
    int16_to_register,
    scaled_from_raw,
    scaled_to_raw,
)

__all__ = ["ModbusClient", "ModbusClientOptions", "ModbusPoint", "ModbusServer", "ModbusServerOptions"]

MAX_READ = 125  # registers per read request (Modbus application protocol, 6.3)
MAX_WRITE = 123  # registers per write-multiple request (6.12)

# pymodbus logs every failed request at ERROR; the runtime reports link state itself.
logging.getLogger("pymodbus").setLevel(logging.CRITICAL)


class ModbusPoint(Point):
    """One value in registers: ``{table = "holding", address = 0, type = "float32"}``."""

    table: Literal["holding", "input"] = "holding"
    address: int = Field(ge=0, le=65535, description="register address, 0-based (protocol address)")
    type: Literal["float32", "int16", "uint16"] = "float32"
    word_order: WordOrder = "big"
    scale: float = 1.0
    offset: float = 0.0

    @model_validator(mode="after")
    def _check(self) -> ModbusPoint:
        if self.address + self.width > 65536:
            raise ValueError(f"a {self.type} at register {self.address} runs past register 65535")
        if self.scale == 0 or not math.isfinite(self.scale) or not math.isfinite(self.offset):
            raise ValueError("scale must be a finite non-zero number and offset finite")
        return self

    @property
    def width(self) -> int:
        return 2 if self.type == "float32" else 1

    def describe(self) -> str:
        end = f"..{self.address + 1}" if self.width == 2 else ""
        return f"{self.table} {self.address}{end} {self.type}"

    def decode(self, registers: Sequence[int]) -> float:
        if self.type == "float32":
            return float32_from_registers(registers[0], registers[1], self.word_order)
        raw = int16_from_register(registers[0], signed=self.type == "int16")
        return scaled_from_raw(raw, self.scale, self.offset)

    def encode(self, value: float) -> list[int]:
        if self.type == "float32":
            return list(float32_to_registers(value, self.word_order))
        return [int16_to_register(scaled_to_raw(value, self.scale, self.offset, signed=self.type == "int16"))]


@dataclass(frozen=True)
class Span:
    """One read request: ``count`` registers of ``table`` from ``start``."""

    table: str
    start: int
    count: int


def plan_reads(points: Sequence[ModbusPoint], max_gap: int = 8) -> list[tuple[Span, list[int]]]:
    """Group points into read spans; returns each span with the indices of its points."""
    order = sorted(range(len(points)), key=lambda i: (points[i].table, points[i].address))
    plan: list[tuple[Span, list[int]]] = []
    for i in order:
        p = points[i]
        if plan:
            span, members = plan[-1]
            end = p.address + p.width
            if (
                span.table == p.table
                and p.address <= span.start + span.count + max_gap
                and max(end, span.start + span.count) - span.start <= MAX_READ
            ):
                plan[-1] = (
                    Span(span.table, span.start, max(end, span.start + span.count) - span.start),
                    members,
                )
                members.append(i)
                continue
        plan.append((Span(p.table, p.address, p.width), [i]))
    return plan


def decode_span(
    out: list[float], points: Sequence[ModbusPoint], members: Sequence[int], span: Span, regs: Sequence[int]
) -> None:
    """Decodes the points ``members`` (indices into ``points`` and ``out``) from the
    registers ``regs`` that one read of ``span`` returned."""
    for i in members:
        p = points[i]
        offset = p.address - span.start
        out[i] = p.decode(regs[offset : offset + p.width])


def plan_writes(points: Sequence[ModbusPoint], values: Sequence[float]) -> list[tuple[str, int, list[int]]]:
    """Registers to write, merged into contiguous runs per table: (table, start, registers)."""
    cells: dict[tuple[str, int], int] = {}
    for p, v in zip(points, values, strict=True):
        for k, reg in enumerate(p.encode(v)):
            cells[(p.table, p.address + k)] = reg
    runs: list[tuple[str, int, list[int]]] = []
    for (table, addr), reg in sorted(cells.items()):
        if (
            runs
            and runs[-1][0] == table
            and runs[-1][1] + len(runs[-1][2]) == addr
            and len(runs[-1][2]) < MAX_WRITE
        ):
            runs[-1][2].append(reg)
        else:
            runs.append((table, addr, [reg]))
    return runs


class ModbusClientOptions(BaseModel):
    model_config = ConfigDict(extra="forbid")

    host: str = "127.0.0.1"
    port: int = Field(default=502, ge=1, le=65535)
    unit: int = Field(default=1, ge=0, le=255, description="unit identifier (device id)")
    timeout: float = Field(default=1.0, gt=0, le=60)
    max_gap: int = Field(
        default=8, ge=0, le=100, description="unused registers read through to merge requests"
    )


class ModbusClient(Connector):
    """A Modbus TCP client (function codes 3, 4 and 16)."""

    point_model = ModbusPoint
    options_model = ModbusClientOptions
    options: ModbusClientOptions

    def __init__(self, name: str, options: ModbusClientOptions) -> None:
        super().__init__(name, options)
        self._client: Any = None

    def endpoint(self) -> str:
        return f"modbus://{self.options.host}:{self.options.port}/{self.options.unit}"

    async def connect(self) -> None:
        from pymodbus.client import AsyncModbusTcpClient

        await self.close()
        o = self.options
        client = AsyncModbusTcpClient(o.host, port=o.port, timeout=o.timeout, retries=0, reconnect_delay=0)
        try:
            ok = await bounded(client.connect(), o.timeout + 1, "connect")
        except (LinkError, OSError) as exc:
            client.close()
            raise LinkError(f"{self.endpoint()}: {exc or 'timed out'}") from exc
        if not ok:
            client.close()
            raise LinkError(f"{self.endpoint()}: connection refused or timed out")
        self._client = client

    async def _call(self, what: str, request: Callable[[], Awaitable[Any]]) -> Any:
        from pymodbus.exceptions import ModbusException

        try:
            # pymodbus raises ConnectionException as soon as the request is made on a closed
            # transport, so the request is made inside the try.
            response = await bounded(request(), self.options.timeout + 0.5, "no answer")
        except (LinkError, ModbusException, OSError) as exc:
            raise LinkError(f"{self.endpoint()}: {what}: {exc or 'timed out'}") from exc
        if response.isError():
            raise LinkError(f"{self.endpoint()}: {what}: the device answered {response}")
        return response

    async def read(self, points: Sequence[Point]) -> list[float]:
        client = self.live(self._client)
        pts: list[ModbusPoint] = list(points)  # type: ignore[arg-type]
        out = [math.nan] * len(pts)
        unit = self.options.unit
        for span, members in plan_reads(pts, self.options.max_gap):
            call = client.read_holding_registers if span.table == "holding" else client.read_input_registers
            resp = await self._call(
                f"read {span.table} {span.start}+{span.count}",
                functools.partial(call, span.start, count=span.count, device_id=unit),
            )
            regs = resp.registers
            if len(regs) < span.count:
                raise LinkError(f"{self.endpoint()}: short answer to a read of {span.count} registers")
            decode_span(out, pts, members, span, regs)
        return out

    async def write(self, points: Sequence[Point], values: Sequence[float]) -> None:
        client = self.live(self._client)
        for table, start, regs in plan_writes(list(points), values):  # type: ignore[arg-type]
            if table != "holding":
                raise LinkError(f"{self.endpoint()}: input registers are read-only for a client")
            await self._call(
                f"write holding {start}+{len(regs)}",
                functools.partial(client.write_registers, start, regs, device_id=self.options.unit),
            )

    async def close(self) -> None:
        client, self._client = self._client, None
        if client is not None:
            with contextlib.suppress(Exception):  # closing a broken transport must never fail the caller
                client.close()


class ModbusServerOptions(BaseModel):
    model_config = ConfigDict(extra="forbid")

    host: str = "127.0.0.1"
    port: int = Field(default=502, ge=0, le=65535, description="0 picks a free port")
    registers: int = Field(default=10000, ge=1, le=65535, description="size of each register table")


class ModbusServer(Connector):
    """A Modbus TCP server holding a holding-register and an input-register table
    (``registers`` each, every unit id).  Inputs of the controller are registers a master
    writes; outputs are registers the runtime writes and a master reads.

    The process image is exchanged with the server's own register lists directly, one
    slice per point (the datastore calls cost ~20 us each and checked every register in
    Python: 300 points took 4 ms of the interpreter every poll, time the cycle thread
    waited for).  Slices are atomic on the event loop, which also serves the master.
    Should a pymodbus release store its registers differently, the datastore calls are
    used instead (``direct`` is then False)."""

    point_model = ModbusPoint
    options_model = ModbusServerOptions
    options: ModbusServerOptions
    server = True

    def __init__(self, name: str, options: ModbusServerOptions) -> None:
        super().__init__(name, options)
        self._server: Any = None
        self.port = options.port
        self._tables: dict[str, list[int]] | None = None
        self._plans: dict[tuple[int, ...], list[tuple[list[int], int, ModbusPoint]]] = {}

    @property
    def direct(self) -> bool:
        """Whether the registers are exchanged directly (see the class doc)."""
        return self._tables is not None

    def endpoint(self) -> str:
        return f"modbus-server://{self.options.host}:{self.port}"

    async def connect(self) -> None:
        from pymodbus.server import ModbusTcpServer
        from pymodbus.simulator import DataType, SimData, SimDevice

        if self._server is not None:
            return
        n = self.options.registers

        def regs() -> list[SimData]:
            return [SimData(0, count=n, values=0, datatype=DataType.REGISTERS)]

        def bits() -> list[SimData]:
            return [SimData(0, count=1, values=False, datatype=DataType.BITS)]

        device = SimDevice(id=0, simdata=(bits(), bits(), regs(), regs()))
        server = ModbusTcpServer(device, address=(self.options.host, self.options.port))
        try:
            await server.serve_forever(background=True)
        except OSError as exc:
            raise LinkError(f"{self.endpoint()}: cannot listen: {exc}") from exc
        sockets = getattr(server.transport, "sockets", None)
        if not sockets:
            raise LinkError(f"{self.endpoint()}: cannot listen")
        self.port = sockets[0].getsockname()[1]
        self._server = server
        self._tables = _register_lists(server, n)

    def _check(self, pts: Sequence[ModbusPoint]) -> None:
        for p in pts:
            if p.address + p.width > self.options.registers:
                served = self.options.registers
                raise LinkError(f"{self.endpoint()}: {p.describe()} is beyond the {served} registers served")

    def _plan(self, points: Sequence[Point]) -> list[tuple[list[int], int, ModbusPoint]] | None:
        """(register list, address, point) per point, cached for a list of points."""
        tables = self._tables
        if tables is None:
            return None
        key = tuple(map(id, points))
        plan = self._plans.get(key)
        if plan is None:
            pts: list[ModbusPoint] = list(points)  # type: ignore[arg-type]
            self._check(pts)
            plan = [(tables[p.table], p.address, p) for p in pts]
            self._plans[key] = plan
        return plan

    async def read(self, points: Sequence[Point]) -> list[float]:
        server = self.live(self._server, "not serving")
        plan = self._plan(points)
        if plan is not None:
            return [p.decode(regs[a : a + p.width]) for regs, a, p in plan]
        pts: list[ModbusPoint] = list(points)  # type: ignore[arg-type]
        self._check(pts)
        out = [math.nan] * len(pts)
        for span, members in plan_reads(pts, 0):
            fc = 3 if span.table == "holding" else 4
            regs = await server.async_getValues(0, fc, span.start, span.count)
            decode_span(out, pts, members, span, regs)
        return out

    async def write(self, points: Sequence[Point], values: Sequence[float]) -> None:
        server = self.live(self._server, "not serving")
        plan = self._plan(points)
        if plan is not None:
            for (regs, a, p), v in zip(plan, values, strict=True):
                regs[a : a + p.width] = p.encode(v)
            return
        pts: list[ModbusPoint] = list(points)  # type: ignore[arg-type]
        self._check(pts)
        for table, start, regs in plan_writes(pts, values):
            # function code 16 stores holding registers, 4 input registers (our own datastore)
            await server.async_setValues(0, 16 if table == "holding" else 4, start, regs)

    async def close(self) -> None:
        server, self._server = self._server, None
        self._tables = None
        self._plans.clear()
        if server is not None:
            with contextlib.suppress(Exception):  # a server already torn down
                await server.shutdown()


def _register_lists(server: Any, count: int) -> dict[str, list[int]] | None:
    """The holding and input register lists of a pymodbus 3.16 simulator device (start
    address 0, ``count`` registers), or None when they are not where 3.16 keeps them."""
    try:
        blocks = server.context.devices[0].block
        tables = {"holding": blocks["h"], "input": blocks["i"]}
    except (AttributeError, KeyError, IndexError, TypeError):
        return None
    out: dict[str, list[int]] = {}
    for name, block in tables.items():
        ok = isinstance(block, tuple) and len(block) == 4 and block[0] == 0
        if not ok or not isinstance(block[2], list):
            return None
        if len(block[2]) < count:
            return None
        out[name] = block[2]
    return out
