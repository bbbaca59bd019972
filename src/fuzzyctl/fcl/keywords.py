"""Operator and method keywords: every spelling seen in the wild mapped onto the canonical
upper-case name stored in the model (see the keyword sets at the end of ``fuzzyctl.model``).

Each table maps an upper-cased spelling to ``(canonical, origin)``; ``origin`` says where the
spelling comes from and is shown by ``docs/fcl.md``.  Verified against the tools' sources:
jFuzzyLogic ``RuleBlock.createAccumulationMethod`` / ``fclTree`` and ``FunctionBlock.
createDefuzzifier``; fuzzylite ``FclExporter::toString(const Norm*)`` and
``toString(const Defuzzifier*)``.
"""

from __future__ import annotations

from typing import Final

from fuzzyctl.kinds.methods import METHODS

Synonyms = dict[str, tuple[str, str]]

IEC = "IEC 61131-7"
JFL = "jFuzzyLogic"
FL = "fuzzylite FCL export"

_T_NORMS: Final[Synonyms] = {
    "MIN": ("MIN", IEC + " Table 3: min(a, b)"),
    "PROD": ("PROD", IEC + " Table 3: a * b"),
    "BDIF": ("BDIF", IEC + " Table 3: max(0, a + b - 1)"),
    "DMIN": ("DMIN", JFL + ": drastic product"),
    "DPROD": ("DMIN", FL + ": DrasticProduct"),
    "NIPMIN": ("NIPMIN", JFL + ": nilpotent minimum"),
    "NMIN": ("NIPMIN", FL + ": NilpotentMinimum"),
    "HAMACHER": ("HAMACHER", JFL + ": Hamacher product ab / (a + b - ab)"),
    "HPROD": ("HAMACHER", FL + ": HamacherProduct"),
    "EINSTEIN": ("EINSTEIN", "Einstein product ab / (2 - (a + b - ab))"),
    "EPROD": ("EINSTEIN", FL + ": EinsteinProduct"),
}

_S_NORMS: Final[Synonyms] = {
    "MAX": ("MAX", IEC + " Table 3: max(a, b)"),
    "ASUM": ("ASUM", IEC + " Table 3: a + b - ab"),
    "PROBOR": ("ASUM", JFL + "/MATLAB probabilistic or, the same formula as ASUM"),
    "BSUM": ("BSUM", IEC + " Table 3: min(1, a + b)"),
    "DMAX": ("DMAX", JFL + ": drastic sum"),
    "DSUM": ("DMAX", FL + ": DrasticSum"),
    "NIPMAX": ("NIPMAX", JFL + ": nilpotent maximum"),
    "NMAX": ("NIPMAX", FL + ": NilpotentMaximum"),
    "EINSTEIN": ("EINSTEIN", JFL + ": Einstein sum (a + b) / (1 + ab)"),
    "ESUM": ("EINSTEIN", FL + ": EinsteinSum"),
    "HAMACHER": ("HAMACHER", "Hamacher sum (a + b - 2ab) / (1 - ab)"),
    "HSUM": ("HAMACHER", FL + ": HamacherSum"),
}

AND_SYNONYMS: Final[Synonyms] = dict(_T_NORMS)
OR_SYNONYMS: Final[Synonyms] = dict(_S_NORMS)
ACT_SYNONYMS: Final[Synonyms] = dict(_T_NORMS)

ACCU_SYNONYMS: Final[Synonyms] = {
    "MAX": ("MAX", IEC + " Table 5: maximum"),
    "BSUM": ("BSUM", IEC + " Table 5: bounded sum min(1, a + b)"),
    "NSUM": ("NSUM", IEC + " Table 5: normalised sum (a + b) / max(1, max over x of (a + b))"),
    "SUM": ("SUM", JFL + ": unbounded sum a + b"),
    "UNBSUM": ("SUM", FL + ": UnboundedSum"),
    "PROBOR": ("PROBOR", JFL + ": probabilistic or a + b - ab"),
    "ASUM": ("PROBOR", FL + ": AlgebraicSum a + b - ab (jFuzzyLogic spells it PROBOR in ACCU)"),
    "DMAX": ("DMAX", "drastic sum"),
    "DSUM": ("DMAX", FL + ": DrasticSum"),
    "NIPMAX": ("NIPMAX", "nilpotent maximum"),
    "NMAX": ("NIPMAX", FL + ": NilpotentMaximum"),
    "EINSTEIN": ("EINSTEIN", "Einstein sum"),
    "ESUM": ("EINSTEIN", FL + ": EinsteinSum"),
    "HAMACHER": ("HAMACHER", "Hamacher sum"),
    "HSUM": ("HAMACHER", FL + ": HamacherSum"),
}

#: the spellings each method's entry lists for FCL, with their notes (kinds/methods.py)
METHOD_SYNONYMS: Final[Synonyms] = {
    spelling: (m.code, note) for m in METHODS.values() for spelling, note in m.notes.items()
}

# fuzzylite writes NONE for a missing norm; it means "not given".
NONE_SPELLINGS: Final = frozenset({"NONE"})


def canonical(table: Synonyms, spelling: str) -> str | None:
    """The canonical keyword for ``spelling`` (case-insensitive), ``None`` when unknown."""
    hit = table.get(spelling.upper())
    return hit[0] if hit else None
