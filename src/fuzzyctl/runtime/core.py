"""The runtime: builds connections, links and instances from a configuration, runs the
cycle thread, the I/O event loop and the API process, and stops them cleanly.

Threads: ``fuzzyctl-cycles`` runs every instance's task (:mod:`.scheduler`);
``fuzzyctl-io`` runs an asyncio loop with one coroutine per link (:mod:`.links`);
``fuzzyctl-api-rpc`` and ``fuzzyctl-api-download`` answer the API process
(:mod:`.apiserver`, :mod:`.rpc`), which serves HTTP in a process of its own;
``fuzzyctl-events`` writes the event file.  With ``realtime_priority`` the cycle thread
runs SCHED_FIFO at that priority and the threads that answer the field and the API one
level below: a thread that holds the interpreter lock when the cycle thread wants it must
not be preempted by an ordinary process meanwhile.
"""

from __future__ import annotations

import asyncio
import contextlib
import gc
import socket
import sys
import threading
from pathlib import Path
from typing import Any

from fuzzyctl.blocks.task import CyclicTask
from fuzzyctl.diagnostics import DiagnosticError, FuzzyctlError, InputError
from fuzzyctl.io.base import Connector, LinkError, create_connector
from fuzzyctl.io.opcua import OpcUaServerPoint
from fuzzyctl.runtime.adapters import make_adapter
from fuzzyctl.runtime.config import Config, ConfigError, InstanceConfig
from fuzzyctl.runtime.events import EventLog
from fuzzyctl.runtime.instance import Instance
from fuzzyctl.runtime.kb import KnowledgeBaseSource, PreparedKB, prepare_kb, read_kb
from fuzzyctl.runtime.links import CLOSE_GRACE, Link
from fuzzyctl.runtime.scheduler import RuntimeClock, Scheduler, auto_phases, set_fifo
from fuzzyctl.webguard import LOOPBACK_NAMES

__all__ = ["Runtime", "allowed_hosts"]

KEEP_RECORDS = 1  # the task's own record list; the instance keeps its timings in a GC-free ring


class Runtime:
    """A configured soft controller.  ``start()``, then ``stop()`` (or use it as a context
    manager).  ``api=False`` runs without the HTTP server; ``event_log`` overrides the
    configured event file (None: memory only)."""

    def __init__(
        self,
        config: Config,
        *,
        api: bool | None = None,
        event_log: Path | str | None = "config",
        token: bool = True,
    ) -> None:
        self.config = config
        self.token_required = token  # False: `serve --no-token`, the API open to every local user
        if event_log == "config":
            name = config.runtime.event_log
            log_path = (config.state_dir / name) if name else None
        else:
            log_path = Path(event_log) if event_log is not None else None
        prio = config.runtime.realtime_priority
        self.events = EventLog(log_path, thread_setup=(lambda: set_fifo(prio - 1)) if prio > 1 else None)
        self.api_enabled = config.api.enabled if api is None else api
        self._stop = threading.Event()
        self.clock = RuntimeClock(self._stop, config.runtime.spin)
        self.links: dict[str, Link] = {}
        self.instances: dict[str, Instance] = {}
        try:
            self._build()
        except BaseException:
            self.events.close()
            raise
        phases = auto_phases(
            [i.config.period for i in self.instances.values()],
            [i.config.phase for i in self.instances.values()],
        )
        self.scheduler = Scheduler(
            [i.task for i in self.instances.values()],
            phases,
            self.clock,
            self._stop,
            on_cycle=[i.after_cycle for i in self.instances.values()],
            priority=config.runtime.realtime_priority,
            on_start=self._scheduler_started,
        )
        self.token: str | None = None
        self.read_token: str | None = None
        self.token_path: Path | None = None
        self.read_token_path: Path | None = None
        self.api_address: tuple[str, int] | None = None
        self.api_process: Any = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self._io_stop: asyncio.Event | None = None
        self._io_thread: threading.Thread | None = None
        self._io_ready = threading.Event()
        self._io_error: BaseException | None = None
        self._api_socket: socket.socket | None = None
        self._switch_interval = sys.getswitchinterval()
        self.started = False

    # ------------------------------------------------------------------ building

    def _build(self) -> None:
        cfg = self.config
        problems: list[str] = []
        connectors: dict[str, Connector] = {}
        for name, conn in cfg.connections.items():
            try:
                connectors[name] = create_connector(conn.type, name, conn.options)
            except (LinkError, ImportError) as exc:
                problems.append(f"{cfg.where(f'connections.{name}', 'type')}: {exc}")
                continue
            self.links[name] = Link(name, connectors[name], conn, self.events)
        for name, icfg in cfg.instances.items():
            try:
                self.instances[name] = self._build_instance(icfg)
            except ConfigError as exc:
                problems += exc.problems
        if problems:
            raise ConfigError(problems)

    def _build_instance(self, icfg: InstanceConfig) -> Instance:
        where = self.config.where
        t = icfg.table
        try:
            kb = prepare_kb(
                read_kb(icfg.knowledge_base, icfg.format),
                icfg.style,
                check_profile=icfg.check_profile,
                span_rule=icfg.span_rule,
            )
        except DiagnosticError as exc:
            raise ConfigError(
                [f"{where(t, 'knowledge_base')}: {icfg.knowledge_base}:\n{exc.render()}"]
            ) from exc
        except FuzzyctlError as exc:
            raise ConfigError([f"{where(t, 'knowledge_base')}: {exc}"]) from exc
        adapter = make_adapter(kb, icfg.style, icfg.period, icfg.span_rule)
        task = CyclicTask(icfg.period, clock=self.clock, keep=KEEP_RECORDS)
        inst = Instance(icfg, adapter, self.events, task=task)
        problems: list[str] = []
        for key, value in icfg.params.items():
            try:
                adapter.set_param(adapter.param_key(key), value)
            except InputError as exc:
                problems.append(f"{where(f'{t}.params', key)}: {exc}")
        for name, b in icfg.inputs.items():
            if b.connection not in self.links:
                continue  # a connection with its own problem, reported with it (serve --check)
            try:
                inst.bind_input(name, self.links[b.connection], self.links[b.connection].input(b.point))
            except (InputError, LinkError) as exc:
                problems.append(f"{where(f'{t}.inputs', name)}: {exc}")
        exposed_outputs: dict[str, list[tuple[Link, Any]]] = {}
        for name, bindings in icfg.outputs.items():
            if any(b.connection not in self.links for b in bindings):
                continue
            try:
                targets = [
                    (self.links[b.connection], self.links[b.connection].output(b.point)) for b in bindings
                ]
                exposed_outputs[name] = targets
            except LinkError as exc:
                problems.append(f"{where(f'{t}.outputs', name)}: {exc}")
        for name, b in icfg.parameters.items():
            if b.connection not in self.links:
                continue
            link = self.links[b.connection]
            try:
                inst.bind_param(name, link, link.input(b.point), link.mirror(b.point))
            except (InputError, LinkError) as exc:
                problems.append(f"{where(f'{t}.parameters', name)}: {exc}")
        for server_name in icfg.expose:
            if server_name not in self.links:
                continue
            try:
                self._expose(inst, self.links[server_name], exposed_outputs)
            except (InputError, LinkError) as exc:
                problems.append(f"{where(t, 'expose')}: {exc}")
        for name, targets in exposed_outputs.items():
            safes = [b.safe for b in icfg.outputs.get(name, ()) if b.safe is not None]
            try:
                inst.bind_output(name, targets, safes[0] if safes else None)
            except InputError as exc:
                problems.append(f"{where(f'{t}.outputs', name)}: {exc}")
        if problems:
            raise ConfigError(problems)
        return inst

    def _expose(self, inst: Instance, link: Link, outputs: dict[str, list[tuple[Link, Any]]]) -> None:
        """Bind every parameter of ``inst`` to nodes ``<instance>.<name>`` of an OPC UA
        server connection (docs/runtime.md, "OPC UA server")."""
        adapter = inst.adapter
        siemens = adapter.style == "siemens"
        value_type = "Float" if siemens else "Int16"
        bound_inputs = {b.key for b in inst.inputs}

        def point(name: str, vtype: str, writable: bool) -> OpcUaServerPoint:
            return OpcUaServerPoint(node=f"{inst.name}.{name}", type=vtype, writable=writable)  # type: ignore[arg-type]

        for name in adapter.kb.inputs:
            try:
                key = adapter.input_key(name)
            except InputError:
                continue
            if key not in bound_inputs:
                inst.bind_input(name, link, link.input(point(name, value_type, True)))
        out_names = list(adapter.kb.outputs) + (["INFO", "ENO"] if siemens else ["STATUS", "ERROR"])
        types = {"INFO": "Byte", "ENO": "Boolean", "STATUS": "Int16", "ERROR": "Boolean"}
        for name in out_names:
            try:
                adapter.output_key(name)
            except InputError:
                continue
            outputs.setdefault(name, []).append(
                (link, link.output(point(name, types.get(name, value_type), False)))
            )
        params = {"START_STOP": "UInt16"} if siemens else {
            "MAN_AUTO": "Boolean", "START": "Boolean", "CONT_ASK": "Boolean", "INHIB": "Boolean",
            "COMMAND": "Int16", "T_OFB": "Int16",
        }  # fmt: skip
        bound_params = {p.key for p in inst.params}
        for name, vtype in params.items():
            if name not in bound_params:
                p = point(name, vtype, True)
                inst.bind_param(name, link, link.input(p), link.mirror(p))

    # ------------------------------------------------------------------ running

    def start(self) -> None:
        """Start the I/O loop (links, API) and the cycle thread."""
        if self.started:
            raise FuzzyctlError("the runtime is already started")
        api = self.config.api
        if self.api_enabled:
            from fuzzyctl.runtime.token import load_or_create_token

            if self.token_required:
                self.token_path = self._state_file(api.token_file)
                self.read_token_path = self._state_file(api.read_token_file)
                self.token = load_or_create_token(self.token_path)
                self.read_token = load_or_create_token(self.read_token_path)
            sock = socket.socket(socket.AF_INET6 if ":" in api.host else socket.AF_INET, socket.SOCK_STREAM)
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            try:
                sock.bind((api.host, api.port))
            except OSError as exc:
                sock.close()
                raise FuzzyctlError(
                    f"{self.config.where('api', 'port')}: cannot listen on {api.host}:{api.port}: "
                    f"{exc.strerror or exc}"
                ) from exc
            sock.listen(64)
            sock.setblocking(False)
            self._api_socket = sock
            self.api_address = sock.getsockname()[:2]
            # Started first: its imports take seconds, they overlap with the rest of the start.
            self._start_api(sock)
        self.started = True
        self.events.emit(
            "runtime-start",
            f"runtime started: {len(self.instances)} instance(s), {len(self.links)} connection(s)"
            + (f", API on http://{self.api_address[0]}:{self.api_address[1]}" if self.api_address else ""),
            config=str(self.config.path),
            instances=list(self.instances),
            connections=list(self.links),
            api=None if self.api_address is None else list(self.api_address),
        )
        self._io_thread = threading.Thread(target=self._io_main, name="fuzzyctl-io", daemon=True)
        self._io_thread.start()
        self._io_ready.wait(30)
        if self._io_error is not None:
            raise FuzzyctlError(f"the I/O loop failed to start: {self._io_error}")
        if self.api_process is not None:
            try:
                self.api_process.wait_ready()
            except BaseException:
                self.stop()
                raise
        sys.setswitchinterval(self.config.runtime.switch_interval)
        gc.collect()
        gc.freeze()  # startup objects out of the collector's way: shorter pauses in the cycle thread
        self.scheduler.start()

    def _state_file(self, name: str) -> Path:
        path = Path(name).expanduser()
        return path if path.is_absolute() else self.config.state_dir / path

    def _start_api(self, sock: socket.socket) -> None:
        from fuzzyctl.runtime.api import ApiSettings
        from fuzzyctl.runtime.apiserver import ApiProcess
        from fuzzyctl.runtime.service import Service

        api = self.config.api
        assert self.token is not None or not self.token_required
        settings = ApiSettings(
            token=self.token,
            read_token=self.read_token,
            hosts=allowed_hosts(api.host, api.allowed_hosts),
            origins=list(api.allowed_origins),
            max_body=api.max_body,
            live_rate_max=api.live_rate_max,
            live_clients_max=api.live_clients_max,
            docs=api.docs,
        )
        prio = self.config.runtime.realtime_priority

        def below_cycles() -> None:
            if prio > 1:
                set_fifo(prio - 1)

        self.api_process = ApiProcess(
            Service(self), sock, settings, emit=self.events.emit, thread_setup=below_cycles
        )
        self.api_process.start(wait=False)

    def _scheduler_started(self, problem: str | None) -> None:
        if problem is not None:
            self.events.emit(
                "realtime", f"cycle thread: {problem}; running at normal priority", level="warning"
            )
        elif self.config.runtime.realtime_priority:
            self.events.emit(
                "realtime",
                f"cycle thread at SCHED_FIFO priority {self.config.runtime.realtime_priority}",
                priority=self.config.runtime.realtime_priority,
            )

    def _io_main(self) -> None:
        try:
            asyncio.run(self._io())
        except BaseException as exc:
            self._io_error = exc
            self._io_ready.set()

    async def _io(self) -> None:
        prio = self.config.runtime.realtime_priority
        if prio > 1:
            # The I/O thread holds the GIL the cycle thread needs: if the OS preempted it for
            # another process while it holds the GIL, the raised cycle thread would wait anyway.
            set_fifo(prio - 1)
        self._loop = asyncio.get_running_loop()
        self._io_stop = asyncio.Event()
        link_tasks = [
            asyncio.create_task(link.run(self._io_stop), name=f"link-{n}") for n, link in self.links.items()
        ]
        self._io_ready.set()
        await self._io_stop.wait()
        # Each link writes its safe values and closes by its stop_by; all in parallel, so a
        # dead peer costs its own stop_timeout once, not once per link after it.
        await asyncio.gather(
            *(link.stopped(task) for link, task in zip(self.links.values(), link_tasks, strict=True)),
            return_exceptions=True,
        )

    def _begin_io_stop(self) -> None:
        """On the I/O loop, between two of its steps (no exchange runs meanwhile): every
        link's stop deadline (from here only the stop write writes outputs), every
        instance's safe values into the cells, then the stop event."""
        assert self._loop is not None and self._io_stop is not None
        try:
            now = self._loop.time()
            for link in self.links.values():
                link.stop_by = now + link.config.stop_timeout
            t = self.clock.now()
            for inst in self.instances.values():
                try:
                    inst.stop_safe(t)
                except Exception as exc:  # one instance's bug must not keep the others from the field
                    self.events.emit(
                        "error", f"{inst.name}: at stop: {type(exc).__name__}: {exc}", level="error"
                    )
        finally:
            self._io_stop.set()

    def stop_bound(self) -> float:
        """Seconds the field writes of a stop may take at most: the largest
        ``stop_timeout`` (the links write in parallel) and the closing grace."""
        return max((lk.config.stop_timeout for lk in self.links.values()), default=0.0) + 3 * CLOSE_GRACE

    def call_io(self, coro: Any, timeout: float = 10.0) -> Any:
        """Run a coroutine on the I/O loop from another thread and wait for its result."""
        if self._loop is None:
            raise FuzzyctlError("the runtime is not started")
        return asyncio.run_coroutine_threadsafe(coro, self._loop).result(timeout)

    def stop(self) -> None:
        """Stop the API and the cycles, put every instance's safe values (and safe INFO)
        into its output cells, have every link write them and close (each within its
        ``stop_timeout``), flush the event log (docs/runtime.md, "Stopping")."""
        if not self.started:
            self.events.close()
            return
        if self.api_process is not None:
            self.api_process.stop()  # first: no request reaches a runtime that is stopping
            self.api_process = None
        self._stop.set()
        self.scheduler.join(10)
        if self._loop is not None and self._io_stop is not None:
            self._loop.call_soon_threadsafe(self._begin_io_stop)
        if self._io_thread is not None:
            self._io_thread.join(self.stop_bound() + 1.0)
        if self._api_socket is not None:
            self._api_socket.close()
        sys.setswitchinterval(self._switch_interval)
        gc.unfreeze()
        self.events.emit(
            "runtime-stop",
            "runtime stopped",
            cycles={n: i.task.stats.count for n, i in self.instances.items()},
        )
        self.events.close()
        self.started = False

    def __enter__(self) -> Runtime:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    # ------------------------------------------------------------------ operations

    def instance(self, name: str) -> Instance:
        try:
            return self.instances[name]
        except KeyError:
            raise InputError(f"no instance {name!r} (instances: {', '.join(self.instances)})") from None

    def prepare_download(self, name: str, text: str, format: str = "fcl", origin: str = "api") -> PreparedKB:
        """Parse, check and build a knowledge base for instance ``name`` (raises
        DiagnosticError or FuzzyctlError when it cannot be used)."""
        from fuzzyctl import formats

        inst = self.instance(name)
        formats.get(format)  # an unknown format is reported as such
        kb = prepare_kb(
            KnowledgeBaseSource(text, format, origin),
            inst.config.style,
            check_profile=inst.config.check_profile,
            span_rule=inst.config.span_rule,
        )
        inst.check_download(kb)
        return kb

    def download(self, name: str, text: str, format: str = "fcl", origin: str = "api") -> dict[str, Any]:
        """Replace the knowledge base of a running instance (prepared first, then switched
        between two cycles); logged as ``download`` (or ``download-refused``)."""
        try:
            kb = self.prepare_download(name, text, format, origin)
        except FuzzyctlError as exc:
            if isinstance(exc, DiagnosticError):
                # Places and messages, no source excerpts: rendering those splits the whole
                # (possibly megabytes of) text once per diagnostic, holding the interpreter.
                shown = [
                    f"{d.location()}: {d.severity.value}: {d.message[:300]}" for d in exc.diagnostics[:20]
                ]
                more = len(exc.diagnostics) - len(shown)
                detail = "\n".join(shown + ([f"... {more} more"] if more > 0 else []))
            else:
                detail = str(exc)
            self.events.emit(
                "download-refused",
                f"{name}: download refused: {detail.splitlines()[0] if detail else exc}",
                level="error",
                instance=name if name in self.instances else None,
                format=format,
                origin=origin,
                error=detail[:4000],
            )
            raise
        return self.instances[name].download(kb, source=origin)

    def links_state(self) -> dict[str, dict[str, Any]]:
        out = {}
        for name, link in self.links.items():
            c = link.counters
            out[name] = {
                "type": link.config.type,
                "endpoint": link.connector.endpoint(),
                "state": link.state.value,
                "exchanges": c.exchanges,
                "failures": c.failures,
                "connects": c.connects,
                "last_exchange_ms": round(c.last_exchange_ms, 3),
                "last_error": c.last_error,
                "points": len(link.points),
            }
        return out


def allowed_hosts(bind: str, extra: list[str]) -> list[str] | None:
    """The names the API answers to in the Host header (docs/runtime.md, "Security"):
    loopback, the bound address, and ``extra``; bound to every interface (0.0.0.0, ::),
    also this machine's name and its addresses.  ``["*"]`` in ``extra``: any (None)."""
    if "*" in extra:
        return None
    names = set(LOOPBACK_NAMES) | {h.lower().strip("[]") for h in extra}
    if bind in ("0.0.0.0", "::", ""):
        for name in {socket.gethostname(), socket.getfqdn()}:
            names.add(name.lower())
            with contextlib.suppress(OSError):
                names.update(str(info[4][0]).lower() for info in socket.getaddrinfo(name, None))
    else:
        names.add(bind.lower().strip("[]"))
    return sorted(names)


def check_config(path: str | Path) -> tuple[Config | None, list[str]]:
    """Every problem of a configuration file in one pass (``fuzzyctl serve --check``): its
    tables, then the instances that could be built from the valid tables (knowledge bases,
    bindings against them); nothing is started."""
    from fuzzyctl.runtime.config import load_config

    try:
        config = load_config(path, partial=True)
    except ConfigError as exc:  # not readable or not TOML
        return None, exc.problems
    problems = list(config.problems)
    try:
        Runtime(config, api=False, event_log=None).stop()
    except ConfigError as exc:
        problems += [p for p in exc.problems if p not in problems]
    return config, problems
