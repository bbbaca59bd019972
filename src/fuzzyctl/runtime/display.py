"""The live terminal view of ``fuzzyctl serve``: one table of instances (period, state,
last cycle time, jitter, INFO/STATUS, cycles, overruns, link states), one of connections,
and the latest events."""

from __future__ import annotations

from typing import TYPE_CHECKING

from rich.console import Group
from rich.table import Table
from rich.text import Text

if TYPE_CHECKING:
    from fuzzyctl.runtime.core import Runtime

__all__ = ["render"]

_STATE_STYLE = {"run": "green", "hold": "yellow", "safe": "bold red"}
_LINK_STYLE = {"up": "green", "down": "bold red", "closed": "dim"}
_LEVEL_STYLE = {"info": "", "warning": "yellow", "error": "red"}


def _ms(seconds: float | None) -> str:
    return "-" if seconds is None else f"{seconds * 1e3:.3f}"


def _status_text(status: dict[str, int]) -> str:
    if "INFO" in status:
        return f"INFO {status['INFO']:02X}"
    return f"STATUS {status['STATUS'] & 0xFFFF:04X}" + (" ERROR" if status.get("ERROR") else "")


def render(runtime: Runtime, *, events: int = 8, max_instances: int = 40) -> Group:
    """A renderable of the runtime's current state (for ``rich.live.Live``)."""
    inst_table = Table(title="instances", expand=True, header_style="bold")
    for col, justify in (
        ("instance", "left"),
        ("style", "left"),
        ("period ms", "right"),
        ("state", "left"),
        ("last cycle ms", "right"),
        ("jitter p99 ms", "right"),
        ("INFO/STATUS", "left"),
        ("cycles", "right"),
        ("overruns", "right"),
        ("links", "left"),
    ):
        inst_table.add_column(col, justify=justify, overflow="fold")  # type: ignore[arg-type]
    shown = list(runtime.instances.values())
    for inst in shown[:max_instances]:
        s = inst.snapshot()
        st = inst.statistics()
        links = Text()
        for i, (name, state) in enumerate(s["links"].items()):
            if i:
                links.append(" ")
            links.append(f"{name}:{state}", style=_LINK_STYLE.get(state, ""))
        state = s["state"] + (" !" if s["error"] else "")
        inst_table.add_row(
            s["name"],
            s["style"],
            f"{s['period'] * 1e3:g}",
            Text(state, style=_STATE_STYLE.get(s["state"], "")),
            _ms(s["last_cycle"]["duration"] if s["last_cycle"] else None),
            _ms(st["jitter_p99"]),
            _status_text(s["status"]),
            str(s["cycles"]),
            Text(str(s["overruns"]), style="red" if s["overruns"] else ""),
            links,
        )
    if len(shown) > max_instances:
        inst_table.caption = f"{len(shown) - max_instances} more instance(s) not shown"

    link_table = Table(title="connections", expand=True, header_style="bold")
    for col in ("connection", "type", "endpoint", "state", "exchange ms", "failures", "last error"):
        link_table.add_column(col, overflow="fold")
    for name, info in runtime.links_state().items():
        link_table.add_row(
            name,
            info["type"],
            info["endpoint"],
            Text(info["state"], style=_LINK_STYLE.get(info["state"], "")),
            f"{info['last_exchange_ms']:.2f}",
            str(info["failures"]),
            info["last_error"] or "",
        )

    log = Text()
    for e in runtime.events.since(max(0, runtime.events.last_seq - events)):
        log.append(f"{e.seq:>6} {e.time[11:23]} {e.kind:<16} ", style="dim")
        log.append(e.message + "\n", style=_LEVEL_STYLE.get(e.level, ""))
    return Group(inst_table, link_table, Text("events", style="bold"), log)


def api_banner(runtime: Runtime, docs: bool) -> tuple[str, list[str]]:
    """What ``fuzzyctl serve`` says about its API once it listens: where, where the tokens
    are, and the warnings (no token; Swagger UI loaded from a CDN)."""
    assert runtime.api_address is not None
    host, port = runtime.api_address
    where_docs = " (docs: /api/v1/docs)" if docs else ""
    tokens = (
        f"token in {runtime.token_path}, read-only token in {runtime.read_token_path}"
        if runtime.token_required
        else "no token"
    )
    warnings = []
    if not runtime.token_required:
        where = "on this machine" if host in ("127.0.0.1", "::1") else f"that reaches {host}"
        warnings.append(
            f"--no-token: any program or user {where} can read and command the instances through the API"
        )
    if docs:
        warnings.append(
            "[api] docs = true: /api/v1/docs loads Swagger UI from a CDN "
            "(third-party code in the page where the token is typed)"
        )
    return f"API on http://{host}:{port}/api/v1{where_docs}; {tokens}", warnings
