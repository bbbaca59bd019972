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
    try:
        from fuzzyctl.api import compile_path

        ctl = compile_path(file, block=block, compat=compat)
        result = ctl.evaluate(values)
    except Exception:  # every error is reported by the full command line
        return None
    if not all(math.isfinite(v) for v in result.values()):
        return None  # an output without a value: the full command line says why and exits 1
    if as_json:
        import json

        print(json.dumps(result))
        return 0
    from rich.console import Console
    from rich.table import Table

    table = Table(title=f"{ctl.name or file.name}", show_lines=False)
    table.add_column("output", overflow="fold")  # as cli/run.py's _print_outputs
    table.add_column("value", justify="right", overflow="fold", no_wrap=False)
    for k, v in result.items():
        table.add_row(k, f"{v:.10g}")
    Console(highlight=False).print(table)
    return 0
