"""``fuzzyctl eval --data FILE``: a controller over every row of a CSV or Parquet file, streamed.

Every column of the input is written back unchanged (a timestamp is the usual passenger),
followed by the outputs; a column that has an output's name is kept and the computed output
is written as ``NAME_computed``.  Rows are successive evaluations of one instance, in file
order (DEFAULT := NC carries from row to row).  An empty, NaN or infinite input cell gives
NaN outputs for its row and is counted in a warning (``--on-error fail`` stops at it
instead, naming its line and column); text that is not a number always stops."""

from __future__ import annotations

import contextlib
import difflib
import sys
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

import numpy as np

from fuzzyctl.diagnostics import InputError
from fuzzyctl.tables import Batch, TableReader, TableWriter, format_of, numbers

#: Show a progress bar for data files larger than this (bytes of CSV or rows of Parquet).
PROGRESS_BYTES = 8 << 20
PROGRESS_ROWS = 200_000
ON_ERROR = ("nan", "fail")
#: rows ``--table`` prints (the rest is counted: -o FILE writes them all)
TABLE_ROWS = 20


def evaluate_file(
    ctl: Any,
    source: str,
    output: str | None,
    *,
    out_format: str | None = None,
    delimiter: str | None = None,
    decimal: str | None = None,
    on_error: str = "nan",
    out_of_range: str = "warn",
    as_table: bool = False,
    warn: Any = None,
) -> None:
    """Evaluate ``ctl`` on every row of ``source`` and write the result to ``output`` (a path,
    ``-`` or None for stdout).  ``warn(text)`` receives the warnings (counts of NaN rows, of
    values outside their range per column).  ``out_of_range`` as in ``Controller.evaluate``
    ("warn": counted here, per column)."""
    from fuzzyctl.engine.ranges import check_mode

    if on_error not in ON_ERROR:
        raise InputError(f"--on-error must be one of {', '.join(ON_ERROR)}, not {on_error!r}")
    check_mode(out_of_range)
    outside: dict[str, int] = {}
    reader = TableReader(source, delimiter=delimiter, decimal=decimal)
    try:
        used = _input_columns(ctl, reader)
        fmt = format_of(output or "-", out_format)
        if fmt == "parquet" and output in (None, "-"):
            raise InputError("Parquet output needs a file: -o FILE.parquet")
        renamed = {o: (f"{o}_computed" if o in reader.header else o) for o in ctl.outputs}
        mode = (on_error, out_of_range, outside)
        if as_table:
            counts = _print_table(ctl, reader, used, renamed, mode)
        else:
            with _sink(output) as sink:
                counts = _stream(ctl, reader, used, renamed, TableWriter(sink, fmt, reader.delimiter), mode)
        if warn is not None:
            for name, n in outside.items():
                lo, hi = ctl.input_ranges[name]
                warn(
                    f"column {name!r}: {n} of {counts[2]} values outside the input's range "
                    f"{lo:g}..{hi:g}, computed as its terms give them (see --out-of-range)"
                )
        if warn is not None:
            bad_inputs, bad_outputs, rows = counts
            if bad_inputs:
                warn(
                    f"{bad_inputs} of {rows} rows have an empty, NaN or infinite input: their outputs "
                    "are NaN (--on-error fail stops at the first one instead)"
                )
            if bad_outputs:
                warn(
                    f"{bad_outputs} of {rows} rows with valid inputs gave a NaN or infinite output "
                    "(no rule fired and the DEFAULT is NaN, or a term is undefined there)"
                )
    finally:
        reader.close()


def _input_columns(ctl: Any, reader: TableReader) -> list[str]:
    """The input columns present; a required input without a column is an error that points
    at a near-miss column name."""
    header = reader.header
    missing = [
        n
        for n, spec in zip(ctl.inputs, ctl.plan.inputs, strict=True)
        if n not in header and spec.default is None
    ]
    if missing:
        close = difflib.get_close_matches(missing[0], [h for h in header if h not in ctl.inputs], n=1)
        hint = f" (is column {close[0]!r} it?)" if close else f" (columns: {', '.join(header)})"
        raise InputError(f"{reader.name}: no column for input {missing[0]!r}{hint}")
    return [n for n in ctl.inputs if n in header]


@contextlib.contextmanager
def _sink(output: str | None) -> Iterator[IO[bytes]]:
    if output in (None, "-"):
        yield sys.stdout.buffer
        sys.stdout.buffer.flush()
        return
    from fuzzyctl.files import atomic_writer

    with atomic_writer(Path(str(output)), "wb") as handle:
        yield handle


#: (--on-error, --out-of-range, the counts of values outside their range by column)
Mode = tuple[str, str, dict[str, int]]


def _evaluate(
    ctl: Any, reader: TableReader, batch: Batch, used: list[str], mode: Mode
) -> tuple[dict[str, np.ndarray[Any, np.dtype[np.float64]]], int]:
    from fuzzyctl.engine.ranges import count_outside, outside_message

    on_error, out_of_range, outside = mode
    values, invalid = numbers(reader, batch, used)
    if invalid.any() and on_error == "fail":
        row = int(np.flatnonzero(invalid)[0])
        name = next(n for n in used if not np.isfinite(values[n][row]))
        col = reader.header.index(name) + 1
        cell = batch.columns.column(name)[row].as_py()
        raise InputError(
            f"{reader.line_of(batch.first_row + row)}: column {col} ({name!r}): "
            f"{'empty' if cell in (None, '') else repr(cell)} is not a finite number (--on-error fail)"
        )
    if not values and ctl.plan.inputs:  # every input has a default value: one row each all the same
        spec = ctl.plan.inputs[0]
        values = {spec.name: np.full(batch.columns.num_rows, float(spec.default))}
    counts = count_outside(ctl.input_ranges, values) if out_of_range in ("warn", "raise") else {}
    if counts and out_of_range == "raise":
        name = next(iter(counts))
        lo, hi = ctl.input_ranges[name]
        row = int(np.flatnonzero((values[name] < lo) | (values[name] > hi))[0])
        where = f"{reader.line_of(batch.first_row + row)}: column {reader.header.index(name) + 1}"
        raise InputError(f"{where}: {outside_message(name, float(values[name][row]), (lo, hi))}")
    for name, n in counts.items():
        outside[name] = outside.get(name, 0) + n
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # counted and reported once, by the caller
        out = ctl.evaluate_batch(
            values, on_invalid="nan", out_of_range="clamp" if out_of_range == "clamp" else "ignore"
        )
    return out, int(np.count_nonzero(invalid))


def _stream(
    ctl: Any,
    reader: TableReader,
    used: list[str],
    renamed: dict[str, str],
    writer: TableWriter,
    mode: Mode,
) -> tuple[int, int, int]:
    from rich.progress import BarColumn, DownloadColumn, Progress, TextColumn, TimeRemainingColumn

    by_bytes = reader.format == "csv" and reader.size is not None
    total = reader.size
    show = (
        sys.stderr.isatty() and total is not None and total >= (PROGRESS_BYTES if by_bytes else PROGRESS_ROWS)
    )
    columns = [TextColumn("{task.description}"), BarColumn()]
    columns += (
        [DownloadColumn()] if by_bytes else [TextColumn("{task.completed:,.0f}/{task.total:,.0f} rows")]
    )
    bad_inputs = bad_outputs = rows = 0
    wrote = False
    with Progress(*columns, TimeRemainingColumn(), disable=not show, transient=True) as progress:
        task = progress.add_task(f"read, evaluate, write {Path(reader.name).name}", total=total)
        for batch in reader.batches():
            out, invalid = _evaluate(ctl, reader, batch, used, mode)
            bad_inputs += invalid
            finite = np.ones(batch.columns.num_rows, bool)
            for v in out.values():
                finite &= np.isfinite(v)
            bad_outputs += int(np.count_nonzero(~finite)) - invalid
            rows += batch.columns.num_rows
            writer.write(batch.columns, {renamed[k]: v for k, v in out.items()})
            wrote = True
            progress.update(task, completed=reader.bytes_read if by_bytes else rows)
        if not wrote:  # a header and no rows: the result has the header too
            writer.write(_empty(reader), {renamed[k]: np.zeros(0) for k in ctl.outputs})
        writer.close()
    return bad_inputs, max(bad_outputs, 0), rows


def _empty(reader: TableReader) -> Any:
    import pyarrow as pa

    return pa.RecordBatch.from_arrays([pa.array([], pa.string()) for _ in reader.header], names=reader.header)


def _print_table(
    ctl: Any, reader: TableReader, used: list[str], renamed: dict[str, str], mode: Mode
) -> tuple[int, int, int]:
    """The first :data:`TABLE_ROWS` rows as a table, and how many it left out (counted, not
    evaluated); returns the counts as :func:`_stream` does, for the rows shown."""
    from rich.console import Console
    from rich.table import Table

    table = Table(title=f"{ctl.name or ''}: {Path(reader.name).name}")
    for h in reader.header:
        table.add_column(h, justify="right", overflow="fold")
    for k in ctl.outputs:
        table.add_column(renamed[k], justify="right", overflow="fold")
    shown = bad = rest = 0
    for batch in reader.batches():
        take = min(batch.columns.num_rows, TABLE_ROWS - shown)
        rest += batch.columns.num_rows - take
        if take <= 0:
            continue
        if take < batch.columns.num_rows:
            batch = Batch(batch.columns.slice(0, take), batch.first_row)
        out, invalid = _evaluate(ctl, reader, batch, used, mode)
        bad += invalid
        cells = [batch.columns.column(h).to_pylist() for h in reader.header]
        for r in range(take):
            table.add_row(
                *("" if c[r] is None else str(c[r]) for c in cells),
                *(f"{out[k][r]:.10g}" for k in ctl.outputs),
            )
        shown += take
    if rest:
        table.caption = f"first {shown} rows; {rest} more not shown (-o FILE writes every row)"
    Console(highlight=False).print(table)
    return bad, 0, shown
