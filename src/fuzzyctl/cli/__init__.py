"""The ``fuzzyctl`` command.  Each command group lives in its own module and registers
itself on :data:`app`; :func:`main` imports only the module of the command it is given
(:mod:`fuzzyctl.cli.commands`) and turns every error into a message and an exit code.

The console script starts in :mod:`fuzzyctl.cli.entry`, which answers the simplest
``fuzzyctl eval`` invocations without importing the command framework (see
:mod:`fuzzyctl.cli.quick`); importing this package imports nothing until used."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from fuzzyctl.cli.app import app, main

__all__ = ["app", "main"]


def __getattr__(name: str) -> Any:
    if name in ("app", "main"):
        import importlib

        return getattr(importlib.import_module("fuzzyctl.cli.app"), name)
    raise AttributeError(f"module 'fuzzyctl.cli' has no attribute {name!r}")
