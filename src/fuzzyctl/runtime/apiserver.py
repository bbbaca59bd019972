"""The API in its own process, so that no HTTP work ever runs on the interpreter that the
cycle thread uses (a 500 MB upload, a thousand connections, a slow client: all of it is
this process's problem, at a lower CPU priority).

The runtime binds the listening socket itself (so that a port in use is its error, and
the port is known at once), then starts ``python -m fuzzyctl.runtime.apiserver LISTEN_FD
LINK_FD`` with both sockets inherited, and sends the settings (tokens, names, limits) over
the link, never on the command line.  The API process serves HTTP with uvicorn and
forwards each request that passed the front door to the runtime (:mod:`.rpc`).  It ends
when the link closes: when the runtime stops, or dies.  :class:`ApiProcess` is the
runtime's side: it starts the process, waits until it serves, restarts it if it dies
(at most once every ``RESTART_DELAY`` s) and stops it.
"""

from __future__ import annotations

import asyncio
import contextlib
import dataclasses
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from typing import Any

from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.runtime.rpc import RpcClient, RpcServer, recv_frame, send_frame
from fuzzyctl.runtime.service import Service

__all__ = ["ApiProcess", "main"]

NICE = 10  # the API process yields the CPU to the runtime (and to the cycles at normal priority)
RESTART_DELAY = 1.0
START_TIMEOUT = 60.0


class ApiProcess:
    """The runtime's handle on its API process."""

    def __init__(
        self,
        service: Service,
        listen: socket.socket,
        settings: Any,
        *,
        emit: Callable[..., Any],
        thread_setup: Callable[[], None] = lambda: None,
    ) -> None:
        self.service = service
        self.listen = listen
        self.settings = settings
        self.emit = emit
        self.thread_setup = thread_setup
        self.proc: subprocess.Popen[bytes] | None = None
        self._link: socket.socket | None = None
        self._server: RpcServer | None = None
        self._ready = threading.Event()
        self._stopping = False
        self._lock = threading.Lock()
        self.restarts = 0

    def start(self, wait: bool = True) -> None:
        """Start the process; with ``wait``, until it serves (FuzzyctlError if it cannot)."""
        self._spawn()
        if wait:
            self.wait_ready()

    def wait_ready(self) -> None:
        """Until the process serves; FuzzyctlError when it does not within START_TIMEOUT."""
        deadline = time.monotonic() + START_TIMEOUT
        while not self._ready.wait(0.1):
            proc = self.proc
            if proc is not None and proc.poll() is not None and self.restarts == 0:
                raise FuzzyctlError(f"the API process ended at start (exit code {proc.returncode})")
            if time.monotonic() > deadline:
                raise FuzzyctlError(f"the API process did not start within {START_TIMEOUT:g} s")

    def _spawn(self) -> None:
        ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
        self._ready.clear()
        cmd = [
            sys.executable,
            "-m",
            "fuzzyctl.runtime.apiserver",
            str(self.listen.fileno()),
            str(theirs.fileno()),
        ]
        try:
            # Started from this (normal-priority) thread: the child must not inherit SCHED_FIFO.
            self.proc = subprocess.Popen(
                cmd,
                pass_fds=(self.listen.fileno(), theirs.fileno()),
                stdin=subprocess.DEVNULL,
                start_new_session=True,  # Ctrl-C is for the runtime, which then closes the link
            )
        finally:
            theirs.close()
        send_frame(ours, {"settings": dataclasses.asdict(self.settings)})
        self._link = ours
        self._server = RpcServer(
            self.service,
            ours,
            max_blob=self.settings.max_body + 1024,
            on_ready=self._ready.set,
            on_closed=self._closed,
            thread_setup=self.thread_setup,
        )
        self._server.start()

    @property
    def ready(self) -> bool:
        return self._ready.is_set()

    @property
    def stopping(self) -> bool:
        return self._stopping

    def _closed(self, problem: BaseException | None) -> None:
        """The link closed: the process ended (or we are stopping)."""
        with self._lock:
            if self._stopping:
                return
        proc = self.proc
        code = None
        if proc is not None:
            with contextlib.suppress(subprocess.TimeoutExpired):
                code = proc.wait(5)
        self.emit(
            "api",
            f"the API process ended (exit code {code}{f', {problem}' if problem else ''}); "
            f"restarting it in {RESTART_DELAY:g} s",
            level="error",
            exit_code=code,
        )
        time.sleep(RESTART_DELAY)
        with self._lock:
            if self.stopping:  # (stop() may have come during the delay)
                return
            if self._link is not None:
                self._link.close()
            self.restarts += 1
            try:
                self._spawn()
            except OSError as exc:
                self.emit("api", f"the API process cannot be restarted: {exc}", level="error")

    def stop(self) -> None:
        """Close the link (the process then ends by itself) and reap the process."""
        with self._lock:
            self._stopping = True
        if self._link is not None:
            with contextlib.suppress(OSError):
                self._link.shutdown(socket.SHUT_RDWR)
            self._link.close()
        proc = self.proc
        if proc is not None:
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait(5)
        if self._server is not None:
            self._server.join(5)


# ---------------------------------------------------------------------------- the process


async def _serve(listen: socket.socket, link: socket.socket, settings: Any) -> None:
    import uvicorn

    from fuzzyctl.runtime.api import create_app

    reader, writer = await asyncio.open_unix_connection(sock=link)
    client = RpcClient(reader, writer)
    client.start()
    app = create_app(client, settings)
    server = uvicorn.Server(
        uvicorn.Config(
            app,
            log_level="warning",
            access_log=False,
            lifespan="off",
            ws="websockets-sansio",
            http="h11",
            limit_concurrency=settings.live_clients_max + 64,  # beyond: 503 at once
            timeout_keep_alive=5,
            h11_max_incomplete_event_size=16 * 1024,  # request line and headers
        )
    )

    async def announce() -> None:
        while not server.started:
            if server.should_exit:
                return
            await asyncio.sleep(0.01)
        await client.call("ready")
        with contextlib.suppress(OSError):
            os.nice(NICE)  # once serving (a niced start-up would be slow on a busy machine)

    async def watch_link() -> None:
        await client.closed.wait()  # the runtime stopped (or died): so do we
        server.should_exit = True

    tasks = [asyncio.create_task(announce()), asyncio.create_task(watch_link())]
    try:
        await server.serve(sockets=[listen])
    finally:
        for t in tasks:
            t.cancel()


def main(argv: list[str] | None = None) -> int:
    """``python -m fuzzyctl.runtime.apiserver LISTEN_FD LINK_FD`` (started by the runtime)."""
    from fuzzyctl.runtime.api import ApiSettings

    args = sys.argv[1:] if argv is None else argv
    listen = socket.socket(fileno=int(args[0]))
    link = socket.socket(fileno=int(args[1]))
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    with contextlib.suppress(OSError, AttributeError):  # never real-time, whoever started us
        os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))
    message, _ = recv_frame(link, 0)
    settings = ApiSettings(**message["settings"])
    link.setblocking(False)
    asyncio.run(_serve(listen, link, settings))
    return 0


if __name__ == "__main__":
    sys.exit(main())
