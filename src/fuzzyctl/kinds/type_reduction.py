"""Interval type-2: the type-reduction methods, one entry each, and which consumers of a
model evaluate or generate type-2 systems (a flag on each consumer's record).

A type-reduction method computes the centroid interval ``[yl, yr]`` of an interval type-2
set (Mamdani: the aggregated output set; Sugeno: the rule outputs with their firing
intervals); the crisp output is ``(yl + yr) / 2``.  The four methods MATLAB offers
(``TypeReductionMethod``) find the same end points - on a discrete set each is exact - and
differ in how they search for the switch points: Karnik-Mendel iterates from the mean,
EKM (enhanced KM) starts from a better guess and updates sums incrementally, IASC and
EIASC scan the switch point from one end (enhanced: with an early stop).

Adding a method: an entry here and its function in :mod:`fuzzyctl.engine.type_reduction`
(named by ``reference``); tests/engine/test_type2.py checks every entry against brute force.

This module imports nothing of fuzzyctl (it sits at the bottom of the stack).
"""

from __future__ import annotations

import functools
import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class TypeReduction:
    """One type-reduction method."""

    code: str
    title: str
    #: format -> spellings accepted when reading (first: the one written)
    spellings: Mapping[str, tuple[str, ...]]
    #: ``"module:function"``: ``f(points, lower_weights, upper_weights) -> (yl, yr)``
    reference: str


METHODS: dict[str, TypeReduction] = {
    m.code: m
    for m in (
        TypeReduction(
            "KM",
            "Karnik-Mendel",
            {"fis": ("karnikmendel", "km"), "fcl": ("KM", "KARNIKMENDEL"), "json": ("KM",)},
            "fuzzyctl.engine.type_reduction:karnik_mendel",
        ),
        TypeReduction(
            "EKM",
            "enhanced Karnik-Mendel",
            {"fis": ("ekm",), "fcl": ("EKM",), "json": ("EKM",)},
            "fuzzyctl.engine.type_reduction:enhanced_karnik_mendel",
        ),
        TypeReduction(
            "IASC",
            "iterative algorithm with stopping condition",
            {"fis": ("iasc",), "fcl": ("IASC",), "json": ("IASC",)},
            "fuzzyctl.engine.type_reduction:iasc",
        ),
        TypeReduction(
            "EIASC",
            "enhanced iterative algorithm with stopping condition",
            {"fis": ("eiasc",), "fcl": ("EIASC",), "json": ("EIASC",)},
            "fuzzyctl.engine.type_reduction:eiasc",
        ),
    )
}
#: The method used when a system names none (MATLAB's default).
DEFAULT = "KM"


def spelled(fmt: str) -> dict[str, str]:
    """Spelling (lower-case) -> code, for reading ``fmt``."""
    return {s.lower(): m.code for m in METHODS.values() for s in m.spellings.get(fmt, ())}


def spelling(code: str | None, fmt: str) -> str:
    """How ``fmt`` writes the method ``code`` (``None``: the default)."""
    return METHODS[code or DEFAULT].spellings[fmt][0]


@functools.cache
def implementation(code: str | None) -> Callable[..., Any]:
    """The function of method ``code`` (``None``: the default)."""
    module, _, name = METHODS[code or DEFAULT].reference.partition(":")
    return getattr(importlib.import_module(module), name)  # type: ignore[no-any-return]


@dataclass(frozen=True)
class Consumer:
    """Something that reads a model: an engine backend, a generator, a tool.  ``type2``:
    it handles interval type-2 systems; else ``why`` says what to do instead."""

    name: str
    type2: bool
    why: str = ""


_GENERATE = (
    "interval type-2 code generation is not available yet; evaluate the system with "
    "`fuzzyctl eval`, or convert it to type-1 (`fuzzyctl convert --type1`) first"
)

CONSUMERS: dict[str, Consumer] = {
    c.name: c
    for c in (
        Consumer("interpreted", True),
        Consumer("python", True),
        Consumer("auto", True),  # (auto picks the Python path for type-2)
        Consumer("native", True),  # the IR evaluator in C, Mamdani outputs sampled
        Consumer("codegen", False, _GENERATE),
        Consumer(
            "analyze",
            False,
            "the analysis (coverage, cells, surface) reads the type-1 plan; evaluate the system "
            "with `fuzzyctl eval`, or convert it to type-1 (`fuzzyctl convert --type1`) first",
        ),
        Consumer(
            "type-1 engine",
            False,
            "the type-1 lowering (code generators, analysis, PLC blocks) does not take it; "
            "fuzzyctl.compile and `fuzzyctl eval` evaluate it",
        ),
        Consumer("blocks", False, _GENERATE),
        Consumer("studio", True),  # (footprint drawn and edited; docs/type2.md, "Studio")
        Consumer("tune", True),  # (lower functions free, kept below the upper; docs/type2.md, "Tune")
    )
}


def refusal(consumer: str) -> str | None:
    """Why ``consumer`` refuses an interval type-2 system, or None when it handles one."""
    record = CONSUMERS.get(consumer)
    if record is None or record.type2:
        return None
    return f"interval type-2 system: {record.why}"


def incomplete(m: TypeReduction) -> list[str]:
    """What entry ``m`` lacks (a test walks the registry)."""
    missing = [f"spelling in {fmt}" for fmt in ("fis", "fcl", "json") if not m.spellings.get(fmt)]
    if not m.reference:
        missing.append("reference")
    return missing
