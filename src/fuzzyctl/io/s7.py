"""Siemens S7 client (python-snap7): REALs, INTs, WORDs and BYTEs in data blocks, addressed
by DB number and byte offset (``DB1.DBD8`` is ``{db = 1, offset = 8}``), or by parameter
name in a FUZZY instance data block (``{db = 30, parameter = "INPUT1"}``).

The FUZZY instance DB (Siemens S7 Fuzzy Control manual, Tables 3-1..3-3) as the PLC holds
it, S7 types big-endian:

==========  ============  =========  ==============================================
byte        parameter     type       meaning
==========  ============  =========  ==============================================
0..28       INPUT1..8     REAL       inputs of the fuzzy application (4 bytes each)
32..44      OUTPUT1..4    REAL       outputs of the fuzzy application
48          INFO          BYTE       B#16#00, 01, 11, 21 (49 is the padding to the WORD)
50          START_STOP    WORD       0: do not process, else process
52..2125    FUZZY[0..2073] BYTE      the block's internal area ("52 to 2126"; the DB
                                     is 2126 bytes long, 3.4)
==========  ============  =========  ==============================================

With these bindings ``fuzzyctl serve`` stands in for FB30 beside a PLC whose program keeps
its FUZZY DB (FUZZY_AI writes INPUTn, FUZZY_AO reads OUTPUTn, the program watches INFO and
sets START_STOP): only the bound parameters are read and written; the internal area is the
PLC's (the soft block keeps its application in the runtime).

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
import re
import struct
from collections.abc import Sequence
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from fuzzyctl.io.base import Connector, DaemonExecutor, LinkError, Point, bounded
from fuzzyctl.io.codec import real_from_bytes, real_to_bytes

__all__ = ["FUZZY_DB", "FUZZY_DB_INTERNAL", "S7Client", "S7Options", "S7Point", "fuzzy_db_address"]

logging.getLogger("snap7").setLevel(logging.CRITICAL)  # the runtime reports link state itself

# python-snap7 blocks: its calls run on daemon threads, so that one stuck on a frozen PLC
# until its socket timeout does not hold the process at exit (a runtime that stops gives
# up on it after the link's stop_timeout).
_CALLS = DaemonExecutor(name="fuzzyctl-s7")

MAX_SPAN = 400  # bytes read in one request before we split (the client chunks by PDU anyway)

S7Type = Literal["real", "int", "word", "byte"]
_WIDTH = {"real": 4, "int": 2, "word": 2, "byte": 1}
_RANGE = {"int": (-32768, 32767), "word": (0, 65535), "byte": (0, 255)}
_FORMAT = {"int": ">h", "word": ">H", "byte": ">B"}
_AREA = {"real": "DBD", "int": "DBW", "word": "DBW", "byte": "DBB"}

FUZZY_DB: dict[str, tuple[int, S7Type]] = {
    **{f"INPUT{i}": (4 * (i - 1), "real") for i in range(1, 9)},  # Table 3-1
    **{f"OUTPUT{i}": (32 + 4 * (i - 1), "real") for i in range(1, 5)},  # Table 3-2
    "INFO": (48, "byte"),  # Table 3-2
    "START_STOP": (50, "word"),  # Table 3-3
}
"""The parameters of a FUZZY instance DB: name -> (byte offset, S7 type), Tables 3-1..3-3."""
FUZZY_DB_INTERNAL = (52, 2126)
"""The internal area ``FUZZY`` (Table 3-3, "52 to 2126"): bytes 52 up to the DB length 2126
(3.4), addressed as ``FUZZY[0]`` .. ``FUZZY[2073]``, BYTE each."""


def fuzzy_db_address(parameter: str) -> tuple[str, int, S7Type]:
    """``(name, byte offset, type)`` of a FUZZY instance DB parameter (``INPUT1``..``INPUT8``,
    ``OUTPUT1``..``OUTPUT4``, ``INFO``, ``START_STOP``, ``FUZZY[n]``), case-insensitive;
    ValueError naming the valid ones otherwise."""
    name = parameter.strip().upper()
    if name in FUZZY_DB:
        offset, kind = FUZZY_DB[name]
        return name, offset, kind
    m = re.fullmatch(r"FUZZY\s*\[\s*(\d+)\s*\]", name)
    first, end = FUZZY_DB_INTERNAL
    if m is not None and first + int(m.group(1)) < end:
        return f"FUZZY[{int(m.group(1))}]", first + int(m.group(1)), "byte"
    raise ValueError(
        f"{parameter!r} is not a parameter of a FUZZY instance DB (Tables 3-1..3-3: INPUT1..INPUT8, "
        f"OUTPUT1..OUTPUT4, INFO, START_STOP, or FUZZY[0]..FUZZY[{end - first - 1}] of the internal area)"
    )


class S7Point(Point):
    """A value in a data block: ``{db = 1, offset = 8}`` (REAL), ``type = "int"``, ``"word"``
    or ``"byte"``; or a FUZZY instance DB parameter ``{db = 30, parameter = "OUTPUT1"}``,
    whose offset and type come from the manual's Tables 3-1..3-3 (:data:`FUZZY_DB`)."""

    area: Literal["DB"] = "DB"
    db: int = Field(ge=1, le=65535)
    offset: int = Field(ge=0, le=65535, description="byte offset in the data block")
    type: S7Type = "real"
    parameter: str | None = Field(
        default=None, description="FUZZY instance DB parameter (Tables 3-1..3-3) instead of offset/type"
    )

    @model_validator(mode="before")
    @classmethod
    def _fuzzy_db_parameter(cls, data: Any) -> Any:
        if not isinstance(data, dict) or data.get("parameter") is None:
            return data
        if "offset" in data or "type" in data:
            raise ValueError("give either parameter (a FUZZY instance DB name) or offset/type, not both")
        if not isinstance(data["parameter"], str):
            raise ValueError("parameter is a name such as 'INPUT1'")
        name, offset, kind = fuzzy_db_address(data["parameter"])
        return {**data, "parameter": name, "offset": offset, "type": kind}

    @property
    def width(self) -> int:
        return _WIDTH[self.type]

    def describe(self) -> str:
        address = f"DB{self.db}.{_AREA[self.type]}{self.offset} {self.type.upper()}"
        return f"DB{self.db}.{self.parameter} ({address})" if self.parameter else address

    def decode(self, data: bytes | bytearray, at: int) -> float:
        if self.type == "real":
            return real_from_bytes(data, at)
        return float(struct.unpack_from(_FORMAT[self.type], data, at)[0])

    def encode(self, value: float) -> bytes:
        if self.type == "real":
            return real_to_bytes(value)
        if math.isnan(value):
            raise ValueError("NaN has no integer representation")
        low, high = _RANGE[self.type]
        n = math.floor(abs(value) + 0.5) * (1 if value >= 0 else -1) if math.isfinite(value) else value
        return struct.pack(_FORMAT[self.type], int(min(max(n, low), high)))


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
            call = asyncio.get_running_loop().run_in_executor(_CALLS, fn, *args)
            return await bounded(call, self.options.timeout + 1, "no answer")
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
        client = self.live(self._client)
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
        client = self.live(self._client)
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
                await asyncio.get_running_loop().run_in_executor(_CALLS, client.disconnect)
