"""Running a configured loop and writing its results (what ``fuzzyctl simulate`` does)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fuzzyctl.sim.config import SimConfig, build_loop
from fuzzyctl.sim.loop import Trace
from fuzzyctl.sim.metrics import Quality, quality
from fuzzyctl.sim.plot import default_panels, save_html, save_png


@dataclass
class Result:
    """A finished run: the trace, its quality figures (if the configuration asks for them)
    and the files written."""

    config: SimConfig
    runtime: str
    cycle: float
    trace: Trace
    quality: Quality | None
    files: dict[str, Path] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """What ``fuzzyctl simulate --json`` prints: the run, its quality figures (NaN as None,
        infinities as ``"inf"``: JSON has no such numbers) and the files written."""
        q = self.quality
        return {
            "title": self.config.title,
            "runtime": self.runtime,
            "cycle": self.cycle,
            "duration": float(self.trace["t"][-1]),
            "quality": None if q is None else {k: _json_number(v) for k, v in q.as_dict().items()},
            "files": {k: str(v) for k, v in self.files.items()},
        }

    def figures(self) -> dict[str, str]:
        """The quality figures as ``fuzzyctl simulate`` shows them (empty without a
        ``[quality]`` table)."""
        q = self.quality
        if q is None:
            return {}
        return {
            "ISE": f"{q.ise:.4g}",
            "IAE": f"{q.iae:.4g}",
            "ITAE": f"{q.itae:.4g}",
            "overshoot": f"{q.overshoot:.3g}",
            "overshoot %": f"{q.overshoot_percent:.2f}",
            "settling time": "never" if math.isinf(q.settling_time) else f"{q.settling_time:.2f} s",
            "final error": f"{q.final_error:.3g}",
        }


def _json_number(v: float | str) -> float | str | None:
    if isinstance(v, float) and not math.isfinite(v):
        return None if math.isnan(v) else ("inf" if v > 0 else "-inf")
    return v


def simulate(
    config: SimConfig,
    *,
    runtime: str | None = None,
    cycle: float | None = None,
    duration: float | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> Result:
    """Run the loop of ``config`` (optionally with another runtime, cycle time or duration)."""
    loop = build_loop(config, runtime=runtime, cycle=cycle)
    trace = loop.run(duration or config.duration, progress=progress)
    q = None
    if config.quality is not None:
        spec = config.quality
        q = quality(trace, spec.signal, spec.setpoint, band=spec.band, limits=spec.limits, t_step=spec.t_step)
    return Result(config, runtime or config.runtime, loop.period, trace, q)


def panels(result: Result) -> list[list[str]]:
    """The configured plot panels, or: the quality signal with its setpoint first, then the rest."""
    if result.config.panels:
        return result.config.panels
    first: list[str] = []
    spec = result.config.quality
    if spec is not None:
        first = [spec.signal] + ([spec.setpoint] if isinstance(spec.setpoint, str) else [])
    drives = [n for n in result.trace.names if n in _driven(result)]
    return default_panels(result.trace, first=first, drives=drives)


def _driven(result: Result) -> set[str]:
    c = result.config.controller
    names = set()
    for key in ("drive",):
        if isinstance(c.get(key), str):
            names.add(c[key])
    outputs = c.get("outputs")
    if isinstance(outputs, dict):
        names.update(outputs)
    if c.get("structure", "direct") == "direct" and not outputs:
        names.update(n[3:] for n in result.trace.names if n.startswith("fb.") and n[3:] in result.trace.units)
    return names


def write_outputs(
    result: Result,
    *,
    csv: Path | None = None,
    png: Path | None = None,
    html: Path | None = None,
) -> dict[str, Path]:
    """Write the CSV, PNG and HTML files that are asked for; returns them by kind."""
    title = f"{result.config.title} ({result.runtime}, cycle {result.cycle:g} s)"
    dashed = list(result.config.setpoints)
    layout = panels(result)
    if csv is not None:
        result.files["csv"] = result.trace.to_csv(csv)
    if png is not None:
        result.files["png"] = save_png(result.trace, png, layout, title=title, dashed=dashed)
    if html is not None:
        result.files["html"] = save_html(result.trace, html, layout, title=title, dashed=dashed)
    return result.files
