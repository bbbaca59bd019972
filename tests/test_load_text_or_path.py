"""``fuzzyctl.load`` tells a path from source text: text with line ends of any kind (FLL reads
U+2028 as one) is source, a name the file system cannot take is an error, never an OSError
(found by the differential fuzzer: a mutant with U+2028 line ends crashed ``load``)."""

from __future__ import annotations

import pytest

import fuzzyctl
from fuzzyctl.diagnostics import DiagnosticError
from tests.conftest import DATA

FLL = DATA / "fuzzylite" / "takagi-sugeno" / "octave" / "linear_tip_calculator.fll"


@pytest.mark.parametrize("line_end", ["\u2028", "\u2029", "\x85", "\x0b", "\x0c"])
def test_text_with_any_line_end_is_source_not_a_path(line_end: str) -> None:
    text = FLL.read_text().replace("\n", line_end)
    try:
        doc = fuzzyctl.load(text, format="fll")
    except DiagnosticError as exc:  # refused by the reader with a diagnostic is fine too
        assert "no such file" not in str(exc) and "cannot read" not in str(exc)
    else:
        assert doc.blocks


def test_a_name_too_long_for_the_file_system_is_a_diagnostic() -> None:
    with pytest.raises(DiagnosticError, match=r"cannot read|no such file"):
        fuzzyctl.load("x" * 300)
