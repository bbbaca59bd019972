"""Running a block on a file of samples, one row per cycle (what ``fuzzyctl blocks siemens``
and ``fuzzyctl blocks xfuz`` do): the sample file read, the values parsed as the PLC reads
them, and the rows of outputs.

A sample file is CSV with a header row naming the columns; an empty cell keeps the previous
value, as a PLC variable keeps its value between cycles."""

from __future__ import annotations

import csv
import io
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fuzzyctl.diagnostics import DiagnosticError, InputError

Warn = Callable[[str], None]
XFUZ_COLUMNS = (
    "cycle",
    "time",
    *(f"OUT{i}" for i in range(1, 7)),
    *(f"O{i}_CALC" for i in range(1, 7)),
    "STATUS",
    "STATUS_BITS",
    "ERROR",
    "INFERRED",
)


def read_samples(path: Path) -> tuple[list[str], list[tuple[int, dict[str, str]]]]:
    """The header and the rows ``(line number, {column: cell})`` of a sample file (empty
    cells left out); a malformed file is an :class:`InputError` naming the line."""
    from fuzzyctl.api import require_file

    require_file(path)
    text = path.read_text(encoding="utf-8-sig")
    reader = csv.reader(io.StringIO(text))
    rows = [(n, r) for n, r in enumerate(reader, start=1) if r and any(c.strip() for c in r)]
    if not rows:
        raise InputError(f"{path}: no header row")
    header = [c.strip() for c in rows[0][1]]
    if len(set(header)) != len(header):
        raise InputError(f"{path}:{rows[0][0]}: a column name appears twice")
    samples = []
    for lineno, row in rows[1:]:
        if len(row) > len(header):
            raise InputError(f"{path}:{lineno}: {len(row)} cells for {len(header)} columns")
        samples.append((lineno, {h: c.strip() for h, c in zip(header, row, strict=False) if c.strip()}))
    return header, samples


def number(text: str, where: str) -> float:
    """A sample cell as a number."""
    try:
        return float(text)
    except ValueError:
        raise InputError(f"{where}: {text!r} is not a number") from None


def integer(text: str, where: str) -> int:
    """A sample cell as a PLC integer: decimal, or hexadecimal as ``W#16#``, ``B#16#``,
    ``16#`` or ``0x``."""
    t = text.strip().upper()
    for prefix in ("W#16#", "B#16#", "16#", "0X"):
        if t.startswith(prefix):
            try:
                return int(t[len(prefix) :], 16)
            except ValueError:
                break
    try:
        value = float(t)
    except ValueError:
        raise InputError(f"{where}: {text!r} is not an integer") from None
    if not value.is_integer():
        raise InputError(f"{where}: {text!r} is not an integer")
    return int(value)


@dataclass
class SampleRun:
    """The rows a block gave, one per sample row, under ``columns``; ``failure`` says how
    the block ended in its error state (None: it did not)."""

    rows: list[dict[str, Any]] = field(default_factory=list)
    columns: list[str] = field(default_factory=list)
    failure: str | None = None


def xfuz_constants(path: Path, fmt: str | None, warn: Warn) -> tuple[Any, dict[str, str]]:
    """The XFUZ constants of ``path`` - tables as they are, or a controller in any format
    encoded into them (its diagnostics go to ``warn``) - and the slot of each model name."""
    from fuzzyctl import formats
    from fuzzyctl.api import require_file
    from fuzzyctl.formats.xfuz.reader import read_tables
    from fuzzyctl.formats.xfuz.writer import constants_from_model, slot_labels

    text = path.read_text(encoding="utf-8-sig")
    if path.suffix.lower() in formats.get("xfuz").extensions:
        return read_tables(text, path=str(path)), {}
    require_file(path)
    loaded = formats.read_path(path, fmt)
    for d in loaded.diagnostics:
        if d.severity.value == "warning":
            warn(d.render())
    constants, diags = constants_from_model(loaded.document)
    for d in diags:
        warn(d.render())
    if any(d.is_error for d in diags):
        raise DiagnosticError([d for d in diags if d.is_error])
    return constants, slot_labels(loaded.document)


def run_xfuz(
    knowledge_base: Path,
    samples: Path,
    *,
    period: float,
    span_rule: bool = True,
    degre: bool = False,
    format: str | None = None,
    warn: Warn = print,
) -> SampleRun:
    """The Schneider XFUZ block on ``knowledge_base`` (tables, or a controller it can hold),
    called once per row of ``samples`` in a cyclic task of ``period`` seconds; ``degre`` adds
    the rules' degrees.  What the block flags in STATUS goes to ``warn``."""
    from fuzzyctl.blocks.schneider import XfuzFB

    constants, names = xfuz_constants(knowledge_base, format, warn)
    fb = XfuzFB(constants, task_period=period, span_rule=span_rule)
    for issue in fb.kb_issues:
        warn(
            f"{knowledge_base}: STATUS bit {issue.bit}: {issue.location} {issue.message}".replace(":  ", ": ")
        )
    header, rows = read_samples(samples)
    for h in header:
        try:
            fb[names.get(h, h)]
        except KeyError:
            raise InputError(
                f"{samples}: unknown column {h!r} (INP1..INP8, "
                f"{', '.join(names) + ', ' if names else ''}INIT, MAN_AUTO, CONT_ASK, START, "
                "REFRESH, INHIB, COMMAND, T_OFB, Ii_SIM, Oi_MAN, Oi_DEF)"
            ) from None
    run = SampleRun()
    _cycles(fb, rows, names, samples, period, degre, run.rows)
    degrees = range(max(1, len(fb.kb.rules))) if degre else range(0)
    run.columns = [*XFUZ_COLUMNS, *(f"DEGRE{k}" for k in degrees)]
    if run.rows and run.rows[-1]["ERROR"]:
        run.failure = f"ERROR = 1, STATUS bits {run.rows[-1]['STATUS_BITS'] or 'none'}"
    return run


def _cycles(
    fb: Any,
    rows: list[tuple[int, dict[str, str]]],
    names: dict[str, str],
    samples: Path,
    period: float,
    degre: bool,
    out_rows: list[dict[str, Any]],
) -> None:
    from fuzzyctl.blocks.task import CyclicTask

    task = CyclicTask(period)

    def cycle(ctx: Any) -> None:
        lineno, values = rows[ctx.index]
        for key, raw in values.items():
            try:
                fb[names.get(key, key)] = integer(raw, f"{samples}:{lineno} {key}")
            except KeyError as exc:
                raise InputError(f"{samples}:{lineno}: {exc.args[0]}") from None
        snap = fb.execute(ctx.period)
        row: dict[str, Any] = {"cycle": ctx.index, "time": round(ctx.index * ctx.period, 9)}
        row.update({f"OUT{i + 1}": v for i, v in enumerate(snap.out)})
        row.update({f"O{i + 1}_CALC": v for i, v in enumerate(snap.o_calc)})
        row.update(
            {
                "STATUS": snap.status,
                "STATUS_BITS": " ".join(map(str, fb.status_bits)),
                "ERROR": int(snap.error),
                "INFERRED": int(snap.inferred),
            }
        )
        if degre:
            row.update({f"DEGRE{k}": v for k, v in enumerate(snap.degre[: max(1, len(fb.kb.rules))])})
        out_rows.append(row)

    task.add(cycle)
    if rows:
        task.run(len(rows))
