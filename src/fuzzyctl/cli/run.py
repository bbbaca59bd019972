"""``fuzzyctl eval`` and ``fuzzyctl explain``: run a fuzzy controller on given inputs."""

from __future__ import annotations

import csv
import io
import json
import math
import os
import sys
import tempfile
from pathlib import Path
from typing import Annotated, Any

import typer

from fuzzyctl.cli.app import app

SetOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--set", "-s", help="An input value, NAME=VALUE (repeat for each input).", show_default=False
    ),
]
BlockOpt = Annotated[str | None, typer.Option("--block", help="Function block to run (default: the first).")]
CompatOpt = Annotated[
    str, typer.Option("--compat", help="Semantics: iec (default), fuzzylite, pyfuzzylite, jfuzzylogic.")
]
PROGRESS_ROWS = 100_000  # show a progress bar from this many rows on
CHUNK_ROWS = 50_000


def _controller(file: Path, block: str | None, compat: str) -> Any:
    import fuzzyctl

    return fuzzyctl.compile(fuzzyctl.load(file), block=block, compat=compat)


def _parse_sets(pairs: list[str] | None) -> dict[str, float]:
    from fuzzyctl.diagnostics import FuzzyctlError

    values: dict[str, float] = {}
    for item in pairs or []:
        name, sep, raw = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise typer.BadParameter(f"expected NAME=VALUE, got {item!r}", param_hint="--set")
        try:
            values[name] = float(raw)
        except ValueError:
            raise FuzzyctlError(f"input {name!r}: {raw.strip()!r} is not a number") from None
    return values


def _why_not_finite(ctl: Any, inputs: dict[str, float], result: dict[str, float]) -> list[str]:
    """One line per output that is not a finite number, with the reason (issue 14.6: such a
    value is never printed as if it were a result, the command exits 1)."""
    bad = [k for k, v in result.items() if not math.isfinite(v)]
    if not bad:
        return []
    fired: dict[str, bool] = {}
    try:  # the explanation tells "no rule fired" from "the arithmetic overflowed"
        fired = {o.name: o.fired for o in ctl.explain(inputs).outputs}
    except Exception:  # the reason is a courtesy: the value alone is enough to refuse
        fired = {}
    lines = []
    for k in bad:
        v = _fmt(result[k])
        if fired.get(k) is False:
            why = "no rule fired and its DEFAULT is not a number"
        else:
            why = "the inputs take the computation beyond the floating-point range"
        lines.append(f"output {k!r} is {v}: {why}")
    return lines


def _fmt(v: float) -> str:
    return repr(float(v)) if math.isfinite(v) else ("nan" if math.isnan(v) else ("inf" if v > 0 else "-inf"))


@app.command("eval")
def eval_(
    file: Annotated[Path, typer.Argument(help="Fuzzy system (FCL, FIS, FLL or JSON).", show_default=False)],
    set_: SetOpt = None,
    csv_in: Annotated[
        Path | None, typer.Option("--csv", help="Evaluate every row of a CSV file (header = input names).")
    ] = None,
    output: Annotated[
        Path | None, typer.Option("--output", "-o", help="Write the CSV result here (atomically).")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print the outputs as JSON.")] = False,
    as_table: Annotated[
        bool, typer.Option("--table", help="With --csv and no -o: print a table, not CSV.")
    ] = False,
    block: BlockOpt = None,
    compat: CompatOpt = "iec",
) -> None:
    """Evaluate a controller once (--set) or on every row of a CSV file (--csv)."""
    ctl = _controller(file, block, compat)
    if csv_in is not None:
        if set_:
            raise typer.BadParameter("use either --set or --csv", param_hint="--set")
        _eval_csv(ctl, csv_in, output, as_table)
        return
    if output is not None:
        raise typer.BadParameter("--output needs --csv", param_hint="--output")
    inputs = _parse_sets(set_)
    result = ctl.evaluate(inputs)
    problems = _why_not_finite(ctl, inputs, result)
    if as_json:
        typer.echo(json.dumps({k: (v if math.isfinite(v) else None) for k, v in result.items()}))
        _refuse_not_finite(problems)
        return
    from rich.console import Console
    from rich.table import Table

    table = Table(title=f"{ctl.name or file.name}", show_lines=False)
    table.add_column("output")
    table.add_column("value", justify="right")
    for k, v in result.items():
        table.add_row(k, f"{v:.10g}")
    Console(highlight=False).print(table)
    _refuse_not_finite(problems)


def _refuse_not_finite(problems: list[str]) -> None:
    if problems:
        from fuzzyctl.cli.app import err_console

        for line in problems:
            err_console.print(f"error: {line}", markup=False)
        raise typer.Exit(1)


def _eval_csv(ctl: Any, path: Path, output: Path | None, as_table: bool = False) -> None:
    import numpy as np

    from fuzzyctl.diagnostics import FuzzyctlError, InputError

    with open(path, newline="", encoding="utf-8-sig") as fh:
        rows = list(csv.reader(fh))
    if not rows:
        raise FuzzyctlError(f"{path}: empty CSV file (expected a header naming the inputs)")
    header = [h.strip() for h in rows[0]]
    body = [r for r in rows[1:] if any(cell.strip() for cell in r)]
    unknown = [h for h in header if h not in ctl.inputs]
    if unknown:
        raise InputError(f"{path}: column {unknown[0]!r} is not an input (inputs: {', '.join(ctl.inputs)})")
    missing = [
        n
        for n, spec in zip(ctl.inputs, ctl.plan.inputs, strict=True)
        if n not in header and spec.default is None
    ]
    if missing:
        raise InputError(f"{path}: no column for input {missing[0]!r}")
    cols = np.empty((len(header), len(body)))
    for r, row in enumerate(body):
        if len(row) != len(header):
            raise InputError(f"{path}:{r + 2}: expected {len(header)} cells, got {len(row)}")
        for c, cell in enumerate(row):
            try:
                v = float(cell)
            except ValueError:
                raise InputError(
                    f"{path}:{r + 2}: column {header[c]!r}: {cell.strip()!r} is not a number"
                ) from None
            if not math.isfinite(v):
                raise InputError(
                    f"{path}:{r + 2}: column {header[c]!r}: {cell.strip()!r} is not a finite number"
                )
            cols[c, r] = v
    n = len(body)
    results: dict[str, Any] = {o: np.empty(n) for o in ctl.outputs}
    show = n >= PROGRESS_ROWS and sys.stderr.isatty()
    from rich.progress import Progress

    with Progress(disable=not show, transient=True) as progress:
        task = progress.add_task(f"evaluating {path.name}", total=n)
        for start in range(0, n, CHUNK_ROWS):
            part = {h: cols[i, start : start + CHUNK_ROWS] for i, h in enumerate(header)}
            try:
                with np.errstate(all="ignore"):  # overflow is reported below, row by row
                    out = ctl.evaluate_batch(part)
            except InputError as exc:
                raise InputError(f"{path}: {exc} (data rows from {start + 1})") from None
            for k, v in out.items():
                results[k][start : start + CHUNK_ROWS] = v
            progress.advance(task, min(CHUNK_ROWS, n - start))
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    out_names = [o for o in ctl.outputs if o not in header]
    writer.writerow(rows[0] + out_names)
    for r, row in enumerate(body):
        writer.writerow(row + [_fmt(results[o][r]) for o in out_names])
    text = buf.getvalue()
    bad = [r for r in range(n) if not all(math.isfinite(results[o][r]) for o in out_names)]
    problems = []
    if bad:
        first = bad[0]
        row_inputs = {h: float(cols[i, first]) for i, h in enumerate(header)}
        detail = _why_not_finite(ctl, row_inputs, {o: float(results[o][first]) for o in out_names})
        problems = [
            f"{path}:{first + 2}: {detail[0] if detail else 'an output is not a number'}"
            + (f" ({len(bad)} rows have outputs that are not finite numbers)" if len(bad) > 1 else "")
        ]
    _write_csv_result(ctl, path, output, as_table, rows, body, out_names, results, text)
    _refuse_not_finite(problems)


def _write_csv_result(
    ctl: Any,
    path: Path,
    output: Path | None,
    as_table: bool,
    rows: list[list[str]],
    body: list[list[str]],
    out_names: list[str],
    results: dict[str, Any],
    text: str,
) -> None:
    if output is None and as_table:
        from rich.console import Console
        from rich.table import Table

        tab = Table(title=f"{ctl.name or ''}: {path.name}")
        for h in rows[0] + out_names:
            tab.add_column(h, justify="right")
        for r, row in enumerate(body):
            tab.add_row(*row, *(f"{results[o][r]:.10g}" for o in out_names))
        Console(highlight=False).print(tab)
        return
    if output is None:
        sys.stdout.write(text)
        return
    fd, tmp = tempfile.mkstemp(prefix=f".{output.name}.", dir=output.parent if str(output.parent) else ".")
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as fh:
            fh.write(text)
        os.replace(tmp, output)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


@app.command()
def explain(
    file: Annotated[Path, typer.Argument(help="Fuzzy system (FCL, FIS, FLL or JSON).", show_default=False)],
    set_: SetOpt = None,
    png: Annotated[
        Path | None, typer.Option("--png", help="Also draw the accumulated output sets to a PNG file.")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="The whole explanation as JSON.")] = False,
    width: Annotated[int, typer.Option("--width", help="Width of the text plot.")] = 64,
    block: BlockOpt = None,
    compat: CompatOpt = "iec",
) -> None:
    """Evaluate once and show why: term degrees, rule degrees, accumulated sets, values."""
    ctl = _controller(file, block, compat)
    e = ctl.explain(_parse_sets(set_))
    if png is not None:
        from fuzzyctl.engine.plot import save_png

        save_png(e, png)
    if as_json:
        typer.echo(json.dumps(e.to_dict(), indent=2))
        return
    from rich.console import Console
    from rich.table import Table

    from fuzzyctl.engine.plot import ascii_plot

    con = Console(highlight=False)
    inputs = Table(title="inputs")
    inputs.add_column("input")
    inputs.add_column("value", justify="right")
    for k, v in e.inputs.items():
        inputs.add_row(k, f"{v:.10g}")
    con.print(inputs)
    terms = Table(title="fuzzification (degree of each term)")
    for col in ("variable", "term", "degree"):
        terms.add_column(col, justify="right" if col == "degree" else "left")
    for t in (*e.terms, *e.chained):
        terms.add_row(t.variable, t.term, f"{t.degree:.6g}")
    con.print(terms)
    rules = Table(title="rules (condition degree, then each conclusion)")
    for col in ("block", "rule", "degree", "conclusion", "weight"):
        rules.add_column(col, justify="right" if col in ("degree", "weight") else "left")
    for r in e.rules:
        concl = ", ".join(f"{c.variable} IS {c.term}" if c.term else c.variable for c in r.conclusions)
        weights = ", ".join(f"{c.weight:g}" for c in r.conclusions)
        style = "" if r.fired else "dim"
        rules.add_row(r.block or "", r.label, f"{r.degree:.6g}", concl, weights, style=style)
    con.print(rules)
    outs = Table(title="outputs")
    for col in ("output", "value", "method", "accumulation", "fired"):
        outs.add_column(col, justify="right" if col == "value" else "left")
    for o in e.outputs:
        outs.add_row(
            o.name,
            f"{o.value:.10g}",
            o.method,
            o.accumulation or "per rule",
            "yes" if o.fired else "no (default)",
        )
    con.print(outs)
    for o in e.outputs:
        if o.kind == "ts" and o.weights:
            ts = Table(title=f"{o.name}: Takagi-Sugeno terms")
            for col in ("term", "weight", "z"):
                ts.add_column(col, justify="left" if col == "term" else "right")
            for name, w, z in o.weights:
                ts.add_row(name, f"{w:.6g}", f"{z:.6g}")
            con.print(ts)
        elif o.kind in ("mamdani", "singleton"):
            con.print(f"[bold]{o.name}[/bold]: accumulated set")
            con.print(ascii_plot(o, width=width), markup=False)
