"""The ``codegen --arith`` registry: complete records, two's-complement limits, clear refusals."""

from __future__ import annotations

import pytest

from fuzzyctl.codegen.emit import check_options
from fuzzyctl.diagnostics import OptionError
from fuzzyctl.kinds import arith


def test_integer_limits_are_twos_complement() -> None:
    assert (arith.get("int16").lowest, arith.get("int16").highest) == (-32768, 32767)
    assert (arith.get("int32").lowest, arith.get("int32").highest) == (-(2**31), 2**31 - 1)
    assert not arith.get(arith.DEFAULT).integer


@pytest.mark.parametrize("record", list(arith.ARITH.values()), ids=list(arith.ARITH))
def test_every_integer_record_names_its_types(record: arith.Arith) -> None:
    assert record.help
    if record.integer:
        for language in ("st", "c"):
            assert record.types[language] and record.wide_types[language]


def test_unknown_arithmetic_is_refused_naming_the_choices() -> None:
    with pytest.raises(ValueError, match="int16"):
        arith.get("int8")
    with pytest.raises(OptionError, match="known: float, int16, int32"):
        check_options("st", dialect=None, lreal=False, single=False, default=None, arith="int8")


def test_arith_is_refused_where_the_target_does_not_take_it() -> None:
    with pytest.raises(OptionError, match="--arith applies to"):
        check_options("fmu", dialect=None, lreal=False, single=False, default=None, arith="int16")
