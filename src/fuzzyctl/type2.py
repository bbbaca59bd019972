"""Interval type-2 systems and the parts of fuzzyctl that do not handle them yet: each
consumer's record in :data:`fuzzyctl.kinds.type_reduction.CONSUMERS` says whether it does;
:func:`refuse` raises that consumer's message for a type-2 model (docs/type2.md)."""

from __future__ import annotations

from fuzzyctl.diagnostics import FuzzyctlError, OptionError
from fuzzyctl.kinds import type_reduction as tr
from fuzzyctl.model import Document, FunctionBlock


class Type2NotSupported(FuzzyctlError):
    """A consumer that does not handle interval type-2 systems was given one."""


def is_type2(model: Document | FunctionBlock) -> bool:
    blocks = model.blocks if isinstance(model, Document) else (model,)
    return any(fb.is_type2 for fb in blocks)


def refuse(model: Document | FunctionBlock, consumer: str, supported: bool | None = None) -> None:
    """Raise :class:`Type2NotSupported` when ``model`` is type-2 and ``consumer`` (a name in
    ``CONSUMERS``; or ``supported``, a target record's own flag) does not handle it."""
    if not is_type2(model):
        return
    # (a target record's flag decides for a generator; the consumer's record otherwise)
    why = tr.refusal(consumer) if supported is None else (None if supported else tr.refusal("codegen"))
    if why:
        name = model.main.name if isinstance(model, Document) else model.name
        raise Type2NotSupported(f"{consumer}: {name or 'this system'} is an {why}")


def check_samples(samples: int | None, model: Document | FunctionBlock | None = None) -> None:
    """Refuse a ``--samples`` the command cannot use (:class:`OptionError` naming it): fewer
    than 2 points, or a model with no type-2 block - its outputs are integrated exactly and a
    sample count there would silently mean nothing.  ``model`` None checks the count only."""
    if samples is None:
        return
    if samples < 2:
        raise OptionError(f"--samples {samples}: at least 2 output samples are needed", "--samples")
    if model is not None and not is_type2(model):
        name = model.main.name if isinstance(model, Document) else model.name
        raise OptionError(
            f"--samples applies to interval type-2 systems; {name or 'this system'} is type-1 "
            "(its outputs are integrated exactly, not sampled)",
            "--samples",
        )
