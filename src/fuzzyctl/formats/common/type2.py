"""What a type-1 format cannot express of an interval type-2 model, and the type-1 model it
can: each term keeps its upper membership function (the footprint of uncertainty and the
type-reduction method are dropped, and said so)."""

from __future__ import annotations

from dataclasses import replace

from fuzzyctl.formats import Loss
from fuzzyctl.model import Document, FunctionBlock


def type2_losses(fb: FunctionBlock, target: str) -> list[Loss]:
    """One loss per type-2 term of ``fb`` and one for the type reduction."""
    losses = [
        Loss(
            f"term {t.name!r} of {b.variable!r}",
            f"{target} has no interval type-2 terms: the lower membership function is dropped "
            "(the term becomes its upper function)",
        )
        for blocks in (fb.fuzzify, fb.defuzzify)
        for b in blocks
        for t in b.terms
        if t.lower is not None
    ]
    if any(d.type_reduction for d in fb.defuzzify) or losses:
        losses.append(
            Loss(
                "type reduction",
                f"{target} has no type reduction: outputs are defuzzified as type-1 sets "
                "(results differ from the type-2 system's)",
            )
        )
    return losses


def to_type1(fb: FunctionBlock) -> FunctionBlock:
    """``fb`` with every term reduced to its upper membership function."""
    return replace(
        fb,
        fuzzify=tuple(replace(f, terms=tuple(replace(t, lower=None) for t in f.terms)) for f in fb.fuzzify),
        defuzzify=tuple(
            replace(d, terms=tuple(replace(t, lower=None) for t in d.terms), type_reduction=None)
            for d in fb.defuzzify
        ),
    )


def drop_type2(document: Document, target: str) -> tuple[Document, list[Loss]]:
    """The type-1 document ``target`` can write, and what was dropped."""
    losses = [loss for fb in document.blocks for loss in type2_losses(fb, target)]
    return replace(document, blocks=tuple(to_type1(fb) for fb in document.blocks)), losses
