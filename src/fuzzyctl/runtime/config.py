"""The configuration of ``fuzzyctl serve``: a TOML file with ``[runtime]``, ``[api]``,
``[connections.<name>]`` and ``[instances.<name>]`` tables (docs/runtime.md has the
reference).

Loading checks the whole file before anything starts and reports every problem at once,
each naming the file, the table and the key (``plant.toml: [instances.tank.inputs.level]
offset: Input should be greater than or equal to 0``).  Addresses are checked by the
protocol module of the connection they refer to.  What needs the knowledge base (are the
bound names inputs of the controller?) is checked when the instances are built
(:mod:`fuzzyctl.runtime.instance`), with the same message format.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.io.base import CONNECTION_TYPES, Point, connector_class

__all__ = [
    "ApiConfig",
    "BindingConfig",
    "Config",
    "ConfigError",
    "ConnectionConfig",
    "InstanceConfig",
    "RuntimeConfig",
    "load_config",
    "parse_config",
]

MIN_PERIOD, MAX_PERIOD = 0.001, 60.0


class ConfigError(FuzzyctlError):
    """The configuration is not valid; ``problems`` holds one line per finding."""

    def __init__(self, problems: Sequence[str]) -> None:
        self.problems = list(problems)
        super().__init__("\n".join(self.problems))


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class RuntimeConfig(_Strict):
    state_dir: str | None = Field(
        default=None, description="token and event log directory (default ~/.local/state/fuzzyctl)"
    )
    event_log: str = Field(
        default="events.jsonl", description="JSON-lines event file in state_dir; '' for none"
    )
    switch_interval: float = Field(
        default=0.0005, gt=0, le=0.1, description="Python thread switch interval (s)"
    )
    spin: float = Field(default=0.0, ge=0, le=0.005, description="busy-wait before each release (s)")
    realtime_priority: int = Field(
        default=0, ge=0, le=99, description="SCHED_FIFO priority of the cycle thread (Linux; 0: normal)"
    )


class ApiConfig(_Strict):
    enabled: bool = True
    host: str = "127.0.0.1"
    port: int = Field(default=8765, ge=0, le=65535)
    token_file: str = Field(default="api-token", description="in state_dir unless absolute")
    read_token_file: str = Field(
        default="api-token-read", description="the read-only token, in state_dir unless absolute"
    )
    allowed_hosts: list[str] = Field(
        default_factory=list,
        description="more names clients may use in the Host header (besides loopback and the bound "
        'address); ["*"] accepts any (no DNS-rebinding protection)',
    )
    allowed_origins: list[str] = Field(
        default_factory=list, description='browser origins allowed, e.g. "http://scada.local:8080"'
    )
    max_body: int = Field(
        default=8 * 1024 * 1024,
        ge=64 * 1024,
        le=64 * 1024 * 1024,
        description="bytes of a knowledge-base upload, at most (other bodies: 64 KiB)",
    )
    live_rate_max: float = Field(
        default=20.0, gt=0, le=20.0, description="WebSocket updates per second, at most"
    )
    live_clients_max: int = Field(default=8, ge=1, le=256, description="WebSocket clients at once")
    docs: bool = Field(
        default=False,
        description="serve the API description as a page at /api/v1/docs (Swagger UI, whose scripts "
        "come from a CDN: third-party code in the page where the token is typed); "
        "/api/v1/openapi.json is always served",
    )


class ConnectionConfig(_Strict):
    """The runtime's own keys of a ``[connections.<name>]`` table; the others are the
    protocol's options."""

    type: str
    poll_interval: float = Field(default=0.01, ge=0.001, le=60)
    deadline: float | None = Field(
        default=None,
        gt=0,
        le=600,
        description="seconds without a complete exchange after which the instances using the "
        "connection hold (a frozen peer); default max(0.25, 10 x poll_interval)",
    )
    reconnect_min: float = Field(default=0.1, gt=0, le=60)
    reconnect_max: float = Field(default=5.0, gt=0, le=600)
    stop_timeout: float = Field(
        default=1.0,
        ge=0,
        le=60,
        description="seconds the connection may take, when the runtime stops, to write the safe "
        "values (connecting first when it is down) and close; 0: nothing is written at stop",
    )
    options: dict[str, Any] = Field(default_factory=dict)

    @property
    def effective_deadline(self) -> float:
        return self.deadline if self.deadline is not None else max(0.25, 10 * self.poll_interval)


class BindingConfig(_Strict):
    """One binding: the connection it uses, the address, and for outputs the safe value."""

    connection: str
    point: Point
    safe: float | None = None


@dataclass(frozen=True)
class InstanceConfig:
    name: str
    style: Literal["siemens", "xfuz"]
    knowledge_base: Path
    format: str | None
    period: float
    phase: float | None
    hold_time: float
    check_profile: bool
    span_rule: bool
    params: dict[str, float]
    inputs: dict[str, BindingConfig]
    outputs: dict[str, tuple[BindingConfig, ...]]
    parameters: dict[str, BindingConfig]
    expose: tuple[str, ...]
    table: str = ""


class _InstanceTable(_Strict):
    style: Literal["siemens", "xfuz"] = "siemens"
    knowledge_base: str = Field(min_length=1)
    format: str | None = None
    period: float = Field(ge=MIN_PERIOD, le=MAX_PERIOD, description="seconds, 0.001 .. 60")
    phase: float | Literal["auto"] = "auto"
    hold_time: float = Field(default=1.0, ge=0, le=3600)
    check_profile: bool = True
    span_rule: bool = True
    params: dict[str, float] = Field(default_factory=dict)
    inputs: dict[str, dict[str, Any]] = Field(default_factory=dict)
    outputs: dict[str, dict[str, Any] | list[dict[str, Any]]] = Field(default_factory=dict)
    parameters: dict[str, dict[str, Any]] = Field(default_factory=dict)
    expose: list[str] = Field(default_factory=list)

    @field_validator("phase")
    @classmethod
    def _phase(cls, v: float | str) -> float | str:
        if isinstance(v, float | int) and not (v >= 0 and math.isfinite(v)):
            raise ValueError("phase is a non-negative number of seconds or 'auto'")
        return v


class _File(_Strict):
    runtime: dict[str, Any] = Field(default_factory=dict)
    api: dict[str, Any] = Field(default_factory=dict)
    connections: dict[str, dict[str, Any]] = Field(default_factory=dict)
    instances: dict[str, dict[str, Any]] = Field(default_factory=dict)


@dataclass(frozen=True)
class Config:
    """A validated configuration.  Paths are absolute (relative ones are resolved against
    the configuration file's directory)."""

    path: Path
    runtime: RuntimeConfig
    api: ApiConfig
    connections: dict[str, ConnectionConfig]
    instances: dict[str, InstanceConfig]
    state_dir: Path = field(default_factory=Path)
    #: with ``partial=True``: what was wrong (the rest of the file is here, valid)
    problems: tuple[str, ...] = ()

    def where(self, table: str, key: str | None = None) -> str:
        return _where(self.path, table, key)


def _where(path: Path | str, table: str, key: str | None = None) -> str:
    return f"{path}: [{table}]" + (f" {key}" if key else "")


def _pydantic_problems(path: Path | str, table: str, exc: ValidationError) -> list[str]:
    """One line per pydantic error: the deepest table of the location, then the key."""
    out = []
    for err in exc.errors():
        loc = [str(x) for x in err["loc"]]
        if err["type"] == "extra_forbidden":
            msg = "unknown key"
        elif err["type"] == "missing":
            msg = "required key is missing"
        else:
            msg = err["msg"]
        where_table = ".".join([table, *loc[:-1]]) if table else ".".join(loc[:-1])
        key = loc[-1] if loc else None
        out.append(f"{_where(path, where_table or '(top level)', key)}: {msg}")
    return out


def _binding(
    spec: Mapping[str, Any],
    where: str,
    output: bool,
    path: Path,
    conns: dict[str, str],
    problems: list[str],
) -> BindingConfig | None:
    """Check one binding table; its address by the protocol of its connection."""
    spec = dict(spec)
    conn_name = spec.pop("connection", None)
    safe = spec.pop("safe", None) if output else None
    if conn_name is None:
        problems.append(f"{_where(path, where, 'connection')}: required key is missing")
        return None
    if conn_name not in conns:
        known = ", ".join(conns) or "none defined"
        problems.append(f"{_where(path, where, 'connection')}: no connection {conn_name!r} ({known})")
        return None
    if safe is not None and (
        isinstance(safe, bool) or not isinstance(safe, int | float) or not math.isfinite(safe)
    ):
        problems.append(f"{_where(path, where, 'safe')}: a safe value is a finite number")
        return None
    try:
        point = connector_class(conns[conn_name]).point_model.model_validate(spec)
    except ValidationError as exc:
        problems.extend(_pydantic_problems(path, where, exc))
        return None
    return BindingConfig(connection=conn_name, point=point, safe=None if safe is None else float(safe))


def load_config(path: str | Path, *, partial: bool = False) -> Config:
    """Read and validate a configuration file; raises :class:`ConfigError` (``partial``: see
    :func:`parse_config`)."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ConfigError([f"{path}: cannot read: {exc.strerror or exc}"]) from exc
    return parse_config(text, path, partial=partial)


def parse_config(text: str, path: str | Path = "<config>", *, partial: bool = False) -> Config:
    """Validate configuration text (``path`` names it in messages and anchors relative
    paths).  ``partial=True`` (``serve --check``) never raises for a problem of one table:
    the Config holds every valid table and ``problems`` lists the rest, so that every
    problem of a file is reported in one pass."""
    path = Path(path)
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError([f"{path}: not valid TOML: {exc}"]) from exc
    problems: list[str] = []
    for key in raw:
        if key not in _File.model_fields:
            problems.append(f"{_where(path, '(top level)', key)}: unknown table")
    runtime_cfg, api_cfg = RuntimeConfig(), ApiConfig()
    try:
        runtime_cfg = RuntimeConfig.model_validate(raw.get("runtime", {}))
    except ValidationError as exc:
        problems.extend(_pydantic_problems(path, "runtime", exc))
    try:
        api_cfg = ApiConfig.model_validate(raw.get("api", {}))
    except ValidationError as exc:
        problems.extend(_pydantic_problems(path, "api", exc))
    try:
        top = _File.model_validate(
            {"connections": raw.get("connections", {}), "instances": raw.get("instances", {})}
        )
    except ValidationError as exc:
        problems += _pydantic_problems(path, "", exc)
        if not partial:
            raise ConfigError(problems) from exc
        return Config(path, runtime_cfg, api_cfg, {}, {}, problems=tuple(problems))
    base = path.resolve().parent

    connections: dict[str, ConnectionConfig] = {}
    # name -> type of every connection with a known type, valid or not: bindings are
    # checked against it, so that one bad connection does not make every binding an error
    declared: dict[str, str] = {
        n: t["type"] for n, t in top.connections.items() if t.get("type") in CONNECTION_TYPES
    }
    for name, table in top.connections.items():
        tname = f"connections.{name}"
        own = {k: v for k, v in table.items() if k in ConnectionConfig.model_fields and k != "options"}
        rest = {k: v for k, v in table.items() if k not in own}
        kind = own.get("type")
        if kind not in CONNECTION_TYPES:
            problems.append(
                f"{_where(path, tname, 'type')}: "
                + ("required key is missing" if kind is None else f"unknown connection type {kind!r}")
                + f" (one of {', '.join(CONNECTION_TYPES)})"
            )
            continue
        try:
            conn = ConnectionConfig.model_validate({**own, "options": rest})
            connector_class(kind).options_model.model_validate(rest)
        except ValidationError as exc:
            problems.extend(_pydantic_problems(path, tname, exc))
            continue
        if conn.reconnect_max < conn.reconnect_min:
            problems.append(f"{_where(path, tname, 'reconnect_max')}: must be >= reconnect_min")
        connections[name] = conn

    instances: dict[str, InstanceConfig] = {}
    for name, table in top.instances.items():
        tname = f"instances.{name}"
        if not name.replace("_", "").replace("-", "").isalnum():
            problems.append(f"{_where(path, tname)}: an instance name is letters, digits, '_' and '-'")
            continue
        try:
            t = _InstanceTable.model_validate(table)
        except ValidationError as exc:
            problems.extend(_pydantic_problems(path, tname, exc))
            continue
        n_before = len(problems)

        def binding(spec: Mapping[str, Any], where: str, output: bool) -> BindingConfig | None:
            return _binding(spec, where, output, path, declared, problems)

        inputs: dict[str, BindingConfig] = {}
        for key, spec in t.inputs.items():
            b = binding(spec, f"{tname}.inputs.{key}", False)
            if b:
                inputs[key] = b
        outputs: dict[str, tuple[BindingConfig, ...]] = {}
        for key, specs in t.outputs.items():
            many = specs if isinstance(specs, list) else [specs]
            bs = [
                binding(s, f"{tname}.outputs.{key}" + (f"[{i}]" if isinstance(specs, list) else ""), True)
                for i, s in enumerate(many)
            ]
            if all(bs):
                safes = {b.safe for b in bs if b and b.safe is not None}
                if len(safes) > 1:
                    problems.append(
                        f"{_where(path, f'{tname}.outputs.{key}', 'safe')}: differing safe values"
                    )
                outputs[key] = tuple(b for b in bs if b)
        parameters: dict[str, BindingConfig] = {}
        for key, spec in t.parameters.items():
            b = binding(spec, f"{tname}.parameters.{key}", False)
            if b:
                parameters[key] = b
        for i, conn_name in enumerate(t.expose):
            exposed = connections.get(conn_name)
            if exposed is None or exposed.type != "opcua-server":
                problems.append(
                    f"{_where(path, tname, f'expose[{i}]')}: {conn_name!r} is not an opcua-server connection"
                )
        if len(problems) > n_before and not partial:  # partial: check what is valid of it
            continue
        kb = Path(t.knowledge_base)
        instances[name] = InstanceConfig(
            name=name,
            style=t.style,
            knowledge_base=kb if kb.is_absolute() else base / kb,
            format=t.format,
            period=t.period,
            phase=None if t.phase == "auto" else float(t.phase),
            hold_time=t.hold_time,
            check_profile=t.check_profile,
            span_rule=t.span_rule,
            params=dict(t.params),
            inputs=inputs,
            outputs=outputs,
            parameters=parameters,
            expose=tuple(t.expose),
            table=tname,
        )
    if not top.instances:
        problems.append(f"{path}: no [instances.<name>] table: nothing to run")
    if problems and not partial:
        raise ConfigError(problems)
    if runtime_cfg.state_dir is None:
        state_dir = Path.home() / ".local" / "state" / "fuzzyctl"
    else:
        sd = Path(runtime_cfg.state_dir).expanduser()
        state_dir = sd if sd.is_absolute() else base / sd
    return Config(path, runtime_cfg, api_cfg, connections, instances, state_dir, problems=tuple(problems))
