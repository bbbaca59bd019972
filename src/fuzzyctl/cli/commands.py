"""The command modules, each registering its commands on the app when imported.

A command line imports only the module of the command it names (``fuzzyctl eval`` reads
:mod:`fuzzyctl.cli.run`, nothing of codegen or the studio); ``fuzzyctl --help`` lists
:data:`COMMANDS` without importing any.  ``tests/cli/test_help.py`` checks that this table
is what the modules register: the same commands, in the same order, with the same summaries."""

from __future__ import annotations

import importlib
from dataclasses import dataclass

__all__ = ["COMMANDS", "MODULES", "Listed", "import_all", "import_for"]


@dataclass(frozen=True)
class Listed:
    """A top-level command as ``fuzzyctl --help`` lists it: the module that registers it and
    the first paragraph of its help."""

    module: str
    summary: str


#: Every top-level command, in the order the help lists them (the modules' import order,
#: then sub-apps such as ``blocks``, as typer places them).
COMMANDS: dict[str, Listed] = {
    "analyze": Listed(
        "analyze",
        "Find where no rule fires (gaps), rules that contradict each other, duplicate, subsumed\n"
        "and dead rules, unused terms, monotonicity violations and the output surface's range,\n"
        "slope and jumps, before the controller meets the plant.",
    ),
    "codegen": Listed(
        "codegen",
        "Generate a PLC function block (ST) or embedded C that computes exactly what the engine\n"
        "computes.  Anything the target cannot express is refused with a message naming it.",
    ),
    "convert": Listed("convert", "Convert a fuzzy system to another format."),
    "check": Listed(
        "lang",
        "Validate a model and report the IEC 61131-7 conformance level it needs as FCL (exit 1\n"
        "on errors).  FCL gets every check; another format gets the model's checks and the\n"
        "engine's, and the report names the checks of FCL text it did not run.",
    ),
    "fmt": Listed("lang", "Print a model in canonical IEC 61131-7 FCL form (exit 1 if it does not load)."),
    "eval": Listed(
        "run",
        "Evaluate a controller once (--set), on every row of a data file (--data), or on a\n"
        "directory/glob of Parquet/CSV files on Dask (--dask DATA -o DIR).",
    ),
    "explain": Listed(
        "run", "Evaluate once and show why: term degrees, rule degrees, accumulated sets, values."
    ),
    "serve": Listed(
        "serve", "Run fuzzy function blocks cyclically against field I/O (OPC UA, Modbus TCP, S7)."
    ),
    "simulate": Listed(
        "simulate",
        "Simulate a closed loop; print its quality figures and write CSV, PNG and HTML (all three\n"
        "into the current directory unless options name which; --json writes only what is named).",
    ),
    "studio": Listed(
        "studio",
        "Start the studio: edit, analyse, simulate and download fuzzy knowledge bases in a\n"
        "web browser.  Prints its URL (with the token the browser needs); Ctrl-C stops it.",
    ),
    "learn": Listed(
        "tune", "Learn a fuzzy system from data: grid partition or clustering, consequents by least squares."
    ),
    "tune": Listed(
        "tune", "Tune a fuzzy system against data or a closed-loop cost (Ctrl-C keeps the best so far)."
    ),
    "blocks": Listed(
        "blocks", "Run PLC fuzzy function blocks against a CSV of input samples, one row per cycle."
    ),
}

#: The command modules, in the order they are imported (which gives the help's order).
MODULES: tuple[str, ...] = (
    "analyze",  # static checks of a rule base
    "blocks",  # fuzzyctl blocks ...
    "codegen",
    "convert",
    "lang",  # check, fmt
    "run",  # eval, explain
    "serve",  # the soft controller
    "simulate",
    "studio",  # the browser configuration tool
    "tune",  # learn, tune
)


def import_for(name: str) -> bool:
    """Import the module of command ``name``; False when no command has that name."""
    listed = COMMANDS.get(name)
    if listed is None:
        return False
    importlib.import_module(f"fuzzyctl.cli.{listed.module}")
    return True


def import_all() -> None:
    """Import every command module (what a command line naming no known command needs)."""
    for module in MODULES:
        importlib.import_module(f"fuzzyctl.cli.{module}")
