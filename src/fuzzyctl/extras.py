"""What to tell a user whose installation lacks an optional extra (``tune``: cma, Dask).

fuzzyctl is installed from a clone (``make run`` runs ``pip install -e .``), not from a
package index: the hint names the clone's directory when this copy runs from one, so the
command it prints works as pasted."""

from __future__ import annotations

import importlib.util
from collections.abc import Sequence
from pathlib import Path

from fuzzyctl.diagnostics import FuzzyctlError


def install_hint(extra: str = "tune") -> str:
    """The pip command that adds ``extra`` to this installation."""
    root = Path(__file__).resolve().parents[2]
    if (root / "pyproject.toml").is_file():  # an editable install from a clone (make run)
        return f"pip install -e '{root}[{extra}]'"
    return f"pip install 'fuzzyctl[{extra}]'"


def require(modules: Sequence[str], what: str, extra: str = "tune") -> None:
    """Raise a :class:`FuzzyctlError` naming the extra when a module of ``modules`` is
    missing; ``what`` says what needs them ("CMA-ES", "--dask", ...)."""
    missing = [m for m in modules if importlib.util.find_spec(m) is None]
    if missing:
        raise FuzzyctlError(
            f"{what} needs the {extra} extra ({', '.join(missing)} missing): {install_hint(extra)}"
        )
