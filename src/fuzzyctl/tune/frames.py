"""Scoring data larger than memory: a controller evaluated partition by partition of a
``dask.dataframe`` (``fuzzyctl.evaluate_dataframe``, ``fuzzyctl eval --dask``).

Each worker compiles the controller once (``fuzzyctl.compile``: the native backend where
the engine picks it) and evaluates each partition with ``evaluate_batch``.  Partitions are
independent: a ``DEFAULT := NC`` output starts every partition as after a cold restart (at
0), where the single-process ``fuzzyctl eval`` carries the last value across all rows; with
a DEFAULT value (or rules that always fire) both give the same numbers."""

from __future__ import annotations

import glob as globmod
import uuid
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from fuzzyctl.diagnostics import InputError
from fuzzyctl.model import Document, FunctionBlock

# Controllers compiled in this (worker) process, by the token of the scorer that built them.
_COMPILED: dict[str, Any] = {}


class Scorer:
    """A picklable recipe for a controller: the model and how to compile it.  Called on a
    pandas DataFrame it returns the frame with the outputs appended (or replaced)."""

    def __init__(
        self, model: Document | FunctionBlock, *, block: str | None = None, **compile_options: Any
    ) -> None:
        import fuzzyctl

        self.model = model
        self.block = block
        self.options = compile_options
        self.token = uuid.uuid4().hex
        ctl = fuzzyctl.compile(model, block=block, **compile_options)  # fail here, not on a worker
        self.inputs: tuple[str, ...] = tuple(ctl.inputs)
        self.outputs: tuple[str, ...] = tuple(ctl.outputs)
        self._required = tuple(i.name for i in ctl.plan.inputs if i.default is None)

    def controller(self) -> Any:
        ctl = _COMPILED.get(self.token)
        if ctl is None:
            import fuzzyctl

            ctl = fuzzyctl.compile(self.model, block=self.block, out_of_range="ignore", **self.options)
            if len(_COMPILED) > 16:
                _COMPILED.clear()
            _COMPILED[self.token] = ctl
        return ctl

    def check_columns(self, columns: Any, where: str) -> None:
        missing = [c for c in self._required if c not in columns]
        if missing:
            raise InputError(
                f"{where}: no column for input {missing[0]!r} (columns: {', '.join(map(str, columns))})"
            )

    def __call__(self, frame: Any) -> Any:
        ctl = self.controller()
        ctl.reset()  # partitions are independent (see the module docstring)
        cols = {c: frame[c].to_numpy(dtype=np.float64) for c in self.inputs if c in frame.columns}
        out = ctl.evaluate_batch(cols) if len(frame) else {o: np.empty(0) for o in self.outputs}
        result = frame.copy()
        for o in self.outputs:
            result[o] = out[o]
        return result

    def meta(self, meta: Any) -> Any:
        """The output frame's empty schema."""
        import pandas as pd

        m = meta.copy()
        for o in self.outputs:
            m[o] = pd.Series(dtype="float64")
        return m


def _scorer(controller: Any, block: str | None) -> Scorer:
    if isinstance(controller, Scorer):
        return controller
    if isinstance(controller, str | Path):
        import fuzzyctl

        return Scorer(fuzzyctl.load(controller), block=block)
    if isinstance(controller, Document | FunctionBlock):
        return Scorer(controller, block=block)
    raise InputError(
        "evaluate_dataframe needs the model (a Document, FunctionBlock or path) so that each worker "
        "can compile it; got " + type(controller).__name__
    )


def evaluate_dataframe(ddf: Any, controller: Any, *, block: str | None = None) -> Any:
    """A lazy ``dask.dataframe`` with the controller's outputs appended to ``ddf`` (input
    columns by name; other columns are kept).  ``controller``: a loaded document, a function
    block or a path (each worker compiles it once)."""
    scorer = _scorer(controller, block)
    scorer.check_columns(list(ddf.columns), "data")
    return ddf.map_partitions(scorer, meta=scorer.meta(ddf._meta))


def read(source: str | Path) -> Any:
    """A dask DataFrame over a directory or glob of Parquet or CSV files (one format)."""
    import dask.dataframe as dd

    text = str(source)
    path = Path(text)
    if path.is_dir():
        files = sorted(p for p in path.iterdir() if p.suffix.lower() in (".parquet", ".pq", ".csv"))
    else:
        files = sorted(Path(p) for p in globmod.glob(text))
    if not files:
        raise InputError(f"--dask {text!r}: no Parquet or CSV file found")
    kinds = {"csv" if p.suffix.lower() == ".csv" else "parquet" for p in files}
    if len(kinds) > 1:
        raise InputError(f"--dask {text!r}: mixes CSV and Parquet files; give one kind")
    names = [str(p) for p in files]
    try:
        if kinds == {"csv"}:
            return dd.read_csv(names, dtype="float64", blocksize="64MB")
        return dd.read_parquet(names)
    except (OSError, ValueError) as exc:
        raise InputError(f"--dask {text!r}: {exc}") from None


def _write_part(frame: Any, scorer: Scorer, directory: str, index: int) -> int:
    import pyarrow as pa
    import pyarrow.parquet as pq

    out = scorer(frame)
    path = Path(directory) / f"part-{index:05d}.parquet"
    tmp = path.with_name(f".{path.name}.tmp")
    pq.write_table(pa.Table.from_pandas(out, preserve_index=False), tmp)
    tmp.replace(path)
    return len(out)


def score_to_parquet(
    source: str | Path,
    model: Document | FunctionBlock,
    out_dir: str | Path,
    *,
    block: str | None = None,
    execu: Any = None,
    progress: Callable[[int, int], None] | None = None,
    compat: str = "iec",
) -> tuple[int, int]:
    """Evaluate every row of the files at ``source`` and write one Parquet file per
    partition to ``out_dir`` (``part-00000.parquet``, ...).  Returns (partitions, rows)."""
    import dask

    ddf = read(source)
    scorer = Scorer(model, block=block, compat=compat)
    scorer.check_columns(list(ddf.columns), str(source))
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    for old in out.glob("part-*.parquet"):
        old.unlink()
    parts = ddf.to_delayed()
    delayed = dask.delayed  # type: ignore[attr-defined]
    tasks = [delayed(_write_part)(p, scorer, str(out), i) for i, p in enumerate(parts)]
    total = 0
    if execu is None or getattr(execu, "client", None) is None:
        for i, t in enumerate(tasks):
            total += int(t.compute(scheduler="sync"))
            if progress:
                progress(i + 1, len(tasks))
        return len(tasks), total
    from distributed import as_completed

    futures = execu.client.compute(tasks)
    try:
        for done, fut in enumerate(as_completed(futures, loop=execu.client.loop), start=1):  # type: ignore[no-untyped-call]
            total += int(fut.result())
            if progress:
                progress(done, len(tasks))
    except BaseException:
        execu.client.cancel(futures)
        raise
    return len(tasks), total


def require_dask() -> None:
    from fuzzyctl.extras import require

    require(("dask", "distributed", "pandas", "pyarrow"), "--dask")
