"""The front door of fuzzyctl's two HTTP servers (the runtime API and the studio): an ASGI
middleware that refuses, before the application sees a request,

* a ``Host`` that is not one of the served names (DNS rebinding: a page from
  ``attacker.example`` whose name now resolves to 127.0.0.1 sends ``Host:
  attacker.example``);
* an ``Origin`` of another site (a browser page reading or writing cross-origin, a
  cross-site WebSocket); clients that are not browsers send no Origin and are not affected;
* a request without a valid token where one is required, *before its body is read*;
* a body over the limit, announced by ``Content-Length`` (refused unread) or sent chunked
  (counted while read, refused at the limit): nothing over the limit is ever held in memory.

A refusal is ``{"detail": "..."}`` with 400, 401, 403 or 413 (a WebSocket is refused at the
handshake, HTTP 403); the connection is closed when a body was left unread.  Nothing of
what the client sent is echoed.  Requests that pass reach the application with their body
already read (so the application never waits on a slow or endless upload either).
"""

from __future__ import annotations

import json
import secrets
import urllib.parse
from collections.abc import Awaitable, Callable, Collection, MutableMapping
from dataclasses import dataclass
from typing import Any

__all__ = ["LOOPBACK_NAMES", "Guard", "Refusal", "bearer_token", "host_name", "token_matches"]

Scope = MutableMapping[str, Any]
Message = MutableMapping[str, Any]
Receive = Callable[[], Awaitable[Message]]
Send = Callable[[Message], Awaitable[None]]
ASGIApp = Callable[[Scope, Receive, Send], Awaitable[None]]

LOOPBACK_NAMES = frozenset({"127.0.0.1", "localhost", "::1"})
BODY_METHODS = frozenset({"POST", "PUT", "PATCH", "DELETE"})


@dataclass(frozen=True)
class Refusal:
    """Why a request is refused: the HTTP status, a message, extra response headers."""

    status: int
    detail: str
    headers: tuple[tuple[str, str], ...] = ()


Authorize = Callable[[Scope, dict[str, str]], "Refusal | None"]
"""``authorize(scope, headers)``: None to let the request through (headers lower-cased)."""


def host_name(value: str) -> str:
    """The name in a Host header or an origin's netloc, lower-cased, without the port:
    ``"[::1]:8765"`` -> ``"::1"``, ``"Plant.Local:80"`` -> ``"plant.local"``."""
    value = value.strip().lower()
    if value.startswith("["):
        end = value.find("]")
        return value[1:end] if end > 0 else ""
    return value.rsplit(":", 1)[0] if value.count(":") == 1 else value


def bearer_token(headers: dict[str, str]) -> str | None:
    """The token of an ``Authorization: Bearer <token>`` header."""
    value = headers.get("authorization", "")
    scheme, _, token = value.partition(" ")
    return token.strip() if scheme.lower() == "bearer" and token.strip() else None


def token_matches(given: str | None, expected: str | None) -> bool:
    """Constant-time comparison; False when either is missing."""
    if not given or not expected:
        return False
    return secrets.compare_digest(given.encode(), expected.encode())


class _BodyTooLarge(Exception):
    pass


class _ClientGone(Exception):
    pass


class Guard:
    """Wraps an ASGI application.

    ``hosts``: the names a Host header may carry (None: any).  ``origins``: browser
    origins allowed besides the server's own (``"http://scada.local:8080"``).
    ``origin_on_reads``: check Origin on every request (the runtime: no cross-origin
    reads) or only on requests with a body and WebSockets (the studio, whose pages are
    fetched by a browser).  ``max_body(method, path)``: the body limit in bytes.
    ``authorize``: the token check (None: no token)."""

    def __init__(
        self,
        app: ASGIApp,
        *,
        hosts: Collection[str] | None,
        max_body: Callable[[str, str], int],
        origins: Collection[str] = (),
        origin_on_reads: bool = True,
        authorize: Authorize | None = None,
        json_only: Callable[[str], bool] | None = None,
    ) -> None:
        self.app = app
        self.hosts = None if hosts is None else frozenset(h.lower().strip("[]") for h in hosts)
        self.origins = frozenset(o.rstrip("/").lower() for o in origins)
        self.origin_on_reads = origin_on_reads
        self.max_body = max_body
        self.authorize = authorize
        self.json_only = json_only

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        kind = scope["type"]
        if kind not in ("http", "websocket"):
            await self.app(scope, receive, send)
            return
        headers = {k.decode("latin-1").lower(): v.decode("latin-1") for k, v in scope["headers"]}
        method = scope.get("method", "GET") if kind == "http" else "GET"
        refusal = self._check(scope, headers, method)
        if refusal is not None:
            await _refuse(scope, receive, send, refusal, body_unread=method in BODY_METHODS)
            return
        if kind == "websocket" or method not in BODY_METHODS:
            await self.app(scope, receive, send)
            return
        limit = self.max_body(method, scope["path"])
        try:
            body = await _read_body(receive, limit)
        except _BodyTooLarge:
            await _refuse(scope, receive, send, Refusal(413, f"request body over {limit} bytes"), True)
            return
        except _ClientGone:
            return
        await self.app(scope, _replay(body, receive), send)

    def _check(self, scope: Scope, headers: dict[str, str], method: str) -> Refusal | None:
        host = headers.get("host", "")
        if self.hosts is not None and host_name(host) not in self.hosts:
            return Refusal(403, "this server does not answer to that host name (Host header)")
        origin = headers.get("origin")
        body = method in BODY_METHODS
        checked = self.origin_on_reads or body or scope["type"] == "websocket"
        if origin is not None and checked and not self._origin_allowed(origin, host):
            return Refusal(403, "cross-origin request refused (Origin header)")
        if self.authorize is not None:
            refusal = self.authorize(scope, headers)
            if refusal is not None:
                return refusal
        if body:
            length = headers.get("content-length")
            if length is not None:
                limit = self.max_body(method, scope["path"])
                if not length.isdigit() or len(length) > 18:
                    return Refusal(400, "invalid Content-Length")
                if int(length) > limit:
                    return Refusal(413, f"request body over {limit} bytes")
        has_body = headers.get("content-length", "0") != "0" or "transfer-encoding" in headers
        if has_body and self.json_only is not None and self.json_only(scope["path"]):
            kind = headers.get("content-type", "")
            if not kind.startswith("application/json"):
                return Refusal(415, "send JSON (content-type: application/json)")
        return None

    def _origin_allowed(self, origin: str, host: str) -> bool:
        origin = origin.strip().lower().rstrip("/")
        if origin in self.origins:
            return True
        parts = urllib.parse.urlsplit(origin)
        # Same origin: the page was served by this very server under the name it used.
        return parts.scheme in ("http", "https") and bool(parts.netloc) and parts.netloc == host.lower()


async def _read_body(receive: Receive, limit: int) -> bytes:
    chunks: list[bytes] = []
    size = 0
    while True:
        message = await receive()
        if message["type"] == "http.disconnect":
            raise _ClientGone
        chunk = message.get("body", b"")
        size += len(chunk)
        if size > limit:
            raise _BodyTooLarge
        chunks.append(chunk)
        if not message.get("more_body", False):
            return b"".join(chunks)


def _replay(body: bytes, receive: Receive) -> Receive:
    sent = False

    async def replay() -> Message:
        nonlocal sent
        if not sent:
            sent = True
            return {"type": "http.request", "body": body, "more_body": False}
        return await receive()

    return replay


async def _refuse(scope: Scope, receive: Receive, send: Send, refusal: Refusal, body_unread: bool) -> None:
    if scope["type"] == "websocket":
        # Closing before accepting makes the server answer the handshake with HTTP 403.
        await send({"type": "websocket.close", "code": 1008, "reason": ""})
        return
    payload = json.dumps({"detail": refusal.detail}).encode()
    headers = [(b"content-type", b"application/json"), (b"content-length", str(len(payload)).encode())]
    headers += [(k.encode("latin-1"), v.encode("latin-1")) for k, v in refusal.headers]
    if body_unread:
        headers.append((b"connection", b"close"))  # the rest of the upload is not read
    await send({"type": "http.response.start", "status": refusal.status, "headers": headers})
    await send({"type": "http.response.body", "body": payload, "more_body": False})
