"""An abusive HTTP client: huge request bodies sent over raw sockets to a fuzzyctl API
(the runtime's or the studio's), with Content-Length or chunked, without a token.

    python benchmarks/http_abuse.py http://127.0.0.1:8765/api/v1/instances/fb000/knowledge_base \
        --mb 500 --repeat 3

For each request it prints one JSON line: how it was sent, how many bytes went out before
the server answered or closed, the status line and the seconds it took.  A server that
bounds its requests answers at once (401 / 413) having read almost nothing; one that reads
the body first takes the whole upload (and its memory).  ``runtime_jitter.py --abuse``
runs this in a separate process while it measures the cycle jitter.
"""

from __future__ import annotations

import argparse
import json
import socket
import sys
import time
import urllib.parse

CHUNK = 1 << 20


def _status(sock: socket.socket) -> str | None:
    """The status line if the server already answered (non-blocking peek)."""
    sock.setblocking(False)
    try:
        data = sock.recv(4096, socket.MSG_PEEK)
    except (BlockingIOError, InterruptedError):
        return None
    except OSError:
        return "closed"
    finally:
        sock.setblocking(True)
    if not data:
        return "closed"
    return data.split(b"\r\n", 1)[0].decode("latin-1")


def abuse(url: str, megabytes: int, chunked: bool, token: str | None = None) -> dict[str, object]:
    """Send one PUT of ``megabytes`` MB; stop as soon as the server answers or closes."""
    parts = urllib.parse.urlsplit(url)
    host, port = parts.hostname or "127.0.0.1", parts.port or 80
    total = megabytes * CHUNK
    head = [f"PUT {parts.path} HTTP/1.1", f"Host: {host}:{port}", "Content-Type: application/json"]
    head.append("Transfer-Encoding: chunked" if chunked else f"Content-Length: {total}")
    if token:
        head.append(f"Authorization: Bearer {token}")
    t0 = time.perf_counter()
    sent = 0
    status: str | None = None
    with socket.create_connection((host, port), timeout=30) as sock:
        sock.sendall(("\r\n".join(head) + "\r\n\r\n").encode())
        piece = b'{"text": "' + b"x" * (CHUNK - 10)
        try:
            while sent < total:
                status = _status(sock)
                if status is not None:
                    break
                data = piece if sent == 0 else b"x" * CHUNK
                if chunked:
                    sock.sendall(f"{len(data):x}\r\n".encode() + data + b"\r\n")
                else:
                    sock.sendall(data)
                sent += len(data)
            else:
                if chunked:
                    sock.sendall(b"0\r\n\r\n")
        except OSError as exc:  # the server closed on us: what it said is in the buffer
            status = status or f"send failed: {exc.__class__.__name__}"
        sock.settimeout(30)
        try:
            answer = sock.recv(4096)
            if answer:
                status = answer.split(b"\r\n", 1)[0].decode("latin-1")
        except OSError:
            pass
    return {
        "mode": "chunked" if chunked else "content-length",
        "token": bool(token),
        "megabytes": megabytes,
        "sent_mb": round(sent / CHUNK, 1),
        "status": status,
        "seconds": round(time.perf_counter() - t0, 3),
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("url")
    ap.add_argument("--mb", type=int, default=500, help="body size in MB")
    ap.add_argument("--repeat", type=int, default=1, help="rounds of (content-length, chunked)")
    ap.add_argument("--token", default=None, help="send this bearer token (an authenticated abuser)")
    ap.add_argument("--seconds", type=float, default=None, help="keep going for this long instead")
    args = ap.parse_args(argv)
    deadline = None if args.seconds is None else time.monotonic() + args.seconds
    rounds = 0
    while True:
        for chunked in (False, True):
            print(json.dumps(abuse(args.url, args.mb, chunked, args.token)), flush=True)
        rounds += 1
        if deadline is None and rounds >= args.repeat:
            break
        if deadline is not None and time.monotonic() >= deadline:
            break
    return 0


if __name__ == "__main__":
    sys.exit(main())
