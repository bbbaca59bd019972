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
from fuzzyctl.runtime.events import EventLog, Level
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
    """What keeps an instance from ``run``: links down, links late (up, but no complete
    exchange for longer than their ``deadline``: a frozen peer), inputs not a number."""

    links: list[str] = field(default_factory=list)
    inputs: list[str] = field(default_factory=list)
    late: list[str] = field(default_factory=list)
    late_by: float = 0.0

    def __bool__(self) -> bool:
        return bool(self.links or self.inputs or self.late)

    def text(self) -> str:
        parts = [f"link {n} down" for n in self.links]
        parts += [f"link {n} late (no exchange for {self.late_by:.3g} s)" for n in self.late]
        parts += [f"input {n} invalid" for n in self.inputs]
        return ", ".join(parts)


NO_PROBLEMS = Problems()  # shared by the cycles that have none (never mutated)
STATUS_KEYS = frozenset({"INFO", "ENO", "STATUS", "ERROR"})


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
        """The reported state: ``io_state``, or ``safe`` while the block cannot compute."""
        self.state_since = 0.0
        self.io_state = SafetyState.SAFE
        self.io_since = 0.0
        self.problems = NO_PROBLEMS
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

    def _event(self, kind: str, message: str, *, level: Level = "info", **data: Any) -> None:
        """Logs an event of this instance: its name heads the message and tags the event."""
        self.events.emit(kind, f"{self.name}: {message}", level=level, instance=self.name, **data)

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
                try:
                    self._block_fault(f"internal error: {type(exc).__name__}: {exc}", ctx.start)
                except Exception:  # not even the status can be read: the safe values at least
                    for o in self.outputs:
                        if o.safe is not None and o.key not in STATUS_KEYS:
                            for cell in o.cells:
                                cell.value = o.safe

    def _cycle(self, now: float, period: float) -> None:
        adapter = self.adapter
        if not self._started:
            self._start(now)
        if adapter.before_cycle():
            self._rekey()
            self._event(
                "download-applied",
                "knowledge base switched by a rising edge of REFRESH",
                sha256=adapter.kb.source.sha256,
            )
        problems = NO_PROBLEMS
        for lk in self.links:
            if not lk.up or now - lk.last_exchange > lk.deadline:
                problems = self._link_problem(problems, lk, now)
        limit = adapter.INPUT_LIMIT  # beyond it (or NaN) the block's type cannot hold the value
        for b in self.inputs:
            v = b.cell.value
            up = b.link.up
            if up and -limit < v < limit:
                b.last_good = v
                if not b.valid:
                    self._input_validity(b, v, True)
            else:
                if up or b.last_good is None:  # the link is fine but the value is not a number
                    if problems is NO_PROBLEMS:
                        problems = Problems()
                    problems.inputs.append(b.name)
                if up and b.valid:
                    self._input_validity(b, v, False)
            if b.last_good is not None:
                adapter.write_input(b.key, b.last_good)
        for p in self.params:
            self._param_from_field(p)
        if problems is NO_PROBLEMS and self.io_state is SafetyState.RUN:
            self.problems = problems  # the usual cycle: nothing to change
        else:
            self._safety(now, problems)
        adapter.fault = None if self.io_state is SafetyState.RUN else self.io_state.value
        try:
            adapter.execute(period)
            adapter.after_cycle()
            bad = adapter.bad_output()
            if bad is not None:
                raise FuzzyctlError(f"the block computed {bad}: not a number it can output")
        except FuzzyctlError as exc:  # a parameter the field or API set out of range, no result, ...
            self._block_fault(str(exc), now)
        else:
            if self.error is not None:
                self._block_cleared(now)
        self._write_outputs()

    def _write_outputs(self) -> None:
        """Block values (safe values in ``safe``) into the output cells; parameters mirrored."""
        adapter = self.adapter
        safe = self.state is SafetyState.SAFE
        for o in self.outputs:
            if safe and o.key not in STATUS_KEYS:
                value = o.safe if o.safe is not None else o.last
            else:
                value = adapter.read_output(o.key)
            if value is None or value - value != 0.0:  # nothing yet, or not finite
                continue
            o.last = value
            for cell in o.cells:
                cell.value = value
        for p in self.params:
            p.mirror.value = float(adapter.get_param(p.key))

    def _start(self, now: float) -> None:
        self._started = True
        self.state_since = now
        self._event(
            "safe-enter",
            "outputs at their safe values until every input has been read",
            level="warning",
            reason="startup",
        )

    def _link_problem(self, problems: Problems, lk: Link, now: float) -> Problems:
        if problems is NO_PROBLEMS:
            problems = Problems()
        if lk.up:
            problems.late.append(lk.name)
            problems.late_by = max(problems.late_by, now - lk.last_exchange)
        else:
            problems.links.append(lk.name)
        return problems

    def _input_validity(self, b: InputBinding, v: float, valid: bool) -> None:
        b.valid = valid
        self._event(
            "input-valid" if valid else "input-invalid",
            f"input {b.name} = {v!r}" + ("" if valid else ", running on its last good value"),
            level="info" if valid else "warning",
            input=b.name,
            value=None if math.isnan(v) else v,
        )

    def _block_fault(self, message: str, now: float) -> None:
        """The block could not compute: safe values on the outputs at once, INFO 16#42 /
        STATUS bit 15 with ERROR, state ``safe``, one ``error`` event per distinct cause."""
        self.adapter.fault = "block"
        if message != self.error:
            self.error = message
            self._event("error", f"{message}; outputs at safe values", level="error")
        if self.state is not SafetyState.SAFE:
            self._event(
                "safe-enter",
                "the block cannot compute; outputs at their safe values",
                level="error",
                reason="block error",
                error=message,
                safe_values={o.name: o.safe for o in self.outputs},
            )
            self.state, self.state_since = SafetyState.SAFE, now
        self._write_outputs()

    def _block_cleared(self, now: float) -> None:
        self._event("error-cleared", "the block runs again")
        self.error = None
        if self.io_state is not SafetyState.SAFE:
            self._event(
                "safe-exit",
                "the block computes again; outputs from the block",
                after=round(now - self.state_since, 6),
            )
            self.state, self.state_since = self.io_state, now
        self.adapter.fault = None if self.io_state is SafetyState.RUN else self.io_state.value

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
        try:
            self._set_param(p.key, v, source=f"field:{p.link.name}")
        except InputError as exc:  # the field wrote a value the block refuses: keep the old one
            self._event(
                "parameter-refused",
                f"{exc} (field:{p.link.name}); {p.key} stays {current}",
                level="warning",
                parameter=p.key,
                value=v,
                source=f"field:{p.link.name}",
            )

    def _safety(self, now: float, problems: Problems) -> None:
        """The I/O state machine (run -> hold -> safe -> run); a block fault overrides the
        reported state with ``safe`` while it lasts (:meth:`_block_fault`)."""
        self.problems = problems
        hold = self.config.hold_time
        state = self.io_state
        if not problems:
            if state is not SafetyState.RUN:
                kind = "safe-exit" if state is SafetyState.SAFE else "hold-end"
                still = "; the block still cannot compute" if self.error is not None else "; running normally"
                self._event(
                    kind,
                    f"every link up and every input good{still}",
                    after=round(now - self.io_since, 6),
                )
                self._set_io(SafetyState.RUN, now)
            return
        if state is SafetyState.RUN:
            self._set_io(SafetyState.HOLD, now)
            self._event(
                "hold-start",
                f"{problems.text()}; running on the last good inputs for {hold:g} s",
                level="warning",
                links=problems.links + problems.late,
                inputs=problems.inputs,
                hold_time=hold,
            )
        if self.io_state is SafetyState.HOLD and now - self.io_since >= hold:
            self._go_safe(
                now,
                f"{problems.text()} for {hold:g} s",
                "hold time elapsed",
                links=problems.links + problems.late,
                inputs=problems.inputs,
            )

    def _go_safe(self, now: float, why: str, reason: str, **data: Any) -> None:
        """Enter the I/O state ``safe`` (``safe-enter`` with the safe values); the cycle
        (or :meth:`stop_safe`) then sets the fault indication and writes the outputs."""
        self._set_io(SafetyState.SAFE, now)
        self._event(
            "safe-enter",
            f"{why}; outputs at their safe values",
            level="error",
            reason=reason,
            safe_values={o.name: o.safe for o in self.outputs},
            **data,
        )

    def stop_safe(self, now: float) -> None:
        """The runtime stops (its cycles have ended): the outputs' cells take the safe
        values and INFO 16#41 (XFUZ: STATUS bit 15, ERROR) - the state a lost link ends
        in after ``hold_time``, entered at once - for the links' last write."""
        # The cycle thread has stopped and the API with it, so the lock is free; should a
        # cycle be stuck in the block, the cells are set all the same (plain attributes).
        locked = self.lock.acquire(timeout=1.0)
        try:
            if self.state is SafetyState.SAFE:
                self._set_io(SafetyState.SAFE, now)  # already safe (start-up, lost link, block error)
            else:
                self._go_safe(now, "the runtime is stopping", "stop")
            self.adapter.fault = "block" if self.error is not None else SafetyState.SAFE.value
            self._write_outputs()
        finally:
            if locked:
                self.lock.release()

    def _set_io(self, state: SafetyState, now: float) -> None:
        self.io_state, self.io_since = state, now
        if self.error is None:  # while the block fails, the reported state stays safe
            self.state, self.state_since = state, now

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
            self._event(
                "overrun",
                f"{count} cycle(s) overran the {self.config.period:g} s period",
                level="warning",
                count=count,
                total=self.task.stats.overruns,
            )

    # ------------------------------------------------------------------ API operations

    def _set_param(self, key: str, value: float, source: str) -> None:
        old = self.adapter.get_param(key)
        self.adapter.set_param(key, value)
        self._event(
            "parameter",
            f"{key} {old} -> {self.adapter.get_param(key)} ({source})",
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
            self._event(
                "force",
                f"{key} " + ("released" if value is None else f"forced to {value:g}") + f" ({source})",
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
            self._event(
                "parameter",
                f"O{key[3:]}_MAN = {value:g} ({source})",
                parameter=f"O{key[3:]}_MAN",
                new=value,
                source=source,
            )

    def set_mode(self, auto: bool, source: str = "api") -> None:
        with self.lock:
            self.adapter.set_mode(auto)
            self._event(
                "parameter",
                f"MAN_AUTO = {int(auto)} ({source})",
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
            self._event(
                "download",
                f"knowledge base from {kb.source.origin} ({kb.source.format}): {procedure}",
                procedure=procedure,
                warnings=[d.message for d in kb.warnings],
                details={k: v for k, v in info.items() if k != "time"},
            )
            if style == "siemens":
                self._event(
                    "download-applied",
                    "knowledge base switched",
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
                "problems": {
                    "links": list(self.problems.links),
                    "late": list(self.problems.late),
                    "inputs": list(self.problems.inputs),
                    "block": [] if self.error is None else [self.error],
                },
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
