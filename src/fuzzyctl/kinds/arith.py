"""Arithmetic of generated code: one record per ``codegen --arith`` choice.

``float`` computes in the target's floating type (REAL, or LREAL with ``--lreal``; C double,
or float with ``--float``).  The integer records compute in fixed point in a signed integer
of ``bits`` bits: the builders read the record (storage type per target, the range of a
stored value); nothing else compares arithmetic names.

This module imports nothing of fuzzyctl, so every layer may read it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

__all__ = ["ARITH", "DEFAULT", "INT_OUTPUTS", "Arith", "choices", "get"]


@dataclass(frozen=True)
class Arith:
    """One arithmetic.  ``types`` maps a builder language (``st``, ``c``) to the storage type
    of a value (empty for ``float``: the target's real type is used); ``bits`` is the width
    of a stored value (0 for ``float``)."""

    name: str
    help: str
    bits: int = 0
    types: Mapping[str, str] = field(default_factory=dict)
    #: the type twice as wide, for products before they are rescaled (language -> type)
    wide_types: Mapping[str, str] = field(default_factory=dict)

    @property
    def integer(self) -> bool:
        return self.bits > 0

    @property
    def lowest(self) -> int:
        """The smallest stored value (two's complement)."""
        return -(1 << (self.bits - 1)) if self.bits else 0

    @property
    def highest(self) -> int:
        """The largest stored value."""
        return (1 << (self.bits - 1)) - 1 if self.bits else 0


FLOAT = Arith("float", "REAL/LREAL (ST), double/float (C)")
INT16 = Arith(
    "int16",
    "16-bit fixed point: INT (ST), int16_t (C)",
    bits=16,
    types=MappingProxyType({"st": "INT", "c": "int16_t"}),
    wide_types=MappingProxyType({"st": "DINT", "c": "int32_t"}),
)
INT32 = Arith(
    "int32",
    "32-bit fixed point: DINT (ST), int32_t (C)",
    bits=32,
    types=MappingProxyType({"st": "DINT", "c": "int32_t"}),
    wide_types=MappingProxyType({"st": "LINT", "c": "int64_t"}),
)

#: ``codegen --arith`` choices, in the order the CLI lists them.
ARITH: MappingProxyType[str, Arith] = MappingProxyType({a.name: a for a in (FLOAT, INT16, INT32)})
DEFAULT = FLOAT.name


def choices() -> tuple[str, ...]:
    return tuple(ARITH)


def get(name: str) -> Arith:
    """The record of ``name``; an unknown name is refused with the known ones."""
    try:
        return ARITH[name]
    except KeyError:
        raise ValueError(f"unknown arithmetic {name!r} (known: {', '.join(ARITH)})") from None


#: ``codegen --int-output``: how an integer block stores an output (``value = stored * scale +
#: offset`` either way; the header and ``--json`` give both numbers).
INT_OUTPUTS: MappingProxyType[str, str] = MappingProxyType(
    {
        "scaled": "the finest power-of-ten scale that holds the output's values (default)",
        "unit": "the output's own engineering unit (scale 1): coarser, rounded to whole units",
    }
)
