"""On line: the studio's backend talks to a running ``fuzzyctl serve`` (docs/runtime.md)
on the browser's behalf, so that the browser needs no cross-origin access and the token
only travels between two local processes.  The runtime wants a token for reading too:
the write token, or its read-only token (enough to watch, not to command).

Only ``http``/``https`` URLs are accepted, and only the runtime API's own paths are
called (``/api/v1/...``).
"""

from __future__ import annotations

import json
import urllib.error
import urllib.parse
import urllib.request
from typing import Any

from fuzzyctl.diagnostics import FuzzyctlError

TIMEOUT = 5.0


class OnlineError(FuzzyctlError):
    """The runtime could not be reached or refused a request; ``status`` is its HTTP
    status (0: not reached)."""

    def __init__(self, message: str, status: int = 0, body: Any = None) -> None:
        super().__init__(message)
        self.status = status
        self.body = body


def base_url(url: str) -> str:
    """``http://host:port`` plus ``/api/v1``, whatever of it the user typed."""
    parsed = urllib.parse.urlsplit(url.strip())
    if parsed.scheme not in ("http", "https") or not parsed.netloc:
        raise FuzzyctlError(f"{url!r}: give the runtime's address as http://host:port")
    path = parsed.path.rstrip("/")
    if path.endswith("/api/v1"):
        path = path[: -len("/api/v1")]
    return urllib.parse.urlunsplit((parsed.scheme, parsed.netloc, path, "", "")) + "/api/v1"


def call(
    url: str,
    method: str,
    path: str,
    *,
    token: str | None = None,
    body: dict[str, Any] | None = None,
) -> Any:
    """One request to the runtime API; its JSON answer, or :class:`OnlineError`."""
    target = base_url(url) + path
    data = None if body is None else json.dumps(body).encode("utf-8")
    request = urllib.request.Request(target, data=data, method=method)
    request.add_header("Accept", "application/json")
    if data is not None:
        request.add_header("Content-Type", "application/json")
    if token:
        request.add_header("Authorization", f"Bearer {token}")
    try:
        with urllib.request.urlopen(request, timeout=TIMEOUT) as response:
            raw = response.read()
    except urllib.error.HTTPError as exc:
        try:
            payload = json.loads(exc.read() or b"null")
        except json.JSONDecodeError:
            payload = None
        detail = payload.get("detail") if isinstance(payload, dict) else None
        message = detail if isinstance(detail, str) else f"the runtime answered {exc.code}"
        raise OnlineError(message, exc.code, payload) from None
    except (urllib.error.URLError, OSError) as exc:
        reason = getattr(exc, "reason", exc)
        raise OnlineError(f"cannot reach the runtime at {target}: {reason}") from None
    try:
        return json.loads(raw or b"null")
    except json.JSONDecodeError:
        raise OnlineError(f"{target} did not answer JSON: is it a fuzzyctl runtime?") from None


def quote(name: str) -> str:
    return urllib.parse.quote(name, safe="")


def knowledge_base_fcl(url: str, instance: str, token: str | None = None) -> dict[str, Any]:
    """The knowledge base an instance runs, as FCL text (converted when it was loaded
    from another format) for the download diff."""
    from fuzzyctl import formats
    from fuzzyctl.fcl import write

    kb = call(url, "GET", f"/instances/{quote(instance)}/knowledge_base", token=token)
    text = kb.get("text", "") if isinstance(kb, dict) else ""
    fmt = kb.get("format", "fcl") if isinstance(kb, dict) else "fcl"
    if fmt == "fcl":
        fcl = text
    else:
        try:
            fcl = write(formats.read_text(text, fmt).document)
        except FuzzyctlError as exc:
            fcl = f"(* the running knowledge base ({fmt}) cannot be shown as FCL: {exc} *)\n"
    return {"format": fmt, "origin": kb.get("origin"), "sha256": kb.get("sha256"), "fcl": fcl}
