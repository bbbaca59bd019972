"""A block instance: the block (Siemens FUZZY or XFUZ), its bindings to the process image,
the safety logic, and what the API may change while it runs.

Each cycle (called by the instance's task, under the instance's lock):

1. a download waiting for this call takes effect (XFUZ: the REFRESH edge);
2. inputs: each bound input takes the field value when its link is up and the value is a
   finite number, else its last good value; parameters bound to the field take a value
   the field changed;
3. safety: with every link up and every input good the instance runs (``run``); on the
   first problem it keeps running on the last good inputs (``hold``) for ``hold_time``,
   then puts the configured safe values on its outputs (``safe``) until every problem is
   gone, which it notices by itself;
4. the block is called once;
5. outputs: block values (safe values in ``safe``) go to their output cells.

API calls take the same lock, so no cycle sees a half-made change: a download swaps a
knowledge base prepared beforehand, outside the lock.
"""

from __future__ import annotations

import itertools
import math
import statistics
import threading
import time
from array import array
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

from fuzzyctl.blocks.task import CycleContext, CycleRecord, CyclicTask
from fuzzyctl.diagnostics import FuzzyctlError, InputError
from fuzzyctl.runtime.adapters import Adapter
from fuzzyctl.runtime.config import InstanceConfig
from fuzzyctl.runtime.events import EventLog
from fuzzyctl.runtime.kb import KnowledgeBaseSource, PreparedKB
from fuzzyctl.runtime.links import InCell, Link, OutCell

__all__ = ["CycleRing", "Instance", "SafetyState"]

RING_SIZE = 2000  # cycles whose timings are kept per instance (20 s at 10 ms)


class CycleRing:
    """Start, jitter and execution time of the last ``size`` cycles, in flat arrays of
    doubles: unlike a record object per cycle, they give Python's cyclic garbage collector
    nothing to scan, whose pauses would otherwise show up as jitter of every instance."""

    def __init__(self, size: int) -> None:
        self.size = size
        self.start = array("d", bytes(8 * size))
        self.jitter = array("d", bytes(8 * size))
        self.duration = array("d", bytes(8 * size))
        self.count = 0

    def push(self, start: float, jitter: float, duration: float) -> None:
        k = self.count % self.size
        self.start[k], self.jitter[k], self.duration[k] = start, jitter, duration
        self.count += 1

    def last(self) -> tuple[float, float, float] | None:
        if not self.count:
            return None
        k = (self.count - 1) % self.size
        return self.start[k], self.jitter[k], self.duration[k]

    def ordered(self) -> tuple[list[float], list[float], list[float]]:
        """The kept cycles, oldest first: (starts, jitters, durations)."""
        n = min(self.count, self.size)
        k = self.count % self.size
        idx = list(range(k, self.size)) + list(range(k)) if self.count > self.size else list(range(n))
        return [self.start[i] for i in idx], [self.jitter[i] for i in idx], [self.duration[i] for i in idx]


class SafetyState(StrEnum):
    RUN = "run"
    HOLD = "hold"
    SAFE = "safe"


@dataclass
class InputBinding:
    name: str
    key: str
    link: Link
    cell: InCell
    last_good: float | None = None
    valid: bool = True  # for input-invalid / input-valid events


@dataclass
class OutputBinding:
    name: str
    key: str
    cells: list[OutCell]
    links: list[Link]
    safe: float | None
    last: float | None = None


@dataclass
class ParamBinding:
    name: str
    key: str
    link: Link
    cell: InCell
    mirror: OutCell
    seen: float | None = None
    seen_stamp: float = 0.0


@dataclass
class Problems:
    links: list[str] = field(default_factory=list)
    inputs: list[str] = field(default_factory=list)

    def __bool__(self) -> bool:
        return bool(self.links or self.inputs)

    def text(self) -> str:
        parts = [f"link {n} down" for n in self.links] + [f"input {n} invalid" for n in self.inputs]
        return ", ".join(parts)


class Instance:
    """One block instance with its task."""

    def __init__(
        self,
        config: InstanceConfig,
        adapter: Adapter,
        events: EventLog,
        *,
        task: CyclicTask,
    ) -> None:
        self.config = config
        self.name = config.name
        self.adapter = adapter
        self.events = events
        self.task = task
        self.lock = threading.Lock()
        self.inputs: list[InputBinding] = []
        self.outputs: list[OutputBinding] = []
        self.params: list[ParamBinding] = []
        self.state = SafetyState.SAFE
        self.state_since = 0.0
        self.problems = Problems()
        self.error: str | None = None
        self.downloads = 0
        self.last_download: dict[str, Any] | None = None
        self._started = False
        self._overruns_logged = 0
        self._overrun_logged_at = -math.inf
        self.ring = CycleRing(RING_SIZE)
        self._links: list[Link] | None = None
        task.add(self.cycle)

    # ------------------------------------------------------------------ bindings

    def bind_input(self, name: str, link: Link, cell: InCell) -> None:
        key = self.adapter.input_key(name)
        if any(b.key == key for b in self.inputs):
            raise InputError(f"{name} ({key}) is bound twice")
        self.inputs.append(InputBinding(name, key, link, cell))
        self._links = None

    def bind_output(self, name: str, targets: list[tuple[Link, OutCell]], safe: float | None) -> None:
        key = self.adapter.output_key(name)
        self.outputs.append(
            OutputBinding(name, key, [c for _, c in targets], [lk for lk, _ in targets], safe)
        )

    def bind_param(self, name: str, link: Link, cell: InCell, mirror: OutCell) -> None:
        key = self.adapter.param_key(name)
        self.params.append(ParamBinding(name, key, link, cell, mirror))
        self._links = None

    @property
    def links(self) -> list[Link]:
        """Every link the instance's bindings use (computed once, after binding)."""
        if self._links is None:
            self._links = self._collect_links()
        return self._links

    def _collect_links(self) -> list[Link]:
        seen: dict[str, Link] = {}
        for b in self.inputs:
            seen[b.link.name] = b.link
        for o in self.outputs:
            for lk in o.links:
                seen[lk.name] = lk
        for p in self.params:
            seen[p.link.name] = p.link
        return list(seen.values())

    # ------------------------------------------------------------------ the cycle

    def cycle(self, ctx: CycleContext) -> None:
        with self.lock:
            try:
                self._cycle(ctx.start, ctx.period)
            except Exception as exc:  # a bug in one instance must not stop the others
                message = f"internal error: {type(exc).__name__}: {exc}"
                if message != self.error:
                    self.error = message
                    self.events.emit("error", f"{self.name}: {message}", level="error", instance=self.name)

    def _cycle(self, now: float, period: float) -> None:
        adapter = self.adapter
        if not self._started:
            self._started = True
            self.state_since = now
            self.events.emit(
                "safe-enter",
                f"{self.name}: outputs at their safe values until every input has been read",
                level="warning",
                instance=self.name,
                reason="startup",
            )
        if adapter.before_cycle():
            self._rekey()
            self.events.emit(
                "download-applied",
                f"{self.name}: knowledge base switched by a rising edge of REFRESH",
                instance=self.name,
                sha256=adapter.kb.source.sha256,
            )
        problems = Problems()
        for lk in self.links:
            if not lk.up:
                problems.links.append(lk.name)
        for b in self.inputs:
            v = b.cell.value
            good = b.link.up and math.isfinite(v)
            if good:
                b.last_good = v
            elif b.link.up or b.last_good is None:  # the link is fine but the value is not a number
                problems.inputs.append(b.name)
            valid = good or not b.link.up
            if valid != b.valid and b.link.up:
                b.valid = valid
                self.events.emit(
                    "input-valid" if valid else "input-invalid",
                    f"{self.name}: input {b.name} = {v!r}"
                    + ("" if valid else ", running on its last good value"),
                    level="info" if valid else "warning",
                    instance=self.name,
                    input=b.name,
                    value=None if math.isnan(v) else v,
                )
            if b.last_good is not None:
                adapter.write_input(b.key, b.last_good)
        for p in self.params:
            self._param_from_field(p)
        self._safety(now, problems)
        adapter.fault = None if self.state is SafetyState.RUN else self.state.value
        try:
            adapter.execute(period)
            adapter.after_cycle()
            if self.error is not None:
                self.events.emit("error-cleared", f"{self.name}: the block runs again", instance=self.name)
                self.error = None
        except FuzzyctlError as exc:  # a parameter the field or API set out of range, ...
            if str(exc) != self.error:
                self.error = str(exc)
                self.events.emit(
                    "error", f"{self.name}: {exc}; outputs at safe values", level="error", instance=self.name
                )
        safe = self.state is SafetyState.SAFE or self.error is not None
        for o in self.outputs:
            if safe and o.key not in ("INFO", "ENO", "STATUS", "ERROR"):
                value = o.safe if o.safe is not None else o.last
            else:
                value = adapter.read_output(o.key)
            if value is None or not math.isfinite(value):
                continue
            o.last = value
            for cell in o.cells:
                cell.value = value
        for p in self.params:
            p.mirror.value = float(adapter.get_param(p.key))

    def _param_from_field(self, p: ParamBinding) -> None:
        v, stamp = p.cell.value, p.cell.stamp
        if not p.link.up or not math.isfinite(v) or stamp == p.seen_stamp:
            return
        # What the field held before this read: the last value read, or our mirror when
        # it was written between that read and this one.  Without the second case a
        # command written right after the mirror (START_STOP 16#FFFF -> 0 before we read
        # the 16#FFFF back) would look like no change and be lost.
        before = p.seen
        last_send = p.mirror.last_send
        if last_send is not None and p.seen_stamp < last_send[1] < stamp:
            before = last_send[0]
        p.seen_stamp = stamp
        first = p.seen is None
        p.seen = v
        if v == before:
            return
        current = self.adapter.get_param(p.key)
        if v == current or (first and p.mirror.sent is None and v == 0 and current != 0):
            # A fresh node or register holds 0 before we mirrored anything: not a command.
            return
        self._set_param(p.key, v, source=f"field:{p.link.name}")

    def _safety(self, now: float, problems: Problems) -> None:
        self.problems = problems
        hold = self.config.hold_time
        if not problems:
            if self.state is not SafetyState.RUN:
                kind = "safe-exit" if self.state is SafetyState.SAFE else "hold-end"
                self.events.emit(
                    kind,
                    f"{self.name}: every link up and every input good; running normally",
                    instance=self.name,
                    after=round(now - self.state_since, 6),
                )
                self.state, self.state_since = SafetyState.RUN, now
            return
        if self.state is SafetyState.RUN:
            self.state, self.state_since = SafetyState.HOLD, now
            self.events.emit(
                "hold-start",
                f"{self.name}: {problems.text()}; running on the last good inputs for {hold:g} s",
                level="warning",
                instance=self.name,
                links=problems.links,
                inputs=problems.inputs,
                hold_time=hold,
            )
        if self.state is SafetyState.HOLD and now - self.state_since >= hold:
            self.state, self.state_since = SafetyState.SAFE, now
            self.events.emit(
                "safe-enter",
                f"{self.name}: {problems.text()} for {hold:g} s; outputs at their safe values",
                level="error",
                instance=self.name,
                links=problems.links,
                inputs=problems.inputs,
                reason="hold time elapsed",
                safe_values={o.name: o.safe for o in self.outputs},
            )

    def _rekey(self, kb: PreparedKB | None = None) -> None:
        for b in self.inputs:
            b.key = self.adapter.input_key(b.name, kb)
        for o in self.outputs:
            o.key = self.adapter.output_key(o.name, kb)

    def after_cycle(self, rec: CycleRecord) -> None:
        """Called by the scheduler after each cycle: timings into the ring, overruns logged."""
        self.ring.push(rec.start, rec.jitter, rec.duration)
        if rec.overrun:
            self._note_overrun(rec.end)

    def _note_overrun(self, now: float) -> None:
        """Logs at most one event a second with the count since the previous one (so
        nothing is lost and nothing floods)."""
        if now - self._overrun_logged_at >= 1.0:
            count = self.task.stats.overruns - self._overruns_logged
            self._overruns_logged = self.task.stats.overruns
            self._overrun_logged_at = now
            self.events.emit(
                "overrun",
                f"{self.name}: {count} cycle(s) overran the {self.config.period:g} s period",
                level="warning",
                instance=self.name,
                count=count,
                total=self.task.stats.overruns,
            )

    # ------------------------------------------------------------------ API operations

    def _set_param(self, key: str, value: float, source: str) -> None:
        old = self.adapter.get_param(key)
        self.adapter.set_param(key, value)
        self.events.emit(
            "parameter",
            f"{self.name}: {key} {old} -> {self.adapter.get_param(key)} ({source})",
            instance=self.name,
            parameter=key,
            old=old,
            new=self.adapter.get_param(key),
            source=source,
        )

    def set_parameters(self, values: dict[str, float], source: str = "api") -> dict[str, int]:
        """Write several parameters between two cycles; all are checked before any is
        written (all or nothing).  Returns the new values by manual name."""
        with self.lock:
            keys = {name: self.adapter.param_key(name) for name in values}
            for name, value in values.items():
                self.adapter.check_param(keys[name], value)
            for name, value in values.items():
                self._set_param(keys[name], value, source)
            return {k: self.adapter.get_param(k) for k in keys.values()}

    def set_parameter(self, name: str, value: float, source: str = "api") -> int:
        """Write a parameter by its manual name; returns the new value."""
        with self.lock:
            key = self.adapter.param_key(name)
            self._set_param(key, value, source)
            return self.adapter.get_param(key)

    def force(self, name: str, value: float | None, source: str = "api") -> dict[str, float]:
        """Force an input to ``value`` (None releases it); returns the forced inputs."""
        with self.lock:
            key = self.adapter.input_key(name)
            self.adapter.force(key, value)
            self.events.emit(
                "force",
                f"{self.name}: {key} "
                + ("released" if value is None else f"forced to {value:g}")
                + f" ({source})",
                instance=self.name,
                input=key,
                value=value,
                source=source,
            )
            return self.adapter.forced()

    def set_manual(self, name: str, value: float, source: str = "api") -> None:
        with self.lock:
            key = self.adapter.output_key(name)
            if not key.startswith("OUT"):
                raise InputError(f"{name!r} is not an output with a manual value")
            self.adapter.set_manual(key, value)
            self.events.emit(
                "parameter",
                f"{self.name}: O{key[3:]}_MAN = {value:g} ({source})",
                instance=self.name,
                parameter=f"O{key[3:]}_MAN",
                new=value,
                source=source,
            )

    def set_mode(self, auto: bool, source: str = "api") -> None:
        with self.lock:
            self.adapter.set_mode(auto)
            self.events.emit(
                "parameter",
                f"{self.name}: MAN_AUTO = {int(auto)} ({source})",
                instance=self.name,
                parameter="MAN_AUTO",
                new=int(auto),
                source=source,
            )

    def check_download(self, kb: PreparedKB) -> None:
        """Raise InputError when a bound input or output is not in the new knowledge base."""
        missing = []
        for b in self.inputs:
            try:
                self.adapter.input_key(b.name, kb)
            except InputError as exc:
                missing.append(f"input binding {b.name}: {exc}")
        for o in self.outputs:
            try:
                self.adapter.output_key(o.name, kb)
            except InputError as exc:
                missing.append(f"output binding {o.name}: {exc}")
        if missing:
            raise InputError("the new knowledge base does not fit the bindings:\n  " + "\n  ".join(missing))

    def download(self, kb: PreparedKB, source: str = "api") -> dict[str, Any]:
        """Switch to a prepared knowledge base between two cycles (see module doc)."""
        self.check_download(kb)
        with self.lock:
            self.adapter.install(kb)
            self.downloads += 1
            style = self.adapter.style
            info = {
                "format": kb.source.format,
                "origin": kb.source.origin,
                "sha256": kb.source.sha256,
                "inputs": list(kb.inputs),
                "outputs": list(kb.outputs),
                "source": source,
                "time": time.time(),
            }
            self.last_download = info
            if style == "siemens":
                self._rekey()
                procedure = "START_STOP = 0, transfer, START_STOP = 16#FFFF between two cycles"
            else:
                procedure = "new constants, REFRESH raised for the next call"
            self.events.emit(
                "download",
                f"{self.name}: knowledge base from {kb.source.origin} ({kb.source.format}): {procedure}",
                instance=self.name,
                procedure=procedure,
                warnings=[d.message for d in kb.warnings],
                details={k: v for k, v in info.items() if k != "time"},
            )
            if style == "siemens":
                self.events.emit(
                    "download-applied",
                    f"{self.name}: knowledge base switched",
                    instance=self.name,
                    sha256=kb.source.sha256,
                )
            return {**info, "procedure": procedure}

    # ------------------------------------------------------------------ reading

    def snapshot(self) -> dict[str, Any]:
        """Everything live about the instance, consistent with one cycle boundary."""
        with self.lock:
            adapter = self.adapter
            stats = self.task.stats
            last = self.ring.last()
            values = adapter.values()
            inputs = {}
            for name in adapter.kb.inputs:
                try:
                    inputs[name] = float(values.get(adapter.input_key(name), math.nan))
                except InputError:  # an input the block does not connect
                    continue
            outputs = {}
            for name in adapter.kb.outputs:
                try:
                    outputs[name] = adapter.read_output(adapter.output_key(name))
                except InputError:  # an output the block does not connect (XFUZ VARn)
                    continue
            return {
                "name": self.name,
                "style": adapter.style,
                "period": self.config.period,
                "state": self.state.value,
                "state_since": self.state_since,
                "problems": {"links": list(self.problems.links), "inputs": list(self.problems.inputs)},
                "error": self.error,
                "status": adapter.status,
                "inputs": inputs,
                "outputs": outputs,
                "field_outputs": {o.name: o.last for o in self.outputs},
                "parameters": values,
                "forced": adapter.forced(),
                "cycles": stats.count,
                "overruns": stats.overruns,
                "last_cycle": None
                if last is None
                else {"start": last[0], "jitter": last[1], "duration": last[2]},
                "links": {lk.name: lk.state.value for lk in self.links},
                "knowledge_base": {
                    "origin": adapter.kb.source.origin,
                    "format": adapter.kb.source.format,
                    "sha256": adapter.kb.source.sha256,
                    "inputs": list(adapter.kb.inputs),
                    "outputs": list(adapter.kb.outputs),
                },
                "downloads": self.downloads,
            }

    def knowledge_base_source(self) -> KnowledgeBaseSource:
        """The text of the knowledge base the instance runs (the last one downloaded)."""
        with self.lock:
            source: KnowledgeBaseSource = self.adapter.kb.source
            return source

    def statistics(self) -> dict[str, Any]:
        """Cycle statistics: counts over the whole run, percentiles over the kept cycles."""
        with self.lock:
            summary = self.task.stats.summary()
            starts, jitter_list, duration_list = self.ring.ordered()
        jitters, durations = sorted(jitter_list), sorted(duration_list)
        intervals = [b - a for a, b in itertools.pairwise(starts)]
        return {
            **summary,
            "kept": len(starts),
            "jitter_p50": percentile(jitters, 50),
            "jitter_p95": percentile(jitters, 95),
            "jitter_p99": percentile(jitters, 99),
            "duration_p50": percentile(durations, 50),
            "duration_p99": percentile(durations, 99),
            "last_duration": duration_list[-1] if duration_list else 0.0,
            "interval_mean": statistics.fmean(intervals) if intervals else 0.0,
        }


def percentile(sorted_values: list[float], q: float) -> float:
    """Nearest-rank percentile of an ascending list (0.0 when empty)."""
    if not sorted_values:
        return 0.0
    k = max(0, min(len(sorted_values) - 1, math.ceil(q / 100 * len(sorted_values)) - 1))
    return sorted_values[k]
