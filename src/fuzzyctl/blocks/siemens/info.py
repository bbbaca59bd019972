"""INFO codes of the Siemens FUZZY block and of FUZZY_AI / FUZZY_AO (3.1-3.3)."""

from __future__ import annotations

from enum import IntEnum

__all__ = ["Info"]


class Info(IntEnum):
    """The INFO byte (B#16#..)."""

    OK = 0x00
    """No error occurred during processing."""
    DISABLED = 0x01
    """Warning: START_STOP = W#16#0000, nothing recalculated (old values kept)."""
    NO_APPLICATION = 0x11
    """No valid fuzzy application (set of rules) in the instance data block."""
    DB_TOO_SHORT = 0x21
    """Length of the data block not sufficient (not a fuzzy data block)."""
    BAD_NUMBER = 0x31
    """FUZZY_AI: INPUT_NR not 1..8; FUZZY_AO: OUTPUT_NR not 1..4."""

    def __str__(self) -> str:
        return f"{self.value:02X}"
