"""Coverage from data: which rules a logged run actually used (docs/analyze.md, "Coverage
from data").  Rule degrees are computed for every row with the analysis' own vectorised
leaf evaluation (:func:`fuzzyctl.analysis.cells.row_degrees`), the engine's formulas."""

from __future__ import annotations

import glob as globmod
from collections.abc import Callable
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from fuzzyctl.analysis import cells
from fuzzyctl.analysis.context import Context, FloatArray, build_context
from fuzzyctl.diagnostics import InputError

if TYPE_CHECKING:
    from fuzzyctl.model import Document, FunctionBlock

#: separators a logger puts between a prefix and an input's name (``ctl.temp``, ``in_temp``)
PREFIX_SEPARATORS = (".", "_", "/", ":")
#: the prefix of the fuzzy block's signals in a ``fuzzyctl simulate`` trace
SIMULATE_PREFIX = "fb."


#: degrees are summed exactly, as integers in units of 2**-SUM_SHIFT (every float64 in [0, 2)
#: is one), so the mean does not depend on how rows are split into batches or partitions
SUM_SHIFT = 1126
#: a float64's exponent from ``np.frexp`` is at least this (the smallest subnormal)
MIN_EXP = -1073


@dataclass
class RuleUse:
    rule: str
    where: str | None
    fired: int = 0
    dominated: int = 0
    exact_total: int = 0  # the sum of its degrees, times 2**SUM_SHIFT (exact)
    max_degree: float = 0.0

    @property
    def total(self) -> float:
        """The sum of its degrees over the rows, correctly rounded."""
        return float(Fraction(self.exact_total, 1 << SUM_SHIFT))

    def merge(self, other: RuleUse) -> None:
        self.fired += other.fired
        self.dominated += other.dominated
        self.exact_total += other.exact_total
        self.max_degree = max(self.max_degree, other.max_degree)

    def to_json(self, rows: int) -> dict[str, Any]:
        return {
            "rule": self.rule,
            "fired": self.fired,
            "dominated": self.dominated,
            "mean_degree": self.total / rows if rows else 0.0,
            "max_degree": self.max_degree,
        }


@dataclass
class Coverage:
    """Per-rule use over the rows of a log; rows in a gap or outside a RANGE."""

    sources: list[str]
    columns: dict[str, str]  # input -> column matched
    rows: int = 0  # rows evaluated (all inputs finite)
    invalid_rows: int = 0  # an input empty, NaN or infinite: skipped
    gap_rows: dict[str, int] = field(default_factory=dict)  # output -> rows no rule fired
    out_of_range: dict[str, int] = field(default_factory=dict)  # input -> rows outside RANGE
    rules: list[RuleUse] = field(default_factory=list)

    def merge(self, other: Coverage) -> None:
        """Add the counts of ``other`` (the same block, another part of the rows): sums and
        maxima, so the order of the parts does not matter."""
        self.rows += other.rows
        self.invalid_rows += other.invalid_rows
        for d, o in ((self.gap_rows, other.gap_rows), (self.out_of_range, other.out_of_range)):
            for k, n in o.items():
                d[k] = d.get(k, 0) + n
        for mine, theirs in zip(self.rules, other.rules, strict=True):
            mine.merge(theirs)

    @property
    def never_fired(self) -> list[str]:
        return [r.rule for r in self.rules if r.fired == 0]

    def to_json(self) -> dict[str, Any]:
        return {
            "sources": self.sources,
            "columns": self.columns,
            "rows": self.rows,
            "invalid_rows": self.invalid_rows,
            "rules": [r.to_json(self.rows) for r in self.rules],
            "never_fired": self.never_fired,
            "gap_rows": self.gap_rows,
            "out_of_range": self.out_of_range,
        }


def expand(data: str | Path | list[str | Path]) -> list[str]:
    """A file, a directory (its *.csv and *.parquet files) or a glob, as sorted file names."""
    items = data if isinstance(data, list) else [data]
    out: list[str] = []
    for item in items:
        p = Path(item)
        if p.is_dir():
            found = sorted(str(f) for f in p.iterdir() if f.suffix.lower() in (".csv", ".parquet", ".pq"))
        elif p.exists():
            found = [str(p)]
        else:
            found = sorted(globmod.glob(str(item)))
        if not found:
            raise InputError(f"{item}: no CSV or Parquet file there")
        out.extend(found)
    return out


def match_columns(inputs: tuple[str, ...], header: list[str], source: str) -> dict[str, str]:
    """Each input's column: ``fb.NAME`` (what ``fuzzyctl simulate`` records as the fuzzy
    block's input, beside the plant's own signals), else its own name, else
    (case-insensitively) the one column that ends with a separator and its name (a logger's
    prefix)."""
    got: dict[str, str] = {}
    for name in inputs:
        if SIMULATE_PREFIX + name in header or name in header:
            got[name] = SIMULATE_PREFIX + name if SIMULATE_PREFIX + name in header else name
            continue
        low = name.lower()
        cands = [h for h in header if h.lower() == low]
        cands = cands or [h for h in header if any(h.lower().endswith(s + low) for s in PREFIX_SEPARATORS)]
        if len(cands) != 1:
            why = "no column" if not cands else f"several columns ({', '.join(cands)})"
            raise InputError(
                f"{source}: {why} for input {name!r} (columns: {', '.join(header)}); name it {name!r} "
                f"or PREFIX.{name}"
            )
        got[name] = cands[0]
    return got


def coverage(
    model: Document | FunctionBlock,
    data: str | Path | list[str | Path],
    *,
    block: str | None = None,
    epsilon: float = 0.0,
    dask: bool = False,
    scheduler: Any = None,
    progress: Callable[[int, int], None] | None = None,
) -> Coverage:
    """How the rules of ``model`` were used over the rows of ``data`` (CSV/Parquet file,
    directory or glob).  A rule fires at a row when its degree is >= ``epsilon`` (0: > 0),
    as in :func:`fuzzyctl.analyze`; it dominates when it fired and no rule of an output it
    concludes has a higher degree there (ties: each one dominates).

    ``dask=True`` reads the files as one ``dask.dataframe`` and counts its partitions in
    parallel on ``scheduler`` (a ``distributed.Client``, or a Dask scheduler name such as
    ``"threads"``, ``"processes"``, ``"sync"``; None: Dask's default), then adds the counts
    up: the same numbers as the serial path.  ``progress(done, total)`` is called as
    partitions finish."""
    ctx = build_context(model, block)
    files = expand(data)
    if dask:
        from fuzzyctl.analysis import usage_dask

        return usage_dask.coverage(ctx, model, files, block, epsilon, scheduler, progress)
    cov: Coverage | None = None
    for i, source in enumerate(files):
        cov = _read_one(ctx, source, cov, epsilon)
        if progress:
            progress(i + 1, len(files))
    assert cov is not None
    cov.sources = files
    return cov


def empty(ctx: Context, cols: dict[str, str]) -> Coverage:
    """Zero counts for the block of ``ctx``, inputs read from ``cols``."""
    cov = Coverage([], cols)
    cov.rules = [RuleUse(n, w) for n, w in zip(ctx.rule_names, ctx.rule_where, strict=True)]
    cov.gap_rows = {op.name: 0 for op in ctx.plan.outputs if op.is_output}
    cov.out_of_range = dict.fromkeys(ctx.inputs, 0)
    return cov


def exact_sums(values: FloatArray) -> list[int]:
    """Each row's sum of ``values`` (shape (n, m), finite, in [0, 2)) exactly, in units of
    2**-SUM_SHIFT.  A float is M * 2**(e - 53) with an integer 53-bit M: split M into two
    halves, add the halves per (row, exponent) with ``bincount`` (exact: a chunk's sums stay
    under 2**51, the running int64 sums under 2**63 up to 2**36 rows), and shift each
    exponent's sum into place once at the end."""
    n, m = values.shape
    width = -MIN_EXP + 2  # exponents MIN_EXP .. 1
    hi = np.zeros(n * width, dtype=np.int64)
    lo = np.zeros(n * width, dtype=np.int64)
    step = max(1, min(1 << 24, (1 << 23) // max(n, 1)))  # about 8M values per chunk
    for start in range(0, m, step):
        chunk = values[:, start : start + step]
        rows, _cols = np.nonzero(chunk)  # most rules are 0 at most rows: only the others count
        mant, exp = np.frexp(chunk[rows, _cols])
        ints = np.ldexp(mant, 53).astype(np.int64)
        idx = rows * width + (exp - MIN_EXP)
        hi += np.bincount(idx, weights=ints >> 26, minlength=n * width).astype(np.int64)
        lo += np.bincount(idx, weights=ints & ((1 << 26) - 1), minlength=n * width).astype(np.int64)
    totals = [0] * n
    for k in np.flatnonzero(hi | lo).tolist():
        row, b = divmod(k, width)
        # exponent e = b + MIN_EXP: M * 2**(e - 53) * 2**SUM_SHIFT = M << (b + MIN_EXP - 53 + SUM_SHIFT)
        totals[row] += ((int(hi[k]) << 26) + int(lo[k])) << (b + MIN_EXP - 53 + SUM_SHIFT)
    return totals


def _fired(a: FloatArray, epsilon: float) -> Any:
    return a >= epsilon if epsilon > 0.0 else a > 0.0


def _read_one(ctx: Context, source: str, cov: Coverage | None, epsilon: float) -> Coverage:
    from fuzzyctl.tables import TableReader, numbers

    reader = TableReader(source)
    try:
        cols = match_columns(ctx.inputs, reader.header, reader.name)
        if cov is None:
            cov = empty(ctx, cols)
        for batch in reader.batches():
            values, invalid = numbers(reader, batch, list(dict.fromkeys(cols.values())))
            keep = ~invalid
            cov.invalid_rows += int(invalid.sum())
            columns = [values[cols[n]][keep] for n in ctx.inputs]
            count(ctx, cov, columns, epsilon)
    finally:
        reader.close()
    return cov


def count(ctx: Context, cov: Coverage, columns: list[FloatArray], epsilon: float) -> None:
    """Add the rows of ``columns`` (one finite array per input slot) to ``cov``."""
    plan = ctx.plan
    m = len(columns[0]) if columns else 0
    if m == 0:
        return
    cov.rows += m
    for name, (lo, hi), x in zip(ctx.inputs, ctx.ranges, columns, strict=True):
        cov.out_of_range[name] += int(np.count_nonzero((x < lo) | (x > hi)))
    degrees, best = cells.row_degrees(ctx, columns)
    fired = _fired(degrees, epsilon)
    # per output: the highest rule degree among the rules concluding it
    top: dict[int, FloatArray] = {}
    for ri, r in enumerate(plan.rules):
        for cp in r.conclusions:
            for o in cp.outputs:
                top[o] = np.maximum(top.get(o, np.zeros(m)), degrees[ri])
    sums = exact_sums(degrees)
    for ri, r in enumerate(plan.rules):
        use = cov.rules[ri]
        use.fired += int(np.count_nonzero(fired[ri]))
        use.exact_total += sums[ri]
        use.max_degree = max(use.max_degree, float(degrees[ri].max()))
        dom = np.zeros(m, dtype=bool)
        for cp in r.conclusions:
            for o in cp.outputs:
                dom |= degrees[ri] >= top[o]
        use.dominated += int(np.count_nonzero(dom & fired[ri]))
    for o, op in enumerate(plan.outputs):
        if op.is_output:
            cov.gap_rows[op.name] += int(np.count_nonzero(~_fired(best[o], epsilon)))


def table(cov: Coverage) -> Any:
    """A rich table of the per-rule counts."""
    from rich.table import Table

    t = Table(title=f"coverage over {cov.rows} rows", header_style="bold")
    for c in ("rule", "line", "fired", "dominated", "mean", "max"):
        t.add_column(c, justify="left" if c == "rule" else "right")
    for r in cov.rules:
        mean = r.total / cov.rows if cov.rows else 0.0
        line = r.where.rsplit(":", 1)[-1] if r.where else ""  # the file is in the header
        t.add_row(r.rule, line, str(r.fired), str(r.dominated), f"{mean:.3g}", f"{r.max_degree:.3g}")
    return t


def plot(cov: Coverage, path: Path) -> Path:
    """A bar chart of firing counts per rule (PNG); matplotlib without pyplot."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(max(6.0, 0.3 * len(cov.rules)), 4.0))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    names = [r.rule for r in cov.rules]
    ax.bar(range(len(names)), [r.fired for r in cov.rules], label="fired")
    ax.bar(range(len(names)), [r.dominated for r in cov.rules], label="dominated", alpha=0.7)
    ax.set_xticks(range(len(names)), names, rotation=90, fontsize=7)
    ax.set_ylabel(f"rows (of {cov.rows})")
    ax.set_title("rule firing counts")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    return path


def lines(cov: Coverage) -> list[str]:
    """The summary under the table: never-fired rules, gap rows, rows outside a RANGE."""
    out = [
        f"coverage: {cov.rows} rows from {len(cov.sources)} file(s), columns "
        + ", ".join(f"{k}<-{v}" if k != v else k for k, v in cov.columns.items())
    ]
    if cov.invalid_rows:
        out.append(f"  {cov.invalid_rows} row(s) with an empty, NaN or infinite input skipped")
    for r in cov.rules:
        if r.fired == 0:
            out.append(f"  never fired: rule {r.rule}" + (f" ({r.where})" if r.where else ""))
    out += [f"  {n} row(s) in a gap of {o} (no rule fired)" for o, n in cov.gap_rows.items() if n]
    out += [f"  {n} row(s) with {i} outside its RANGE" for i, n in cov.out_of_range.items() if n]
    return out
