"""The ``fuzzyctl`` command.  Each command group lives in its own module and registers
itself on :data:`app`; :func:`main` turns every error into a message and an exit code."""

from fuzzyctl.cli.app import app, main

__all__ = ["app", "main"]
