"""``compile()``: model -> :class:`~fuzzyctl.engine.controller.Controller`."""

from __future__ import annotations

import dataclasses
from typing import Any

from fuzzyctl.diagnostics import DiagnosticError, FuzzyctlError
from fuzzyctl.engine.controller import Controller
from fuzzyctl.engine.lowering.lower import lower
from fuzzyctl.engine.plan import Options
from fuzzyctl.model import Document, FunctionBlock

#: Semantic switches reproducing other tools (for cross-checks and migrations); the default
#: ``"iec"`` is IEC 61131-7 as documented in docs/engine.md.
COMPAT_PROFILES: dict[str, Options] = {
    "iec": Options(),
    # fuzzylite 6 (C++), the tool that produced the .fld reference files.  Its conclusion
    # hedges carrying over to the next conclusions is a matter of reading its rule text: our
    # FLL and FIS readers resolve it; for fuzzylite's FCL exports add hedges_carry_over=True.
    "fuzzylite": Options(
        weight_before_activation=True,
        firing_threshold=1e-6,
        ts_default_accu="SUM",
        singleton_default_accu="SUM",
    ),
    # pyfuzzylite 8: like fuzzylite but no firing threshold and per-conclusion hedges
    "pyfuzzylite": Options(
        weight_before_activation=True, ts_default_accu="SUM", singleton_default_accu="SUM"
    ),
    # jFuzzyLogic 3.3, reproduced by engine/compat/jfl.py (docs/engine.md, "jfuzzylogic profile")
    "jfuzzylogic": Options(
        weight_before_activation=True,
        weight_whole_rule=True,
        span_universe=True,
        ignore_declared_range=True,
        emulate="jfuzzylogic",
    ),
}


def compile_block(
    model: Document | FunctionBlock,
    *,
    block: str | None = None,
    backend: str = "python",
    compat: str = "iec",
    **options: Any,
) -> Controller:
    """Compile a function block into a :class:`Controller`.

    ``block`` picks a function block of a document by name (default: the first).  ``backend``
    is ``"python"`` (specialised Python for single evaluations, numpy for batches) or
    ``"interpreted"`` (the reference interpreter only).  ``compat`` picks a semantic profile
    (:data:`COMPAT_PROFILES`); keyword ``options`` override single fields of
    :class:`~fuzzyctl.engine.plan.Options`.  Raises :class:`DiagnosticError` when the block
    uses something the engine does not evaluate."""
    if isinstance(model, Document):
        try:
            fb = model.block(block)
        except KeyError as exc:
            raise FuzzyctlError(str(exc.args[0])) from None
    elif isinstance(model, FunctionBlock):
        if block is not None and model.name != block:
            raise FuzzyctlError(f"no function block {block!r} (this one is {model.name!r})")
        fb = model
    else:
        raise TypeError(f"compile() takes a Document or a FunctionBlock, not {type(model).__name__}")
    if fb.is_type2:  # the type-1 lowering would take each term's upper function silently
        from fuzzyctl.type2 import refuse

        refuse(fb, "type-1 engine")
    if compat not in COMPAT_PROFILES:
        raise FuzzyctlError(f"unknown compat profile {compat!r} (known: {', '.join(COMPAT_PROFILES)})")
    opts = COMPAT_PROFILES[compat]
    if options:
        known = {f.name for f in dataclasses.fields(Options)}
        bad = sorted(set(options) - known)
        if bad:
            raise FuzzyctlError(f"unknown compile option {bad[0]!r} (known: {', '.join(sorted(known))})")
        opts = dataclasses.replace(opts, **options)
    if backend not in ("python", "interpreted"):
        raise FuzzyctlError(f"unknown backend {backend!r} (available: python, interpreted, native)")
    plan, diags = lower(fb, opts)
    path = getattr(model, "path", None) if isinstance(model, Document) else None
    if plan is None:
        raise DiagnosticError([dataclasses.replace(d, file=d.file or path) for d in diags])
    controller = Controller(plan, specialise=backend == "python", model=fb)
    controller.warnings = tuple(dataclasses.replace(d, file=d.file or path) for d in diags)
    return controller
