"""The PLC function blocks of :mod:`fuzzyctl.blocks` as loop runtimes: the block is called
once per controller cycle, exactly as a cyclic interrupt of the PLC would call it.

* :class:`SiemensRuntime` - the S7 FUZZY block (FB30): inputs written to INPUT1..8 (single
  precision REALs, clamped to MIN/MAX by the block), ``execute()``, outputs read from
  OUTPUT1..4; an output no rule concerns keeps its last value.
* :class:`XfuzRuntime` - the Schneider XFUZ block in automatic, continuous mode
  (``MAN_AUTO = 1``, ``CONT_ASK = 0``, ``START = 1``, ``T_OFB`` = one cycle).  Its inputs
  and outputs are 16-bit words, so, as a PLC engineer does, the controller is rescaled
  first: every input (and output) gets a power-of-ten factor, as large as the words allow,
  that the term abscissae (singleton positions) are multiplied by; the measured value is
  multiplied by the same factor and rounded to a word, the output word divided by its
  factor.  ``input_scale``/``output_scale`` fix the factors instead.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace
from typing import TypeVar

from fuzzyctl.diagnostics import InputError
from fuzzyctl.model import (
    DefuzzifyBlock,
    Document,
    FunctionBlock,
    FuzzifyBlock,
    PointsMF,
    Range,
    SingletonMF,
    Term,
)

WORD_MAX = 32767

_Block = TypeVar("_Block", FuzzifyBlock, DefuzzifyBlock)


def _main(model: Document | FunctionBlock, block: str | None) -> FunctionBlock:
    if isinstance(model, FunctionBlock):
        return model
    if block is None:
        return model.main
    for fb in model.blocks:
        if fb.name == block:
            return fb
    raise InputError(f"no function block {block!r} (blocks: {', '.join(str(b.name) for b in model.blocks)})")


class SiemensRuntime:
    """The Siemens S7 FUZZY block (``fuzzyctl.blocks.siemens.FuzzyFB``)."""

    def __init__(self, model: Document | FunctionBlock, *, block: str | None = None) -> None:
        from fuzzyctl.blocks.siemens import FuzzyFB

        self.application = _main(model, block)
        self.block_name = self.application.name or ""
        self.fb = FuzzyFB(self.application)
        self.name = "siemens"
        self.inputs = self.fb.input_names
        self.outputs = self.fb.output_names

    def evaluate(self, inputs: Mapping[str, float]) -> dict[str, float]:
        self.fb.set_inputs({name: inputs[name] for name in self.inputs})
        info = self.fb.execute()
        if info:
            raise InputError(f"the Siemens FUZZY block answered INFO = B#16#{info:02X}")
        return self.fb.output_values()

    def reset(self) -> None:
        """A fresh instance DB: the configuration tool downloads the application again."""
        from fuzzyctl.blocks.siemens import FuzzyFB

        self.fb = FuzzyFB(self.application)


def _xs(mf: object) -> list[float]:
    if isinstance(mf, PointsMF):
        return [float(p.x) for p in mf.points]  # type: ignore[arg-type]
    if isinstance(mf, SingletonMF):
        return [float(mf.value)]  # type: ignore[arg-type]
    return []


def _scaled_term(term: Term, factor: float) -> Term:
    mf = term.mf
    if isinstance(mf, PointsMF):
        points = tuple(replace(p, x=float(p.x) * factor) for p in mf.points)  # type: ignore[arg-type]
        return replace(term, mf=PointsMF(points))
    if isinstance(mf, SingletonMF):
        return replace(term, mf=SingletonMF(float(mf.value) * factor))  # type: ignore[arg-type]
    raise InputError(
        f"term {term.name!r}: the xfuz runtime rescales points and singleton terms only "
        f"(got {type(mf).__name__})"
    )


def _auto_factor(values: list[float]) -> float:
    """The largest power of ten (at most 10^6) that keeps every value within a word and turns
    the values into whole numbers (to 1e-9); at least 1, with rounding if no power does."""
    largest = max((abs(v) for v in values), default=1.0) or 1.0
    best = 1.0
    for k in range(0, 7):
        f = 10.0**k
        if largest * f > WORD_MAX:
            break
        best = f
    for k in range(int(math.log10(best)), -1, -1):
        f = 10.0**k
        if all(abs(v * f - round(v * f)) < 1e-9 for v in values):
            return best if best >= f else f
    return best


def scale_model(fb: FunctionBlock, factors: Mapping[str, float]) -> FunctionBlock:
    """``fb`` with the abscissae of the named variables' terms (and their RANGE) multiplied
    by the factors; rules and operators unchanged."""

    def rng(r: Range | None, f: float) -> Range | None:
        return None if r is None else replace(r, low=r.low * f, high=r.high * f)

    def scaled(b: _Block) -> _Block:
        if b.variable not in factors:
            return b
        f = factors[b.variable]
        return replace(b, terms=tuple(_scaled_term(t, f) for t in b.terms), range=rng(b.range, f))

    return replace(
        fb, fuzzify=tuple(scaled(b) for b in fb.fuzzify), defuzzify=tuple(scaled(b) for b in fb.defuzzify)
    )


class XfuzRuntime:
    """The Schneider XFUZ block (``fuzzyctl.blocks.schneider.XfuzFB``) on a rescaled controller."""

    def __init__(
        self,
        model: Document | FunctionBlock,
        *,
        block: str | None = None,
        cycle: float = 0.01,
        input_scale: Mapping[str, float] | None = None,
        output_scale: Mapping[str, float] | None = None,
    ) -> None:
        from fuzzyctl.diagnostics import DiagnosticError
        from fuzzyctl.formats.xfuz.writer import constants_from_model, slot_labels

        fb = _main(model, block)
        self.block_name = fb.name or ""
        self.name = "xfuz"
        self.cycle = cycle
        self.inputs = tuple(v.name for v in fb.inputs)
        self.outputs = tuple(v.name for v in fb.outputs)
        factors: dict[str, float] = {}
        blocks: list[FuzzifyBlock | DefuzzifyBlock] = [*fb.fuzzify, *fb.defuzzify]
        for b in blocks:
            given = (input_scale or {}).get(b.variable, (output_scale or {}).get(b.variable))
            factors[b.variable] = (
                float(given) if given else _auto_factor([x for t in b.terms for x in _xs(t.mf)])
            )
        self.factors = factors
        scaled = scale_model(fb, factors)
        # XFUZ samples outputs between BorneInf and BorneSup; without a RANGE the engine uses
        # the hull of the terms, so give the block the same.
        scaled = replace(
            scaled,
            defuzzify=tuple(
                b if b.range is not None else replace(b, range=Range(min(xs), max(xs)))
                for b in scaled.defuzzify
                for xs in [[x for t in b.terms for x in _xs(t.mf)] or [0.0, 1.0]]
            ),
        )
        constants, diags = constants_from_model(scaled)
        if any(d.is_error for d in diags):
            raise DiagnosticError(diags)
        self.constants = replace(constants, contask=False, t_ofb=0)
        self.slots = slot_labels(scaled)
        self.reset()

    def reset(self) -> None:
        """A cold restart, then automatic mode with continuous inference every call."""
        from fuzzyctl.blocks.schneider import XfuzFB

        self.fb = XfuzFB(self.constants, task_period=self.cycle)
        if self.fb.ERROR:
            raise InputError(f"the XFUZ block refuses the knowledge base: STATUS bits {self.fb.status_bits}")
        self.fb.MAN_AUTO, self.fb.CONT_ASK, self.fb.START, self.fb.T_OFB = 1, 0, 1, 0

    def evaluate(self, inputs: Mapping[str, float]) -> dict[str, float]:
        for name in self.inputs:
            word = round(inputs[name] * self.factors.get(name, 1.0))
            self.fb[self.slots[name]] = min(max(word, -WORD_MAX - 1), WORD_MAX)
        self.fb.execute(self.cycle)
        if self.fb.ERROR:
            raise InputError(f"the XFUZ block reports an error: STATUS bits {self.fb.status_bits}")
        return {name: self.fb[self.slots[name]] / self.factors.get(name, 1.0) for name in self.outputs}
