"""What the engine can evaluate: :func:`unsupported` reports everything else.

``fuzzyctl check`` shows these diagnostics next to the parser's; :func:`fuzzyctl.compile`
raises :class:`~fuzzyctl.diagnostics.DiagnosticError` with the errors among them.
"""

from __future__ import annotations

from fuzzyctl.diagnostics import Diagnostic
from fuzzyctl.engine.lower import lower
from fuzzyctl.model import FunctionBlock


def unsupported(fb: FunctionBlock) -> list[Diagnostic]:
    """Diagnostics for everything in ``fb`` the engine does not evaluate (errors) or
    evaluates by a decision worth knowing (warnings: duplicate term names, rule blocks that
    disagree on ACCU, outputs no rule concludes)."""
    _plan, diags = lower(fb)
    return diags
