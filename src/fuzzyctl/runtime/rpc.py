"""The local link between the API process and the runtime: framed messages over one
socket pair, requests from the API process, answers from the runtime.

A frame is an 8-byte header (the lengths of a JSON part and of a blob), the JSON, the
blob.  A knowledge base's text travels as the blob (UTF-8), never inside JSON: the
runtime encodes and decodes it in slices, and large answers are encoded item by item, so
that no single C call holds the interpreter (which the cycle thread shares) for long.

Requests ``{"id", "op", "args"}`` are answered ``{"id", "result"}`` or ``{"id", "error":
{"status", "detail", "diagnostics"}}``; ``op = "ready"`` tells the runtime that the API
serves.  Downloads run one at a time on a worker thread, so reads keep being answered
while a knowledge base is built.
"""

from __future__ import annotations

import asyncio
import codecs
import contextlib
import itertools
import json
import queue
import socket
import struct
import threading
from collections.abc import Callable
from typing import Any

from fuzzyctl.runtime.service import Service, ServiceError

__all__ = [
    "HEADER",
    "RpcClient",
    "RpcServer",
    "decode_text",
    "dumps",
    "encode_text",
    "recv_frame",
    "send_frame",
]

HEADER = struct.Struct(">II")
SLICE = 1 << 18  # characters / bytes converted per C call
MAX_JSON = 64 << 20
TEXT_KEY = "text"
SLOW_OPS = frozenset({"download"})


def dumps(obj: Any) -> bytes:
    """JSON, containers of many items encoded one item at a time (each call short)."""
    if isinstance(obj, list) and len(obj) > 32:
        return b"[" + b",".join(dumps(v) for v in obj) + b"]"
    if isinstance(obj, dict) and len(obj) > 32:
        items = (json.dumps(str(k)).encode() + b":" + dumps(v) for k, v in obj.items())
        return b"{" + b",".join(items) + b"}"
    return json.dumps(obj, separators=(",", ":")).encode()


def encode_text(text: str) -> bytes:
    return b"".join(text[i : i + SLICE].encode("utf-8", "surrogatepass") for i in range(0, len(text), SLICE))


def decode_text(blob: bytes | bytearray | memoryview) -> str:
    decoder = codecs.getincrementaldecoder("utf-8")("surrogatepass")
    view = memoryview(blob)
    parts = [decoder.decode(view[i : i + SLICE]) for i in range(0, len(view), SLICE)]
    parts.append(decoder.decode(b"", final=True))
    return "".join(parts)


def _frame(message: dict[str, Any], blob: bytes = b"") -> list[bytes]:
    body = dumps(message)
    return [HEADER.pack(len(body), len(blob)), body, blob]


def send_frame(sock: socket.socket, message: dict[str, Any], blob: bytes = b"") -> None:
    """Send one frame (blocking socket)."""
    for part in _frame(message, blob):
        if part:
            sock.sendall(part)


def _recv_exact(sock: socket.socket, n: int) -> bytearray:
    buf = bytearray(n)
    view = memoryview(buf)
    got = 0
    while got < n:
        k = sock.recv_into(view[got:], min(n - got, 1 << 20))
        if k == 0:
            raise EOFError("the peer closed the link")
        got += k
    return buf


def recv_frame(sock: socket.socket, max_blob: int) -> tuple[dict[str, Any], bytearray]:
    """Receive one frame (blocking socket); ValueError for an oversized or invalid one."""
    size, blob_size = HEADER.unpack(_recv_exact(sock, HEADER.size))
    if size > MAX_JSON or blob_size > max_blob:
        raise ValueError(f"frame too large ({size} + {blob_size} bytes)")
    message = json.loads(_recv_exact(sock, size))
    if not isinstance(message, dict):
        raise ValueError("a frame is a JSON object")
    return message, _recv_exact(sock, blob_size) if blob_size else bytearray()


class RpcServer:
    """The runtime's end: answers the API process's requests with ``service``."""

    def __init__(
        self,
        service: Service,
        sock: socket.socket,
        *,
        max_blob: int,
        on_ready: Callable[[], None],
        on_closed: Callable[[BaseException | None], None],
        thread_setup: Callable[[], None] = lambda: None,
    ) -> None:
        self.service = service
        self.sock = sock
        self.max_blob = max_blob
        self._on_ready = on_ready
        self._on_closed = on_closed
        self._thread_setup = thread_setup
        self._send_lock = threading.Lock()
        self._slow: queue.SimpleQueue[tuple[dict[str, Any], bytearray] | None] = queue.SimpleQueue()
        self._threads = [
            threading.Thread(target=self._read_loop, name="fuzzyctl-api-rpc", daemon=True),
            threading.Thread(target=self._slow_loop, name="fuzzyctl-api-download", daemon=True),
        ]

    def start(self) -> None:
        for t in self._threads:
            t.start()

    def join(self, timeout: float) -> None:
        for t in self._threads:
            t.join(timeout)

    def _read_loop(self) -> None:
        self._thread_setup()
        problem: BaseException | None = None
        try:
            while True:
                message, blob = recv_frame(self.sock, self.max_blob)
                if message.get("op") in SLOW_OPS:
                    self._slow.put((message, blob))
                else:
                    self._handle(message, blob)
        except EOFError:
            pass
        except (OSError, ValueError) as exc:
            problem = exc
        finally:
            self._slow.put(None)
            self._on_closed(problem)

    def _slow_loop(self) -> None:
        self._thread_setup()  # it parses and builds while holding the lock: not preemptible either
        while (item := self._slow.get()) is not None:
            self._handle(*item)

    def _handle(self, message: dict[str, Any], blob: bytearray) -> None:
        op = str(message.get("op", ""))
        reply: dict[str, Any] = {"id": message.get("id")}
        out_blob = b""
        try:
            if op == "ready":
                self._on_ready()
                result: Any = None
            else:
                args = message.get("args") or {}
                if blob:
                    args[TEXT_KEY] = decode_text(blob)
                result = self.service.call(op, args)
            if isinstance(result, dict) and isinstance(result.get(TEXT_KEY), str):
                out_blob = encode_text(result[TEXT_KEY])
                result = {**result, TEXT_KEY: None}
            reply["result"] = result
        except ServiceError as exc:
            reply["error"] = exc.to_dict()
        except UnicodeDecodeError:
            reply["error"] = {"status": 400, "detail": "the text is not UTF-8"}
        except Exception as exc:  # a bug: answer it, keep serving
            reply["error"] = {"status": 500, "detail": f"internal error: {type(exc).__name__}"}
        frame = _frame(reply, out_blob)
        with self._send_lock, contextlib.suppress(OSError):  # the API process went away
            for part in frame:
                if part:
                    self.sock.sendall(part)


class RpcClient:
    """The API process's end (asyncio): ``await client.call(op, **args)``."""

    def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self._reader = reader
        self._writer = writer
        self._ids = itertools.count(1)
        self._pending: dict[int, asyncio.Future[tuple[Any, bytes]]] = {}
        self.closed = asyncio.Event()
        self._task: asyncio.Task[None] | None = None

    def start(self) -> None:
        self._task = asyncio.get_running_loop().create_task(self._read_loop())

    async def call(self, op: str, **args: Any) -> Any:
        """The result of one operation; raises :class:`ServiceError` (503 when the runtime
        is gone)."""
        if self.closed.is_set():
            raise ServiceError(503, "the runtime is stopping")
        ident = next(self._ids)
        future: asyncio.Future[tuple[Any, bytes]] = asyncio.get_running_loop().create_future()
        self._pending[ident] = future
        blob = b""
        text = args.get(TEXT_KEY)
        if isinstance(text, str):
            blob = text.encode("utf-8", "surrogatepass")
            args = {k: v for k, v in args.items() if k != TEXT_KEY}
        for part in _frame({"id": ident, "op": op, "args": args}, blob):
            self._writer.write(part)
        await self._writer.drain()
        result, out_blob = await future
        if isinstance(result, dict) and TEXT_KEY in result and result[TEXT_KEY] is None and out_blob:
            result[TEXT_KEY] = out_blob.decode("utf-8", "surrogatepass")
        return result

    async def _read_loop(self) -> None:
        try:
            while True:
                size, blob_size = HEADER.unpack(await self._reader.readexactly(HEADER.size))
                message = json.loads(await self._reader.readexactly(size))
                blob = await self._reader.readexactly(blob_size) if blob_size else b""
                future = self._pending.pop(message.get("id"), None)
                if future is None or future.done():
                    continue
                if "error" in message:
                    e = message["error"]
                    future.set_exception(ServiceError(e["status"], e["detail"], e.get("diagnostics")))
                else:
                    future.set_result((message.get("result"), blob))
        except (asyncio.IncompleteReadError, ConnectionError, OSError, ValueError):
            pass
        finally:
            self.closed.set()
            for future in self._pending.values():
                if not future.done():
                    future.set_exception(ServiceError(503, "the runtime is stopping"))
            self._pending.clear()
