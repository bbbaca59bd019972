"""Shared pieces of the runtime tests: building a runtime from TOML text, the engine as
the reference, and event-log checks."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

import fuzzyctl
from fuzzyctl.runtime import Runtime, parse_config
from fuzzyctl.runtime.events import Event
from tests.conftest import EXAMPLES

FPLTEST_FCL = EXAMPLES / "siemens_fpltest.fcl"
_ENGINE = fuzzyctl.compile(fuzzyctl.load(FPLTEST_FCL))


def f32(x: float) -> float:
    return float(np.float32(x))


def fpltest_reference(temp: float, pressure: float) -> float:
    """What the Siemens block must output, computed by the engine (not the block): inputs
    as REALs clamped to the FCL ranges (manual 1.5: Temp 0..30, Pressure 50..100), the
    output as a REAL."""
    t = min(max(f32(temp), 0.0), 30.0)
    p = min(max(f32(pressure), 50.0), 100.0)
    return f32(_ENGINE.evaluate({"Temp": t, "Pressure": p})["Valve"])


FPLTEST_9_65 = f32(100.0 / 3.0)
"""FPLTEST at Temp 9, Pressure 65 by the manual's formula (1.4, the rules of one term
added): inlet .75, closed .25 + .25, drainage .25 -> (75 - 25) / 1.5, as a REAL."""


def make_runtime(tmp_path: Path, toml: str, *, api: bool = False) -> Runtime:
    path = tmp_path / "serve.toml"
    path.write_text(toml, encoding="utf-8")
    return Runtime(parse_config(toml, path), api=api, event_log=tmp_path / "events.jsonl")


def assert_log_complete(runtime: Runtime, path: Path) -> list[Event]:
    """Every event has the next sequence number, and the file holds exactly the events the
    runtime kept in memory (nothing lost on the way to the disk)."""
    events = runtime.events.since(0)
    assert [e.seq for e in events] == list(range(1, len(events) + 1))
    lines = [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()]
    assert [ln["seq"] for ln in lines] == [e.seq for e in events]
    assert [ln["kind"] for ln in lines] == [e.kind for e in events]
    return events


SAFETY_KINDS = {
    "link-lost",
    "link-up",
    "hold-start",
    "hold-end",
    "safe-enter",
    "safe-exit",
    "input-invalid",
    "input-valid",
}


def safety_sequence(events: list[Event], instance: str | None = None, link: str | None = None) -> list[str]:
    """The safety-related event kinds about an instance or a link, in order (retries and
    overruns, which a loaded machine may add anywhere, left out)."""
    return [
        e.kind
        for e in events
        if e.kind in SAFETY_KINDS and ((instance and e.instance == instance) or (link and e.link == link))
    ]


def until_stop(events: list[Event]) -> list[Event]:
    """The events before the runtime began to stop: its stop puts every instance that is
    not yet safe into ``safe`` (reason ``stop``) and logs each link's last write
    (docs/runtime.md, "Stopping")."""
    for i, e in enumerate(events):
        stop_safe = e.kind == "safe-enter" and e.data.get("reason") == "stop"
        if stop_safe or e.kind in ("stop-write", "runtime-stop"):
            return events[:i]
    return events


def close(a: float, b: float) -> bool:
    return math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-4)
