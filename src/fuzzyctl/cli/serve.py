"""``fuzzyctl serve CONFIG.toml``: run the soft controller (docs/runtime.md)."""

from __future__ import annotations

import os
import signal
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Annotated, Any

import typer

from fuzzyctl.cli.app import app, err_console


@app.command()
def serve(
    config: Annotated[Path, typer.Argument(help="the runtime configuration (TOML)", show_default=False)],
    api: Annotated[bool, typer.Option("--api/--no-api", help="serve the HTTP/WebSocket API")] = True,
    table: Annotated[
        bool, typer.Option("--table/--no-table", help="live table (on a terminal); else one line per event")
    ] = True,
    duration: Annotated[
        float | None, typer.Option("--duration", min=0, help="stop after this many seconds")
    ] = None,
    check: Annotated[bool, typer.Option("--check", help="check the configuration and exit")] = False,
    no_token: Annotated[
        bool,
        typer.Option(
            "--no-token",
            help="the API without a token: any program or user that reaches it can command the instances",
        ),
    ] = False,
) -> None:
    """Run fuzzy function blocks cyclically against field I/O (OPC UA, Modbus TCP, S7)."""
    from rich.console import Console

    from fuzzyctl.runtime import Runtime, load_config
    from fuzzyctl.runtime.display import api_banner

    if check:
        from fuzzyctl.runtime.capacity import check as check_file

        summary, warnings = check_file(config)
        typer.echo(summary)
        for text in warnings:
            err_console.print(f"warning: {text}", markup=False)
        return
    cfg = load_config(config)
    runtime = Runtime(cfg, api=api and cfg.api.enabled, token=not no_token)
    stop = threading.Event()
    console = Console(highlight=False)
    last: int | None = None
    with _signals_set(stop):
        try:
            runtime.start()
            _realtime(cfg.runtime.realtime_priority)
            if runtime.api_address is not None:
                line, warnings = api_banner(runtime, cfg.api.docs)
                err_console.print(line, markup=False)
                for text in warnings:
                    err_console.print(f"warning: {text}", markup=False)
            deadline = None if duration is None else time.monotonic() + duration
            last = _run(runtime, console, stop, deadline, table and console.is_terminal)
        except KeyboardInterrupt:
            last = None
        finally:
            stop.set()  # from here a signal means "exit at once"
            _stop(runtime)
    if last is not None:
        _print_events(runtime, last)
    if runtime.scheduler.error is not None:
        raise RuntimeError(f"the cycle thread failed: {runtime.scheduler.error}")


@contextmanager
def _signals_set(stop: threading.Event) -> Iterator[None]:
    """SIGTERM and SIGINT set ``stop``; a second one while stopping exits at once.  The
    previous handlers come back on leaving."""

    def on_signal(signum: int, _frame: Any) -> None:
        if stop.is_set():
            # A second SIGINT/SIGTERM while stopping: at once, without waiting for the links.
            err_console.print("stopped at once: the safe values may not all be written", markup=False)
            sys.stderr.flush()
            os._exit(128 + signum)
        stop.set()

    previous = {s: signal.signal(s, on_signal) for s in (signal.SIGTERM, signal.SIGINT)}
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def _realtime(prio: int) -> None:
    if prio > 1:
        # This thread draws the table and holds the interpreter lock meanwhile: an ordinary
        # process must not preempt it then, the cycle thread would wait (docs/runtime.md).
        from fuzzyctl.runtime.scheduler import set_fifo

        set_fifo(prio - 1)


def _stop(runtime: Any) -> None:
    if runtime.started and runtime.links:
        err_console.print(
            f"stopping: safe values to the field (at most {runtime.stop_bound():.3g} s; "
            "Ctrl-C again to exit at once)",
            markup=False,
        )
    runtime.stop()


def _print_events(runtime: Any, after: int) -> int:
    for e in runtime.events.since(after):
        after = e.seq
        print(f"{e.time} {e.level:<7} {e.kind:<16} {e.message}", file=sys.stdout, flush=True)
    return after


def _run(
    runtime: Any, console: Any, stop: threading.Event, deadline: float | None, live_table: bool
) -> int | None:
    """Show the runtime until a signal, the deadline, or the cycle thread ends; returns the
    last event printed (None with the live table)."""

    def remaining() -> float:
        return 0.25 if deadline is None else max(0.0, min(0.25, deadline - time.monotonic()))

    def done() -> bool:
        return (
            stop.is_set()
            or (deadline is not None and time.monotonic() >= deadline)
            or not runtime.scheduler.alive
        )

    if live_table:
        from rich.live import Live

        from fuzzyctl.runtime.display import render

        with Live(render(runtime), console=console, refresh_per_second=4, screen=False) as live:
            while not done():
                stop.wait(remaining())
                live.update(render(runtime))
        return None
    last = 0
    while True:
        last = _print_events(runtime, last)
        if done():
            return last
        stop.wait(remaining())
