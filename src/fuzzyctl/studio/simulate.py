"""The simulated process of the curve recorder (issue 9): a loop configuration from the
project directory (``examples/crane.toml`` and friends, docs/sim.md) run with the
knowledge base being edited, stepped by the browser.

A session holds one :class:`~fuzzyctl.sim.Loop`; the browser asks for the next stretch of
cycles and draws them.  Sessions live in memory, a few at a time.
"""

from __future__ import annotations

import math
import secrets
import threading
import time
from collections import OrderedDict
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from fuzzyctl.diagnostics import FuzzyctlError, InputError
from fuzzyctl.model import Document, FunctionBlock

MAX_SESSIONS = 8
MAX_CYCLES_PER_STEP = 20000


@dataclass
class SimSession:
    loop: Any
    config: Any
    created: float = field(default_factory=time.monotonic)
    lock: threading.Lock = field(default_factory=threading.Lock)


def describe_configs(root: Path, files: list[str], current: str | None) -> list[dict[str, Any]]:
    """The loop configurations among ``files`` (TOML with a ``[plant]`` table) with what
    the recorder needs to offer them: plant, parameters, setpoints, fuzzy inputs."""
    import tomllib

    from fuzzyctl.sim import make_plant

    out = []
    for rel in files:
        if not rel.endswith(".toml"):
            continue
        path = root / rel
        try:
            data = tomllib.loads(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
            continue
        plant_table = data.get("plant")
        controller = data.get("controller", {})
        if not isinstance(plant_table, dict) or not isinstance(plant_table.get("model"), str):
            continue
        try:
            plant = make_plant(plant_table["model"], {k: v for k, v in plant_table.items() if k != "model"})
        except (InputError, TypeError, ValueError):
            continue
        file = controller.get("file") if isinstance(controller, dict) else None
        target = (path.parent / str(file)).resolve() if isinstance(file, str) else None
        setpoints = data.get("setpoints", {})
        out.append(
            {
                "path": rel,
                "title": str(data.get("title", path.stem)),
                "plant": plant.kind,
                "structure": controller.get("structure", "direct") if isinstance(controller, dict) else None,
                "controller_file": (
                    target.relative_to(root).as_posix()
                    if target is not None and target.is_relative_to(root)
                    else None
                ),
                "matches": current is not None
                and target is not None
                and target == (root / current).resolve(),
                "duration": data.get("duration", 60),
                "parameters": [
                    {
                        "name": p.name,
                        "value": plant_table.get(p.name, p.default),
                        "default": p.default,
                        "unit": p.unit,
                        "doc": p.doc,
                    }
                    for p in plant.parameters()
                    if isinstance(p.default, int | float) and math.isfinite(p.default)
                ],
                "setpoints": {k: v for k, v in setpoints.items() if isinstance(v, int | float)}
                if isinstance(setpoints, dict)
                else {},
                "inputs": controller.get("inputs", {}) if isinstance(controller, dict) else {},
                "outputs": controller.get("outputs", {}) if isinstance(controller, dict) else {},
            }
        )
    out.sort(key=lambda c: (not c["matches"], c["path"]))
    return out


class SimSessions:
    """Running loops by session id."""

    def __init__(self) -> None:
        self._sessions: OrderedDict[str, SimSession] = OrderedDict()
        self._lock = threading.Lock()

    def start(
        self,
        config_path: Path,
        fb: FunctionBlock,
        *,
        parameters: dict[str, float],
        setpoints: dict[str, float],
    ) -> tuple[str, dict[str, Any]]:
        from fuzzyctl.sim.config import build_loop, load_config

        try:
            config = load_config(config_path)
            config = replace(
                config,
                plant_parameters={**config.plant_parameters, **parameters},
                setpoints={**config.setpoints, **setpoints},
            )
            loop = build_loop(config, model=Document((fb,)))
        except InputError as exc:
            raise FuzzyctlError(str(exc)) from None
        sid = secrets.token_hex(8)
        with self._lock:
            self._sessions[sid] = SimSession(loop, config)
            while len(self._sessions) > MAX_SESSIONS:
                self._sessions.popitem(last=False)
        info = {
            "id": sid,
            "period": loop.period,
            "columns": list(loop.columns),
            "units": loop.units,
            "duration": config.duration,
            "panels": config.panels,
            "fuzzy": {
                "inputs": [
                    c[3:]
                    for c in loop.columns
                    if c.startswith("fb.") and c[3:] in [v.name for v in fb.inputs]
                ],
                "outputs": [
                    c[3:]
                    for c in loop.columns
                    if c.startswith("fb.") and c[3:] in [v.name for v in fb.outputs]
                ],
            },
        }
        return sid, info

    def step(self, sid: str, seconds: float) -> dict[str, Any]:
        with self._lock:
            session = self._sessions.get(sid)
        if session is None:
            raise KeyError(sid)
        loop = session.loop
        cycles = min(MAX_CYCLES_PER_STEP, max(1, round(seconds / loop.period)))
        rows: dict[str, list[float | None]] = {c: [] for c in loop.columns}
        with session.lock:
            try:
                for _ in range(cycles):
                    row = loop.cycle()
                    for c in loop.columns:
                        v = row.get(c, math.nan)
                        rows[c].append(v if math.isfinite(v) else None)
            except InputError as exc:
                raise FuzzyctlError(str(exc)) from None
        return {"t": loop.t, "rows": rows}

    def stop(self, sid: str) -> bool:
        with self._lock:
            return self._sessions.pop(sid, None) is not None
