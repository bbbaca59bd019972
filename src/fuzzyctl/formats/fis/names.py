"""Names the FIS reader and writer share: MATLAB's method names as the model spells them,
and fuzzylite's hedge codes."""

from __future__ import annotations

from fuzzyctl.kinds import methods

AND_METHODS = {
    "min": "MIN",
    "prod": "PROD",
    "bounded_difference": "BDIF",
    "drastic_product": "DMIN",
    "einstein_product": "EINSTEIN",
    "hamacher_product": "HAMACHER",
    "nilpotent_minimum": "NIPMIN",
}
OR_METHODS = {
    "max": "MAX",
    "probor": "ASUM",
    "bounded_sum": "BSUM",
    "drastic_sum": "DMAX",
    "einstein_sum": "EINSTEIN",
    "hamacher_sum": "HAMACHER",
    "nilpotent_maximum": "NIPMAX",
}
AGG_METHODS = {
    "max": "MAX",
    "sum": "SUM",
    "probor": "PROBOR",
    "bounded_sum": "BSUM",
    "drastic_sum": "DMAX",
    "einstein_sum": "EINSTEIN",
    "hamacher_sum": "HAMACHER",
    "nilpotent_maximum": "NIPMAX",
}
#: MATLAB's defuzzMethod names (kinds/methods.py; ``centroid_integral``, a user-defined
#: function of the Octave toolkit's demos, is the centroid by integration: our exact COG)
DEFUZZ_METHODS = methods.spelled("fis")

# fuzzylite's hedge codes (FisImporter::translateProposition); "any" is resolved apart.
FUZZYLITE_HEDGE_CODES: dict[int, tuple[str, ...]] = {
    1: ("seldom",),
    5: ("somewhat",),
    20: ("very",),
    30: ("extremely",),
    40: ("very", "very"),
}
