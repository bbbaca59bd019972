"""Names the FIS reader and writer share: MATLAB's method names as the model spells them,
and fuzzylite's hedge codes."""

from __future__ import annotations

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
DEFUZZ_METHODS = {
    "centroid": "COG",
    "bisector": "COA",
    "mom": "MOM",
    "som": "LM",
    "lom": "RM",
    "wtaver": "WTAVER",
    "wtsum": "WTSUM",
    # A user-defined function of the Octave toolkit's demos: the centroid by integration,
    # which is what our COG computes exactly.
    "centroid_integral": "COG",
}

# fuzzylite's hedge codes (FisImporter::translateProposition); "any" is resolved apart.
FUZZYLITE_HEDGE_CODES: dict[int, tuple[str, ...]] = {
    1: ("seldom",),
    5: ("somewhat",),
    20: ("very",),
    30: ("extremely",),
    40: ("very", "very"),
}
