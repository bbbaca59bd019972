"""Siemens S7 client (python-snap7): REALs and INTs in data blocks, addressed by DB number
and byte offset (``DB1.DBD8`` is ``{db = 1, offset = 8}``).

python-snap7 is pure Python from release 3.0 on (it no longer loads the native snap7
library), so nothing but the wheel is needed; pyproject.toml requires >= 3.0 for that.
Its client is synchronous: each request runs in a worker thread so that the I/O event
loop keeps serving the other connections.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import math
import struct
from collections.abc import Sequence
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from fuzzyctl.io.base import Connector, LinkError, Point, bounded
from fuzzyctl.io.codec import real_from_bytes, real_to_bytes

__all__ = ["S7Client", "S7Options", "S7Point"]

logging.getLogger("snap7").setLevel(logging.CRITICAL)  # the runtime reports link state itself

MAX_SPAN = 400  # bytes read in one request before we split (the client chunks by PDU anyway)


class S7Point(Point):
    """A value in a data block: ``{db = 1, offset = 8}`` (REAL) or ``type = "int"``."""

    area: Literal["DB"] = "DB"
    db: int = Field(ge=1, le=65535)
    offset: int = Field(ge=0, le=65535, description="byte offset in the data block")
    type: Literal["real", "int", "word"] = "real"

    @property
    def width(self) -> int:
        return 4 if self.type == "real" else 2

    def describe(self) -> str:
        return f"DB{self.db}.{'DBD' if self.type == 'real' else 'DBW'}{self.offset} {self.type.upper()}"

    def decode(self, data: bytes | bytearray, at: int) -> float:
        if self.type == "real":
            return real_from_bytes(data, at)
        return float(struct.unpack_from(">h" if self.type == "int" else ">H", data, at)[0])

    def encode(self, value: float) -> bytes:
        if self.type == "real":
            return real_to_bytes(value)
        if math.isnan(value):
            raise ValueError("NaN has no integer representation")
        low, high = (-32768, 32767) if self.type == "int" else (0, 65535)
        n = math.floor(abs(value) + 0.5) * (1 if value >= 0 else -1) if math.isfinite(value) else value
        return struct.pack(">h" if self.type == "int" else ">H", int(min(max(n, low), high)))


class S7Options(BaseModel):
    model_config = ConfigDict(extra="forbid")

    host: str = "127.0.0.1"
    port: int = Field(default=102, ge=1, le=65535)
    rack: int = Field(default=0, ge=0, le=7)
    slot: int = Field(default=1, ge=0, le=31)
    timeout: float = Field(default=1.0, gt=0, le=60)


class S7Client(Connector):
    """An S7 client (PUT/GET communication: ``db_read`` / ``db_write``)."""

    point_model = S7Point
    options_model = S7Options
    options: S7Options

    def __init__(self, name: str, options: S7Options) -> None:
        super().__init__(name, options)
        self._client: Any = None

    def endpoint(self) -> str:
        o = self.options
        return f"s7://{o.host}:{o.port}/{o.rack}/{o.slot}"

    async def _run(self, what: str, fn: Any, *args: Any) -> Any:
        try:
            return await bounded(asyncio.to_thread(fn, *args), self.options.timeout + 1, "no answer")
        # snap7 raises its own errors, OSError, RuntimeError and struct errors on a broken
        # connection: all of them mean the link is unusable.
        except Exception as exc:
            raise LinkError(f"{self.endpoint()}: {what}: {exc or type(exc).__name__}") from exc

    async def connect(self) -> None:
        import snap7

        await self.close()
        o = self.options
        client = snap7.Client()

        def connect() -> None:
            client.connect(o.host, o.rack, o.slot, o.port)
            conn = getattr(client, "connection", None)
            sock = getattr(conn, "socket", None)
            if conn is not None:
                conn.timeout = o.timeout
            if sock is not None:
                sock.settimeout(o.timeout)

        await self._run("connect", connect)
        self._client = client

    async def read(self, points: Sequence[Point]) -> list[float]:
        client = self._client
        if client is None:
            raise LinkError(f"{self.endpoint()}: not connected")
        pts: list[S7Point] = list(points)  # type: ignore[arg-type]
        out = [math.nan] * len(pts)
        by_db: dict[int, list[int]] = {}
        for i, p in enumerate(pts):
            by_db.setdefault(p.db, []).append(i)
        for db, members in by_db.items():
            members.sort(key=lambda i: pts[i].offset)
            group: list[int] = []
            for i in [*members, -1]:
                if i >= 0 and (not group or pts[i].offset + pts[i].width - pts[group[0]].offset <= MAX_SPAN):
                    group.append(i)
                    continue
                start = pts[group[0]].offset
                size = max(pts[j].offset + pts[j].width for j in group) - start
                data = await self._run(f"read DB{db}.DBB{start}+{size}", client.db_read, db, start, size)
                if len(data) < size:
                    raise LinkError(f"{self.endpoint()}: short answer reading DB{db}")
                for j in group:
                    out[j] = pts[j].decode(data, pts[j].offset - start)
                group = [i]
        return out

    async def write(self, points: Sequence[Point], values: Sequence[float]) -> None:
        client = self._client
        if client is None:
            raise LinkError(f"{self.endpoint()}: not connected")
        cells: dict[tuple[int, int], int] = {}
        for p, v in zip(points, values, strict=True):
            assert isinstance(p, S7Point)
            for k, byte in enumerate(p.encode(v)):
                cells[(p.db, p.offset + k)] = byte
        runs: list[tuple[int, int, bytearray]] = []
        for (db, off), byte in sorted(cells.items()):
            if runs and runs[-1][0] == db and runs[-1][1] + len(runs[-1][2]) == off:
                runs[-1][2].append(byte)
            else:
                runs.append((db, off, bytearray([byte])))
        for db, off, data in runs:
            await self._run(f"write DB{db}.DBB{off}+{len(data)}", client.db_write, db, off, data)

    async def close(self) -> None:
        client, self._client = self._client, None
        if client is not None:
            with contextlib.suppress(Exception):  # a connection already broken
                await asyncio.to_thread(client.disconnect)
