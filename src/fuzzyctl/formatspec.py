"""What the format registry (:mod:`fuzzyctl.formats`) knows of each built-in format before
its package is imported: the name, the file extensions, the size limit and a description.

It sits at the bottom of the stack so that the size limits apply to every reader, the FCL
parser below the registry included (:func:`fuzzyctl.limits.max_input_bytes`); a format's
package (``fuzzyctl/formats/<name>/``) builds its ``FORMAT`` from its entry here.  Each limit
lets every shape of file at the limit be read (accepted or refused) well within the 5 s of
issue 14 (benchmarks/large_inputs.py; docs/limits.md has the figures)."""

from __future__ import annotations

from dataclasses import dataclass

MiB = 1024 * 1024
DEFAULT_MAX_BYTES = 8 * MiB
"""The size limit of a model file of no known format."""


@dataclass(frozen=True)
class FormatSpec:
    """One built-in format: ``name``, ``extensions`` (lower case, with the dot), the largest
    file read (``max_bytes``) and what it is."""

    name: str
    extensions: tuple[str, ...]
    max_bytes: int
    description: str


BUILTIN: tuple[FormatSpec, ...] = (
    # the 10,000-rule 8-input system is 1.31 MiB; the largest real FCL file we know 290 KB
    FormatSpec("fcl", (".fcl",), MiB * 3 // 2, "IEC 61131-7 Fuzzy Control Language"),
    # FIS rules are dense (8 bytes each): 512 KiB is 65,000 rules (a 10,000-rule 4-input
    # FIS file is 191 KB, the largest real one 179 KB)
    FormatSpec(
        "fis", (".fis",), MiB // 2, "MATLAB / Octave Fuzzy Logic Toolbox FIS (and fuzzylite's FIS export)"
    ),
    # FLL's terse lines make the most model per byte (a Function term or a nested rule costs
    # three times what an FCL rule of that length does); the 10,000-rule system is 1.19 MiB,
    # the largest real FLL file 14 KB
    FormatSpec("fll", (".fll",), MiB * 3 // 2, "fuzzylite language (fuzzylite 5/6, pyfuzzylite 8)"),
    # JSON spells out every span (that 10,000-rule system is 43.5 MB) and is read by C
    FormatSpec(
        "json",
        (".json",),
        12 * DEFAULT_MAX_BYTES,
        "fuzzyctl model as JSON (lossless; schema in fuzzyctl/formats/json/fuzzyctl-model.schema.json)",
    ),
    # the largest project S7 Fuzzy Control allows (8 inputs of 7 terms, 4 outputs of 9, 200
    # rules; Siemens manual 1.3) is a 77 KB FPL file, 346 KB with 56 conditions a rule
    FormatSpec(
        "fpl", (".fpl",), MiB, "FPL of Siemens S7 Fuzzy Control (Togai InfraLogic subset, Siemens manual 1.3)"
    ),
    # an XFUZ block's tables are fixed in size (ESV 62, FA 576, RG 384 words): the examples
    # are 4 KB
    FormatSpec(
        "xfuz",
        (".xfuz",),
        MiB,
        "Schneider XFUZ knowledge-base tables ESV/FA/RG and constants (JSON or CSV layout)",
    ),
)
SPECS: dict[str, FormatSpec] = {spec.name: spec for spec in BUILTIN}
"""The built-in formats by name, in the registry's order."""
