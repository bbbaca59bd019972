"""FUZZY_AI (FC30) and FUZZY_AO (FC31): normalisation between the analog I/O range
(±27648) and the limits of a fuzzy input or output (Siemens manual 3.2 and 3.3).

Formulas, with Xmin/Xmax the MIN/MAX of the input or output in the fuzzy data block::

    AI bipolar      INPUT = (Xmin (27648 - Xi) + Xmax (Xi + 27648)) / (2 * 27648) * FACTOR + OFFSET
    AI unipolar     INPUT = (Xmin (27648 - Xi) + Xmax Xi) / 27648 * FACTOR + OFFSET
    AI thermocouple INPUT = Xi / 10.0 * FACTOR + OFFSET
    AO bipolar      Xq = 27648 (2 OUTPUT - Xmax - Xmin) / (Xmax - Xmin) * FACTOR + OFFSET
    AO unipolar     Xq = 27648 (OUTPUT - Xmin) / (Xmax - Xmin) * FACTOR + OFFSET

The thermocouple formula is printed as ``Xi / (10.0 * FACTOR + OFFSET)`` in the OCR text;
modules deliver tenths of a degree and FACTOR/OFFSET are "the gradient and offset of the
normalisation line", so we read it as the line ``Xi / 10 * FACTOR + OFFSET``.

With BIPOLAR and MIN/MAX that are not symmetric the manual warns that values "may be
calculated incorrectly" (3.2, 3.3 notes): the formula is applied as printed and the
result's ``warning`` says so (the ``siemens`` profile says it ahead, ``bipolar=``).

INFO, checked in this order and stopping at the first that applies ("execution is stopped
immediately"): 21 the data block is not a fuzzy data block of sufficient length, 11 no
valid fuzzy application in it, 31 INPUT_NR not 1..8 / OUTPUT_NR not 1..4, 01 START_STOP =
0.  On any of them nothing is written.  ENO (status bit BR) is true exactly when INFO = 00.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

from fuzzyctl.blocks.siemens.info import Info
from fuzzyctl.diagnostics import InputError

__all__ = ["AnalogResult", "FuzzyDataBlock", "fuzzy_ai", "fuzzy_ao"]

FULL_SCALE = 27648
"""The nominal range of S7 analog modules: ±27648 (bipolar) or 0..27648 (unipolar)."""
DB_FUZZY_LENGTH = 2126
"""Length of the FUZZY instance data block at runtime (3.4, "Block length at runtime")."""


class FuzzyDataBlock(Protocol):
    """What FUZZY_AI/AO use of a fuzzy data block (a :class:`~fuzzyctl.blocks.siemens.FuzzyFB`)."""

    START_STOP: int
    db_length: int

    @property
    def has_application(self) -> bool: ...

    def input_limits(self, number: int) -> tuple[float, float]: ...

    def output_limits(self, number: int) -> tuple[float, float]: ...

    def write_input(self, number: int, value: float) -> None: ...

    def read_output(self, number: int) -> float: ...


@dataclass(frozen=True)
class AnalogResult:
    """What one call returns: INFO, ENO and, when INFO = 00, the value written.

    ``value`` is the REAL written to the fuzzy input (FUZZY_AI) or the normalisation
    value Xq (FUZZY_AO); ``word`` is Xq as the INT written to the analog output module
    (rounded to nearest, saturated to -32768..32767)."""

    info: int
    value: float | None = None
    word: int | None = None
    warning: str | None = None
    """Set when a bipolar signal meets asymmetric MIN/MAX (3.2, 3.3 notes: the value "may be
    calculated incorrectly"); the value is computed by the manual's formula all the same."""

    @property
    def eno(self) -> bool:
        return self.info == Info.OK


def _check_db(db: object) -> Info | None:
    length = getattr(db, "db_length", None)
    if length is None or not hasattr(db, "START_STOP") or length < DB_FUZZY_LENGTH:
        return Info.DB_TOO_SHORT
    if not getattr(db, "has_application", False):
        return Info.NO_APPLICATION
    return None


def _refusal(db: FuzzyDataBlock, number: int, count: int) -> Info | None:
    """Why a FUZZY_AI/FUZZY_AO call does nothing (in the order the blocks check): the data
    block, a channel ``number`` outside 1..``count``, or a stopped block (START_STOP = 0)."""
    bad = _check_db(db)
    if bad is not None:
        return bad
    if not 1 <= number <= count:
        return Info.BAD_NUMBER
    if db.START_STOP == 0:
        return Info.DISABLED
    return None


def _bipolar_warning(what: str, number: int, x_min: float, x_max: float) -> str | None:
    if x_min == -x_max:
        return None
    return (
        f"{what}{number}: MIN {x_min:g} and MAX {x_max:g} are not symmetric; with a bipolar signal "
        "the value may be calculated incorrectly (manual 3.2/3.3: give e.g. -100.0 and +100.0)"
    )


def _raw_word(name: str, value: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not -32768 <= value <= 32767:
        raise InputError(f"{name} = {value!r}: the analog value is a 16-bit integer (-32768..32767)")
    return value


def fuzzy_ai(
    fuzzy_db: FuzzyDataBlock,
    ai_value: int,
    *,
    bipolar: bool = False,
    therm_el: bool = False,
    factor: float = 1.0,
    offset: float = 0.0,
    input_nr: int = 1,
) -> AnalogResult:
    """FUZZY_AI: normalise the analog input word ``ai_value`` (the value read at AI_ADR)
    and write it to input ``input_nr`` of ``fuzzy_db``.  THERM_EL takes precedence over
    BIPOLAR (the manual lists THERM_EL = TRUE only with BIPOLAR = FALSE)."""
    refused = _refusal(fuzzy_db, input_nr, 8)
    if refused is not None:
        return AnalogResult(refused)
    xi = _raw_word("AI value", ai_value)
    note = None
    if therm_el:
        value = xi / 10.0 * factor + offset
    else:
        x_min, x_max = fuzzy_db.input_limits(input_nr)
        if bipolar:
            value = (x_min * (FULL_SCALE - xi) + x_max * (xi + FULL_SCALE)) / (
                2 * FULL_SCALE
            ) * factor + offset
            note = _bipolar_warning("INPUT", input_nr, x_min, x_max)
        else:
            value = (x_min * (FULL_SCALE - xi) + x_max * xi) / FULL_SCALE * factor + offset
    fuzzy_db.write_input(input_nr, value)
    return AnalogResult(Info.OK, value, warning=note)


def fuzzy_ao(
    fuzzy_db: FuzzyDataBlock,
    *,
    bipolar: bool = False,
    factor: float = 1.0,
    offset: float = 0.0,
    output_nr: int = 1,
) -> AnalogResult:
    """FUZZY_AO: normalise output ``output_nr`` of ``fuzzy_db`` to the analog range; the
    result's ``word`` is what goes to AO_ADR.  An output whose MIN equals its MAX has no
    normalisation line and is reported as INFO 11 (no valid application for it)."""
    refused = _refusal(fuzzy_db, output_nr, 4)
    if refused is not None:
        return AnalogResult(refused)
    x_min, x_max = fuzzy_db.output_limits(output_nr)
    if x_max == x_min:
        return AnalogResult(Info.NO_APPLICATION)
    out = fuzzy_db.read_output(output_nr)
    note = None
    if bipolar:
        xq = FULL_SCALE * (2 * out - x_max - x_min) / (x_max - x_min) * factor + offset
        note = _bipolar_warning("OUTPUT", output_nr, x_min, x_max)
    else:
        xq = FULL_SCALE * (out - x_min) / (x_max - x_min) * factor + offset
    rounded = math.floor(abs(xq) + 0.5) * (1 if xq >= 0 else -1)
    return AnalogResult(Info.OK, xq, int(min(max(rounded, -32768), 32767)), warning=note)
