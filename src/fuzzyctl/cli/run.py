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
StrictOpt = Annotated[
    bool,
    typer.Option(
        "--strict",
        help="Refuse what a strict IEC 61131-7 reading refuses: an output without RANGE whose terms "
        "do not fall to 0, names that are reserved keywords.",
    ),
]
PROGRESS_ROWS = 100_000  # show a progress bar from this many rows on
CHUNK_ROWS = 50_000


def _controller(file: Path, block: str | None, compat: str, strict: bool = False) -> Any:
    import fuzzyctl
    from fuzzyctl.cli.app import err_console

    ctl = fuzzyctl.compile(fuzzyctl.load(file, strict=strict), block=block, compat=compat, strict=strict)
    for d in ctl.warnings:  # what the engine settled with a warning (a universe from the terms, ...)
        err_console.print(d.render(), style="yellow", markup=False, highlight=False)
    return ctl


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
    strict: StrictOpt = False,
) -> None:
    """Evaluate a controller once (--set) or on every row of a CSV file (--csv)."""
    ctl = _controller(file, block, compat, strict)
    if csv_in is not None:
        if set_:
            raise typer.BadParameter("use either --set or --csv", param_hint="--set")
        _eval_csv(ctl, csv_in, output, as_table)
        return
    if output is not None:
        raise typer.BadParameter("--output needs --csv", param_hint="--output")
    result = ctl.evaluate(_parse_sets(set_))
    if as_json:
        typer.echo(json.dumps({k: (v if math.isfinite(v) else None) for k, v in result.items()}))
        return
    from rich.console import Console
    from rich.table import Table

    table = Table(title=f"{ctl.name or file.name}", show_lines=False)
    table.add_column("output")
    table.add_column("value", justify="right")
    for k, v in result.items():
        table.add_row(k, f"{v:.10g}")
    Console(highlight=False).print(table)


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
    strict: StrictOpt = False,
) -> None:
    """Evaluate once and show why: term degrees, rule degrees, accumulated sets, values."""
    ctl = _controller(file, block, compat, strict)
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
