"""Names the FLL reader and writer share: fuzzylite's norm and defuzzifier names as the
model spells them, and the words a rule reserves (the writer avoids them as names)."""

from __future__ import annotations

from fuzzyctl.kinds import methods

TNORMS = {
    "Minimum": "MIN",
    "AlgebraicProduct": "PROD",
    "BoundedDifference": "BDIF",
    "DrasticProduct": "DMIN",
    "EinsteinProduct": "EINSTEIN",
    "HamacherProduct": "HAMACHER",
    "NilpotentMinimum": "NIPMIN",
}
SNORMS_OR = {
    "Maximum": "MAX",
    "AlgebraicSum": "ASUM",
    "BoundedSum": "BSUM",
    "DrasticSum": "DMAX",
    "EinsteinSum": "EINSTEIN",
    "HamacherSum": "HAMACHER",
    "NilpotentMaximum": "NIPMAX",
}
SNORMS_ACCU = {
    "Maximum": "MAX",
    "AlgebraicSum": "PROBOR",
    "BoundedSum": "BSUM",
    "DrasticSum": "DMAX",
    "EinsteinSum": "EINSTEIN",
    "HamacherSum": "HAMACHER",
    "NilpotentMaximum": "NIPMAX",
    "UnboundedSum": "SUM",
}
DEFUZZIFIERS = methods.spelled("fll")  # kinds/methods.py
KEYWORDS = frozenset({"if", "then", "and", "or", "is", "with"})
HEDGE_WORDS = frozenset({"not", "very", "somewhat", "extremely", "seldom", "any"})
