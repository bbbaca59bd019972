"""Tables of samples for learning and tuning: CSV or Parquet files with a header, read with
pyarrow, split into training and validation rows."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from fuzzyctl.diagnostics import InputError

Arr = npt.NDArray[np.float64]
Columns = dict[str, Arr]


def read_table(source: str | Path | Mapping[str, Any] | Any, *, what: str = "data") -> Columns:
    """Numeric columns of a CSV/Parquet file, a mapping of arrays or a DataFrame (pandas,
    polars, pyarrow).  A missing file, a non-numeric or non-finite cell is an error naming
    the file, the column and the row."""
    if isinstance(source, str | Path):
        path = Path(source)
        if not path.exists():
            raise InputError(f"{path}: no such file ({what})")
        table = _read_file(path)
        where = str(path)
        cols = {name: table.column(name).to_numpy(zero_copy_only=False) for name in table.column_names}
    else:
        where = what
        if isinstance(source, Mapping):
            cols = dict(source)
        elif hasattr(source, "column_names") and hasattr(source, "column"):  # pyarrow Table
            cols = {n: source.column(n).to_numpy(zero_copy_only=False) for n in source.column_names}
        elif hasattr(source, "columns"):
            cols = {
                str(c): source[c].to_numpy() if hasattr(source[c], "to_numpy") else source[c]
                for c in source.columns
            }
        else:
            raise InputError(f"{what}: expected a CSV/Parquet path, a mapping of columns or a DataFrame")
    out: Columns = {}
    n = None
    for name, raw in cols.items():
        arr = _numeric(where, str(name), raw)
        if n is not None and len(arr) != n:
            raise InputError(f"{where}: column {name!r} has {len(arr)} values, expected {n}")
        n = len(arr)
        out[str(name).strip()] = arr
    if not out or not n:
        raise InputError(f"{where}: no rows")
    return out


def _read_file(path: Path) -> Any:
    try:
        import pyarrow.csv as pacsv
        import pyarrow.parquet as pq
    except ImportError as exc:  # pragma: no cover - the tune extra brings pyarrow
        raise InputError(f"reading {path} needs pyarrow: pip install -e . (it is a core dependency)") from exc
    import pyarrow as pa

    try:
        if path.suffix.lower() in (".parquet", ".pq"):
            return pq.read_table(path)
        return pacsv.read_csv(path)
    except (pa.ArrowInvalid, OSError) as exc:
        kind = "Parquet" if path.suffix.lower() in (".parquet", ".pq") else "CSV"
        raise InputError(f"{path}: cannot read it as {kind}: {exc}") from None


def _numeric(where: str, name: str, raw: Any) -> Arr:
    try:
        arr = np.asarray(raw, dtype=np.float64)
    except (TypeError, ValueError):
        items = list(raw)
        for i, v in enumerate(items):
            try:
                float(v)
            except (TypeError, ValueError):
                raise InputError(f"{where}: column {name!r}, row {i + 1}: {v!r} is not a number") from None
        raise InputError(f"{where}: column {name!r} is not numeric") from None
    arr = arr.reshape(-1)
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        raise InputError(
            f"{where}: column {name!r}, row {int(bad[0]) + 1}: {arr[bad[0]]} is not a finite number"
        )
    return arr


def require(cols: Columns, names: Sequence[str], where: str) -> None:
    missing = [n for n in names if n not in cols]
    if missing:
        raise InputError(f"{where}: no column {missing[0]!r} (columns: {', '.join(cols)})")


@dataclass(frozen=True)
class Split:
    """Training and validation rows (validation may be empty)."""

    train: Columns
    validation: Columns | None


def split(cols: Columns, fraction: float, seed: int) -> Split:
    """A seeded random ``fraction`` of the rows for validation (none when 0)."""
    if not 0.0 <= fraction < 1.0 or math.isnan(fraction):
        raise InputError(f"validation fraction must be in [0, 1), got {fraction}")
    n = len(next(iter(cols.values())))
    k = round(fraction * n)
    if fraction == 0.0 or k == 0:
        return Split(cols, None)
    if n - k < 2:
        raise InputError(f"{n} rows are too few to keep {fraction:g} of them for validation")
    order = np.random.default_rng(seed).permutation(n)
    val, tr = np.sort(order[:k]), np.sort(order[k:])
    return Split({c: a[tr] for c, a in cols.items()}, {c: a[val] for c, a in cols.items()})


def rows(cols: Columns) -> int:
    return len(next(iter(cols.values()))) if cols else 0


def loss_value(kind: str, sse: float, sae: float, worst: float, n: int) -> float:
    """RMSE, MAE or max error from sums over ``n`` residuals."""
    if n == 0:
        return 0.0
    if kind == "rmse":
        return math.sqrt(sse / n)
    if kind == "mae":
        return sae / n
    return worst


LOSSES = ("rmse", "mae", "max")
