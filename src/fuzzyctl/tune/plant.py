"""Closed-loop costs: scenarios built from a ``fuzzyctl simulate`` configuration and a
weighted sum of quality figures.

A ``[tune]`` table in the simulate TOML (ignored by ``fuzzyctl simulate``) sets the cost
and the scenarios; each scenario is the configured loop with some tables replaced::

    [tune]
    cost = { settling_time = 1, "max:angle" = 0.5 }
    [[tune.scenarios]]
    name = "30 m, loaded"
    setpoints = { target = 30 }
    [[tune.scenarios]]
    name = "10 m, light"
    setpoints = { target = 10 }
    plant = { load_mass = 5000 }          # merged into [plant]
    duration = 50

Without ``[[tune.scenarios]]`` the loop as configured is the one scenario.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from fuzzyctl.diagnostics import InputError
from fuzzyctl.model import Document, FunctionBlock
from fuzzyctl.sim.config import QualitySpec, SimConfig, build_loop, load_config
from fuzzyctl.sim.loop import Trace
from fuzzyctl.sim.metrics import iae, ise, quality

#: Terms about the [quality] signal and setpoint.
QUALITY_TERMS = ("ise", "iae", "itae", "overshoot", "overshoot_percent", "settling_time", "final_error")
#: Terms about the plant inputs the controller drives.
EFFORT_TERMS = ("effort", "effort_abs", "travel")
#: Terms on any recorded signal: "ise:angle", "max:angle", ...
SIGNAL_TERMS = ("ise", "iae", "max", "rms")
DEFAULT_COST = {"iae": 1.0}
_SCENARIO_KEYS = {
    "name",
    "weight",
    "duration",
    "setpoints",
    "disturbances",
    "plant",
    "noise",
    "seed",
    "quality",
}


@dataclass(frozen=True)
class Scenario:
    """One simulation of the cost: a loop configuration and its weight in the sum."""

    name: str
    config: SimConfig
    weight: float = 1.0


def parse_cost(spec: str | Mapping[str, float] | None, where: str = "--cost") -> dict[str, float]:
    """``"settling_time=1,max:angle=0.5"`` or a mapping -> ``{term: weight}``."""
    if spec is None:
        return dict(DEFAULT_COST)
    if isinstance(spec, str):
        items: dict[str, float] = {}
        for part in (p.strip() for p in spec.split(",") if p.strip()):
            name, sep, raw = part.partition("=")
            try:
                items[name.strip()] = float(raw) if sep else 1.0
            except ValueError:
                raise InputError(f"{where}: {part!r}: the weight {raw!r} is not a number") from None
        spec = items
    out: dict[str, float] = {}
    for name, w in spec.items():
        check_term(name, where)
        if isinstance(w, bool) or not isinstance(w, int | float) or not math.isfinite(w):
            raise InputError(f"{where}: the weight of {name!r} must be a number, got {w!r}")
        out[name] = float(w)
    if not out:
        raise InputError(f"{where}: no cost term given")
    return out


def check_term(name: str, where: str) -> None:
    kind, sep, signal = name.partition(":")
    if sep and kind in SIGNAL_TERMS and signal:
        return
    if not sep and name in (*QUALITY_TERMS, *EFFORT_TERMS):
        return
    known = ", ".join([*QUALITY_TERMS, *EFFORT_TERMS, *(f"{k}:SIGNAL" for k in SIGNAL_TERMS)])
    raise InputError(f"{where}: unknown cost term {name!r} (known: {known})")


def load_scenarios(
    config: str | Path | SimConfig, *, cost: str | Mapping[str, float] | None = None
) -> tuple[list[Scenario], dict[str, float]]:
    """The scenarios and cost of a simulate TOML with an optional ``[tune]`` table; ``cost``
    overrides the file's."""
    cfg = config if isinstance(config, SimConfig) else load_config(config)
    path = cfg.path
    table: dict[str, Any] = {}
    if path.exists():
        table = tomllib.loads(path.read_text(encoding="utf-8")).get("tune", {})
    if not isinstance(table, Mapping):
        raise InputError(f"{path}: [tune] must be a table")
    extra = sorted(set(table) - {"cost", "scenarios"})
    if extra:
        raise InputError(
            f"{path}: [tune]: unknown key(s) {', '.join(map(repr, extra))} (allowed: cost, scenarios)"
        )
    weights = parse_cost(
        cost if cost is not None else table.get("cost"),
        "--cost" if cost is not None else f"{path}: [tune] cost",
    )
    if cfg.quality is None and any(t.split(":")[0] in QUALITY_TERMS and ":" not in t for t in weights):
        raise InputError(f"{path}: the cost uses quality figures but the file has no [quality] table")
    raw = table.get("scenarios", [])
    if not isinstance(raw, list) or not all(isinstance(s, Mapping) for s in raw):
        raise InputError(f"{path}: [[tune.scenarios]] must be tables")
    if not raw:
        return [Scenario(cfg.title, cfg)], weights
    out = []
    for i, s in enumerate(raw):
        where = f"{path}: [[tune.scenarios]] #{i + 1}"
        bad = sorted(set(s) - _SCENARIO_KEYS)
        if bad:
            raise InputError(
                f"{where}: unknown key(s) {', '.join(map(repr, bad))} "
                f"(allowed: {', '.join(sorted(_SCENARIO_KEYS))})"
            )
        variant = _variant(cfg, s, where)
        weight = s.get("weight", 1.0)
        if isinstance(weight, bool) or not isinstance(weight, int | float) or weight < 0:
            raise InputError(f"{where}: weight must be a number >= 0")
        out.append(Scenario(str(s.get("name", f"scenario {i + 1}")), variant, float(weight)))
    return out, weights


def _variant(cfg: SimConfig, s: Mapping[str, Any], where: str) -> SimConfig:
    changes: dict[str, Any] = {}
    for key in ("setpoints", "disturbances", "noise"):
        if key in s:
            if not isinstance(s[key], Mapping):
                raise InputError(f"{where}: {key} must be a table")
            changes[key] = dict(s[key])
    if "plant" in s:
        if not isinstance(s["plant"], Mapping):
            raise InputError(f"{where}: plant must be a table")
        changes["plant_parameters"] = {**cfg.plant_parameters, **s["plant"]}
    if "duration" in s:
        d = s["duration"]
        if isinstance(d, bool) or not isinstance(d, int | float) or not d > 0:
            raise InputError(f"{where}: duration must be a number > 0")
        changes["duration"] = float(d)
    if "seed" in s:
        changes["seed"] = int(s["seed"])
    if "quality" in s:
        if cfg.quality is None or not isinstance(s["quality"], Mapping):
            raise InputError(f"{where}: quality overrides need a [quality] table in the file")
        q = dict(s["quality"])
        allowed = {f.name for f in dataclasses.fields(QualitySpec)}
        bad = sorted(set(q) - allowed)
        if bad:
            raise InputError(f"{where}: quality: unknown key(s) {', '.join(map(repr, bad))}")
        changes["quality"] = dataclasses.replace(cfg.quality, **q)
    variant = dataclasses.replace(cfg, **changes)
    try:
        build_loop(variant).step()
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None
    return variant


def controlled_block(cfg: SimConfig, model: Document | FunctionBlock) -> str | None:
    """The name of the block the loop runs (its [controller] block, else the first)."""
    block = cfg.controller.get("block")
    if block is not None:
        return str(block)
    return model.main.name if isinstance(model, Document) else model.name


def simulate(scenario: Scenario, model: Document, runtime: str | None = None) -> Trace:
    """Run the scenario's loop with ``model`` as the fuzzy controller."""
    cfg = scenario.config
    loop = build_loop(cfg, model=model, runtime=runtime)
    return loop.run(cfg.duration)


def drives(cfg: SimConfig, trace: Trace) -> list[str]:
    """The plant inputs the controller sets."""
    c = cfg.controller
    names: list[str] = []
    if isinstance(c.get("drive"), str):
        names.append(c["drive"])
    outs = c.get("outputs")
    if isinstance(outs, Mapping):
        names.extend(outs)
    elif c.get("structure", "direct") == "direct":
        names.extend(n[3:] for n in trace.names if n.startswith("fb.") and n[3:] in trace.names)
    return [n for n in dict.fromkeys(names) if n in trace]


def metrics(scenario: Scenario, trace: Trace, terms: Sequence[str]) -> dict[str, float]:
    """The value of each cost term for one run (a response that never settles counts as
    settling at twice the measured duration, so that the cost stays finite)."""
    cfg = scenario.config
    out: dict[str, float] = {}
    q = None
    if cfg.quality is not None:
        spec = cfg.quality
        q = quality(trace, spec.signal, spec.setpoint, band=spec.band, limits=spec.limits, t_step=spec.t_step)
    t = trace["t"]
    for term in terms:
        kind, sep, signal = term.partition(":")
        if sep:
            y = trace[signal]
            if kind == "ise":
                out[term] = ise(t, y)
            elif kind == "iae":
                out[term] = iae(t, y)
            elif kind == "max":
                out[term] = float(np.max(np.abs(y))) if len(y) else 0.0
            else:
                out[term] = float(np.sqrt(np.mean(y * y))) if len(y) else 0.0
        elif term in EFFORT_TERMS:
            total = 0.0
            for d in drives(cfg, trace):
                u = trace[d]
                if term == "effort":
                    total += ise(t, u)
                elif term == "effort_abs":
                    total += iae(t, u)
                else:
                    total += float(np.sum(np.abs(np.diff(u))))
            out[term] = total
        else:
            assert q is not None
            v = float(getattr(q, term))
            if term == "settling_time" and math.isinf(v):
                v = 2.0 * (float(t[-1]) - (cfg.quality.t_step if cfg.quality else 0.0))
            out[term] = abs(v) if term == "final_error" else v
    return out


def weighted(values: Mapping[str, float], weights: Mapping[str, float]) -> float:
    return float(sum(weights[k] * values[k] for k in weights))
