"""Coverage from data on Dask (``fuzzyctl analyze FILE --data 'logs/*.parquet' --dask``):
the files as one ``dask.dataframe``, each partition counted where Dask runs it, the partial
counts added up here.  Every count is a sum or a maximum (degree sums exact, see
:func:`fuzzyctl.analysis.usage.exact_sums`), so the result equals the serial path's,
whatever the partitions and the order they finish in."""

from __future__ import annotations

import uuid
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from fuzzyctl.analysis import usage
from fuzzyctl.analysis.context import Context, build_context
from fuzzyctl.diagnostics import InputError

if TYPE_CHECKING:
    from fuzzyctl.model import Document, FunctionBlock

#: contexts built in this (worker) process, by the token of the recipe that asked
_CONTEXTS: dict[str, Context] = {}


class Recipe:
    """What a worker needs to count a partition: the model (picklable; a compiled context
    is not shipped, each process builds it once), the block, the matched columns."""

    def __init__(
        self, model: Document | FunctionBlock, block: str | None, cols: dict[str, str], epsilon: float
    ) -> None:
        self.model = model
        self.block = block
        self.cols = cols
        self.epsilon = epsilon
        self.token = uuid.uuid4().hex

    def context(self) -> Context:
        ctx = _CONTEXTS.get(self.token)
        if ctx is None:
            if len(_CONTEXTS) > 8:
                _CONTEXTS.clear()
            ctx = _CONTEXTS[self.token] = build_context(self.model, self.block)
        return ctx

    def __call__(self, frame: Any) -> usage.Coverage:
        """The counts of one pandas partition (rows with an empty, NaN or infinite input skipped)."""
        ctx = self.context()
        cov = usage.empty(ctx, self.cols)
        values = {c: frame[c].to_numpy(dtype=np.float64, na_value=np.nan) for c in set(self.cols.values())}
        invalid = np.zeros(len(frame), dtype=bool)
        for arr in values.values():
            invalid |= ~np.isfinite(arr)
        cov.invalid_rows = int(invalid.sum())
        keep = ~invalid
        usage.count(ctx, cov, [values[self.cols[n]][keep] for n in ctx.inputs], self.epsilon)
        return cov


def require_dask() -> None:
    from fuzzyctl.extras import require

    require(("dask", "pandas", "pyarrow"), "--dask")


def read(files: list[str], inputs: tuple[str, ...]) -> tuple[Any, dict[str, str]]:
    """A dask DataFrame of the input columns of ``files`` (one format; CSV with the delimiter
    and decimal mark the serial reader finds in the first file) and the columns matched."""
    import dask.dataframe as dd

    from fuzzyctl.tables import TableReader

    kinds = {"csv" if Path(f).suffix.lower() == ".csv" else "parquet" for f in files}
    if len(kinds) > 1:
        raise InputError(f"--dask: {files[0]} ... mix CSV and Parquet files; give one kind")
    reader = TableReader(files[0])
    try:
        cols = usage.match_columns(inputs, reader.header, reader.name)
        sep, decimal = reader.delimiter, reader.decimal
    finally:
        reader.close()
    used = list(dict.fromkeys(cols.values()))
    try:
        if kinds == {"csv"}:
            ddf = dd.read_csv(
                files, usecols=used, dtype="float64", sep=sep, decimal=decimal, blocksize="64MB"
            )
        else:
            ddf = dd.read_parquet(files, columns=used)
    except (OSError, ValueError, KeyError) as exc:
        raise InputError(f"--dask {files[0]} ...: {exc}") from None
    return ddf, cols


def coverage(
    ctx: Context,
    model: Document | FunctionBlock,
    files: list[str],
    block: str | None,
    epsilon: float,
    scheduler: Any,
    progress: Callable[[int, int], None] | None,
) -> usage.Coverage:
    """See :func:`fuzzyctl.analysis.usage.coverage` (``dask=True``)."""
    require_dask()
    import dask

    ddf, cols = read(files, ctx.inputs)
    recipe = Recipe(model, block, cols, epsilon)
    _CONTEXTS[recipe.token] = ctx  # this process already has it
    delayed = dask.delayed  # type: ignore[attr-defined]
    tasks = [delayed(recipe)(part) for part in ddf.to_delayed()]
    total = usage.empty(ctx, cols)
    total.sources = files
    try:
        for part in _compute(tasks, scheduler, progress):
            total.merge(part)
    except (ValueError, TypeError) as exc:  # a cell that is not a number, a schema that differs
        raise InputError(f"--dask {files[0]} ...: {exc}") from None
    finally:
        _CONTEXTS.pop(recipe.token, None)
    return total


def _compute(tasks: list[Any], scheduler: Any, progress: Callable[[int, int], None] | None) -> Any:
    """The partitions' counts as they finish: on a ``distributed.Client`` (futures, as
    completed) or a named scheduler (in batches of a few per worker thread, for the progress)."""
    import dask

    n = len(tasks)
    if hasattr(scheduler, "compute") and hasattr(scheduler, "cancel"):  # a distributed.Client
        from distributed import as_completed

        futures = scheduler.compute(tasks)
        try:
            for done, fut in enumerate(as_completed(futures), start=1):  # type: ignore[no-untyped-call]
                yield fut.result()
                if progress:
                    progress(done, n)
        except BaseException:
            scheduler.cancel(futures)
            raise
        return
    step = 4 * max(1, dask.config.get("num_workers", None) or _cpus())
    for start in range(0, n, step):
        yield from dask.compute(*tasks[start : start + step], scheduler=scheduler)  # type: ignore[attr-defined,no-untyped-call]
        if progress:
            progress(min(n, start + step), n)


def _cpus() -> int:
    import os

    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1
