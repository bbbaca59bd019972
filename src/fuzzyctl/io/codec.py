"""Wire encodings shared by the connectors: IEEE single precision in big-endian bytes (S7
REAL, Modbus FLOAT32 registers) and scaled 16-bit integers.

Word order of a FLOAT32 over two Modbus registers: ``"big"`` puts the high word in the
first register (ABCD, the Modbus convention and most PLCs), ``"little"`` the low word
first (CDAB, e.g. many Schneider and some Siemens devices).  Bytes within a register are
always big-endian, as the Modbus specification requires.
"""

from __future__ import annotations

import math
import struct
from typing import Literal

__all__ = [
    "WordOrder",
    "float32_from_registers",
    "float32_to_registers",
    "int16_from_register",
    "int16_to_register",
    "real_from_bytes",
    "real_to_bytes",
    "scaled_from_raw",
    "scaled_to_raw",
]

WordOrder = Literal["big", "little"]
_F32 = struct.Struct(">f")
_H2 = struct.Struct(">HH")


def float32_to_registers(value: float, word_order: WordOrder = "big") -> tuple[int, int]:
    """The two registers of a FLOAT32 (values beyond the float32 range become +-inf)."""
    try:
        raw = _F32.pack(value)
    except OverflowError:
        raw = _F32.pack(math.copysign(math.inf, value))
    high, low = _H2.unpack(raw)
    return (high, low) if word_order == "big" else (low, high)


def float32_from_registers(first: int, second: int, word_order: WordOrder = "big") -> float:
    high, low = (first, second) if word_order == "big" else (second, first)
    return float(_F32.unpack(_H2.pack(high & 0xFFFF, low & 0xFFFF))[0])


def int16_from_register(register: int, signed: bool = True) -> int:
    """A register (0..65535 on the wire) as INT16 (signed) or UINT16."""
    register &= 0xFFFF
    return register - 0x10000 if signed and register >= 0x8000 else register


def int16_to_register(value: int) -> int:
    """An INT16 or UINT16 value as the register's 0..65535 wire value."""
    return value & 0xFFFF


def scaled_from_raw(raw: int, scale: float, offset: float) -> float:
    """Engineering value of a scaled integer: ``raw * scale + offset``."""
    return raw * scale + offset


def scaled_to_raw(value: float, scale: float, offset: float, *, signed: bool = True) -> int:
    """The integer that represents ``value``: ``(value - offset) / scale`` rounded to the
    nearest (halves away from zero) and saturated to the type's range; NaN raises
    ValueError (the runtime never writes NaN, see docs/runtime.md)."""
    if math.isnan(value):
        raise ValueError("NaN has no integer representation")
    low, high = (-32768, 32767) if signed else (0, 65535)
    x = (value - offset) / scale
    if math.isinf(x):
        return high if x > 0 else low
    n = math.floor(abs(x) + 0.5)
    n = n if x >= 0 else -n
    return min(max(n, low), high)


def real_to_bytes(value: float) -> bytes:
    """An S7 REAL (big-endian IEEE single) as 4 bytes."""
    try:
        return _F32.pack(value)
    except OverflowError:
        return _F32.pack(math.copysign(math.inf, value))


def real_from_bytes(data: bytes | bytearray, offset: int = 0) -> float:
    return float(_F32.unpack_from(data, offset)[0])
