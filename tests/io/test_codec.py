"""Wire encodings against independent byte layouts (IEEE 754 bit patterns)."""

from __future__ import annotations

import math

import pytest

from fuzzyctl.io.codec import (
    float32_from_registers,
    float32_to_registers,
    int16_from_register,
    real_from_bytes,
    real_to_bytes,
    scaled_from_raw,
    scaled_to_raw,
)
from fuzzyctl.io.modbus import ModbusPoint, plan_reads, plan_writes


def test_float32_word_orders_follow_the_ieee_bit_pattern() -> None:
    # 1.0 = 0x3F800000, -2.5 = 0xC0200000, 123.456 ~ 0x42F6E979
    assert float32_to_registers(1.0, "big") == (0x3F80, 0x0000)
    assert float32_to_registers(1.0, "little") == (0x0000, 0x3F80)
    assert float32_to_registers(-2.5, "big") == (0xC020, 0x0000)
    assert float32_to_registers(123.456, "big") == (0x42F6, 0xE979)
    assert float32_from_registers(0x42F6, 0xE979, "big") == pytest.approx(123.456, rel=1e-7)
    assert float32_from_registers(0xE979, 0x42F6, "little") == pytest.approx(123.456, rel=1e-7)
    assert math.isnan(float32_from_registers(0x7FC0, 0, "big"))
    assert float32_to_registers(1e300) == (0x7F80, 0)  # beyond float32: +inf


def test_int16_scaling_rounds_half_away_and_saturates() -> None:
    assert int16_from_register(0xFFFF) == -1 and int16_from_register(0xFFFF, signed=False) == 65535
    assert scaled_from_raw(-250, 0.1, 0.0) == pytest.approx(-25.0)
    assert scaled_to_raw(12.25, 0.5, 0.0) == 25  # 24.5 -> 25 (half away from zero)
    assert scaled_to_raw(-12.25, 0.5, 0.0) == -25
    assert scaled_to_raw(1e9, 1.0, 0.0) == 32767 and scaled_to_raw(-1e9, 1.0, 0.0) == -32768
    assert scaled_to_raw(-5.0, 1.0, 0.0, signed=False) == 0
    assert scaled_to_raw(20.0, 0.5, 10.0) == 20  # (20 - 10) / 0.5
    with pytest.raises(ValueError):
        scaled_to_raw(math.nan, 1.0, 0.0)


def test_s7_real_is_big_endian_ieee_single() -> None:
    assert real_to_bytes(1.0) == b"\x3f\x80\x00\x00"
    assert real_from_bytes(b"\x00\x00\xc0\x20\x00\x00", 2) == -2.5


def test_modbus_read_plan_merges_near_points_and_respects_the_request_limit() -> None:
    pts = [ModbusPoint(address=a) for a in (0, 2, 4, 40, 300)] + [ModbusPoint(table="input", address=2)]
    plan = plan_reads(pts, max_gap=8)
    spans = [(s.table, s.start, s.count) for s, _ in plan]
    assert spans == [("holding", 0, 6), ("holding", 40, 2), ("holding", 300, 2), ("input", 2, 2)]
    assert sorted(i for _, members in plan for i in members) == list(range(6))
    wide = [ModbusPoint(address=a) for a in range(0, 300, 2)]
    assert all(s.count <= 125 for s, _ in plan_reads(wide))
    runs = plan_writes([ModbusPoint(address=10), ModbusPoint(address=12, type="int16")], [1.0, -3.0])
    assert runs == [("holding", 10, [0x3F80, 0, 0xFFFD])]


def test_modbus_point_validation_names_the_problem() -> None:
    with pytest.raises(ValueError, match="runs past register 65535"):
        ModbusPoint(address=65535)
    with pytest.raises(ValueError, match="scale"):
        ModbusPoint(address=1, type="int16", scale=0)
    with pytest.raises(ValueError, match="Extra inputs"):
        ModbusPoint.model_validate({"address": 1, "adress": 2})
