"""What the engine can evaluate: :func:`unsupported` reports everything else.

``fuzzyctl check`` shows these diagnostics next to the parser's; :func:`fuzzyctl.compile`
raises :class:`~fuzzyctl.diagnostics.DiagnosticError` with the errors among them.
"""

from __future__ import annotations

import dataclasses

from fuzzyctl.diagnostics import Diagnostic
from fuzzyctl.engine.lowering.lower import lower
from fuzzyctl.model import FunctionBlock


def unsupported(fb: FunctionBlock, *, compat: str = "iec", strict: bool = False) -> list[Diagnostic]:
    """Diagnostics for everything in ``fb`` the engine does not evaluate (errors) or
    evaluates by a decision worth knowing (warnings: duplicate term names, rule blocks that
    disagree on ACCU, outputs no rule concludes, a universe taken from the terms), under the
    semantics of ``compat`` (see :data:`fuzzyctl.engine.compile.COMPAT_PROFILES`)."""
    from fuzzyctl.engine.compile import COMPAT_PROFILES

    options = dataclasses.replace(COMPAT_PROFILES[compat], strict=strict)
    _plan, diags = lower(fb, options)
    return diags
