"""``fuzzyctl eval FILE --set NAME=VALUE ... [--json] [--block B] [--compat C]`` without the
command framework: typer, rich (with ``--json``) and numpy are not imported, and with the
caches warm (:mod:`fuzzyctl.cache`) the file is not parsed and not lowered and the native
library is not built: a start costs little more than Python's own.

Anything else - another command, another option, ``--help``, an error of any kind - returns
None and the full command line handles it (and reports errors its way), so this path never
changes what the command does, only how fast it starts.
"""

from __future__ import annotations

import math
import os
import re
import sys
from pathlib import Path


def _parse(argv: list[str]) -> tuple[Path, list[str], bool, str | None, str] | None:
    """(file, NAME=VALUE items, --json, --block, --compat), or None when the arguments are
    not this simple form."""
    if not argv or argv[0] != "eval":
        return None
    file: str | None = None
    sets: list[str] = []
    as_json, block, compat = False, None, "iec"
    args = argv[1:]
    i = 0
    while i < len(args):
        a = args[i]
        value: str | None = None
        if a.startswith("--") and "=" in a:
            a, value = a.split("=", 1)
        if a in ("--set", "-s", "--block", "--compat"):
            if value is None:
                if i + 1 >= len(args):
                    return None
                i += 1
                value = args[i]
            if a in ("--set", "-s"):
                sets.append(value)
            elif a == "--block":
                block = value
            else:
                compat = value
        elif a == "--json" and value is None:
            as_json = True
        elif a.startswith("-") or file is not None:
            return None
        else:
            file = a
        i += 1
    if file is None or not sets:
        return None
    return Path(file), sets, as_json, block, compat


def try_quick(argv: list[str]) -> int | None:
    """Run the simple ``eval`` form; None when the full command line must handle ``argv``."""
    parsed = _parse(argv)
    if parsed is None:
        return None
    file, sets, as_json, block, compat = parsed
    values: dict[str, float] = {}
    for item in sets:
        name, sep, raw = item.partition("=")
        try:
            values[name.strip()] = float(raw)
        except ValueError:
            return None
        if not sep or not name.strip():
            return None
    from fuzzyctl.cli import quick_record

    record, key = quick_record.lookup(file, block, compat)
    result = record.run(values) if record is not None else None
    if record is not None and result is not None:
        title, warnings, ranges = record.title, record.warnings, record.ranges
    else:
        try:
            from fuzzyctl.api import compile_path
            from fuzzyctl.diagnostics import render_all

            ctl = compile_path(file, block=block, compat=compat)
            title, warnings = f"{ctl.name or file.name}", render_all(ctl.warnings)
            if key is not None:
                quick_record.save(key, ctl, title)
            ranges = ctl.input_ranges
            result = ctl.evaluate(values, out_of_range="ignore")  # warned about below
        except Exception:  # every error is reported by the full command line
            return None
    if not all(math.isfinite(v) for v in result.values()):
        return None  # an output without a value: the full command line says why and exits 1
    from fuzzyctl.cli.quick_record import outside_lines

    for line in warnings:  # as cli/run.py's _controller (without its colour)
        print(line, file=sys.stderr)
    for line in outside_lines(ranges, values):  # as cli/run.py's _checked_sets
        print(f"warning: {line}", file=sys.stderr)
    if as_json:
        import json

        print(json.dumps(result))
        return 0
    rows = [(k, f"{v:.10g}") for k, v in result.items()]
    text = plain_table(title, rows) if _plain_console() else None
    if text is not None:
        sys.stdout.write(text)
        return 0
    from rich.console import Console
    from rich.table import Table

    table = Table(title=title, show_lines=False)
    table.add_column("output", overflow="fold")  # as cli/run.py's _print_outputs
    table.add_column("value", justify="right", overflow="fold", no_wrap=False)
    for k, v in rows:
        table.add_row(k, v)
    Console(highlight=False).print(table)
    return 0


#: where rich would render differently from :func:`plain_table` (colour forced, another width)
_RICH_ENV = ("FORCE_COLOR", "TTY_COMPATIBLE", "TTY_INTERACTIVE", "COLUMNS", "JUPYTER_COLUMNS")
_PLAIN = re.compile(r"[A-Za-z0-9_.+\- ]*\Z")


def _plain_console() -> bool:
    """Output to a file or pipe, where rich draws without colour at 80 columns."""
    return not sys.stdout.isatty() and not any(k in os.environ for k in _RICH_ENV)


def plain_table(title: str, rows: list[tuple[str, str]]) -> str | None:
    """The two-column table rich prints to a file or pipe (heavy head box, title centred above
    it), without importing rich (~60 ms of a start); None where rich would do more than draw
    it (markup or wide characters in a name, a title or table that must wrap)."""
    if not all(_PLAIN.match(t) for t in (title, *(c for r in rows for c in r))):
        return None
    w0 = max(len("output"), *(len(r[0]) for r in rows))
    w1 = max(len("value"), *(len(r[1]) for r in rows))
    width = w0 + w1 + 7  # three bars and a space either side of each cell
    if width > 80 or len(title) > width or not title.strip() or title != title.strip():
        return None
    pad = width - len(title)
    lines = [" " * (pad // 2) + title + " " * (pad - pad // 2)]
    lines.append(f"┏{'━' * (w0 + 2)}┳{'━' * (w1 + 2)}┓")
    lines.append(f"┃ {'output'.ljust(w0)} ┃ {'value'.rjust(w1)} ┃")
    lines.append(f"┡{'━' * (w0 + 2)}╇{'━' * (w1 + 2)}┩")
    lines += [f"│ {a.ljust(w0)} │ {b.rjust(w1)} │" for a, b in rows]
    lines.append(f"└{'─' * (w0 + 2)}┴{'─' * (w1 + 2)}┘")
    return "\n".join(lines) + "\n"
