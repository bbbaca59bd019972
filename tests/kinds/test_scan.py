"""No comparison against a kind name outside its registry (tests/kinds/scan.py says what a
kind comparison is): a decision that depends on the kind of a shape, a defuzzification
method, a code-generation target or a norm is a field of that kind's entry."""

from __future__ import annotations

import pytest

from tests.kinds import scan

#: Comparisons that read a kind-like name but compare something else spelled like an entry:
#: (file, literal) -> what it is.
OTHER_MEANING: dict[tuple[str, str], str] = {
    ("sim/profiles.py", "constant"): "a set-point profile kind (constant, sine, step...)",
    ("studio/analysis.py", "constant"): "a test signal kind of the studio's analysis",
    ("studio/analysis.py", "triangle"): "a test signal kind of the studio's analysis",
    ("formats/fpl/parse.py", "MIN"): "FPL's VAR keyword for the low end of the range",
    ("formats/fpl/parse.py", "MAX"): "FPL's VAR keyword for the high end of the range",
}


def _found(registry: str) -> dict[str, list[scan.Hit]]:
    out: dict[str, list[scan.Hit]] = {}
    for hit in scan.scan(registry):
        if all((hit.path, name) in OTHER_MEANING for name in hit.names):
            continue
        out.setdefault(hit.path, []).append(hit)
    return out


@pytest.mark.parametrize("registry", ["shapes", "methods", "targets", "norms"])
def test_no_kind_name_is_compared_outside_its_registry(registry: str) -> None:
    found = {
        path: [f"{h.line}: {', '.join(h.names)}" for h in hits] for path, hits in _found(registry).items()
    }
    assert not found, f"{registry}: kind names compared outside the registry (read the entry): {found}"


def test_the_other_meanings_are_still_there() -> None:
    """Each allowance names a comparison that exists (a stale one would hide a new one)."""
    hits = {(h.path, n) for r in scan.HOMES for h in scan.scan(r) for n in h.names}
    assert set(OTHER_MEANING) <= hits, sorted(set(OTHER_MEANING) - hits)


@pytest.mark.parametrize(
    ("source", "registry", "names"),
    [
        ('if t.kind == "gaussian": pass', "shapes", ("gaussian",)),
        ('ok = mf.kind in ("triangle", "trapezoid")', "shapes", ("triangle", "trapezoid")),
        ('x = "sigmoid" != term.kind', "shapes", ("sigmoid",)),
        ('match shape:\n    case "arc" | "concave":\n        pass', "shapes", ("arc", "concave")),
        ('if (d.method or "COG").upper() == "COA": pass', "methods", ("COA",)),
        ('if self.target == "st": pass', "targets", ("st",)),
        ('if dialect not in {"scl", "iec"}: pass', "targets", ("scl", "iec")),
        ('if c.op in ("MIN", "PROD"): pass', "norms", ("MIN", "PROD")),
        ('if accu.upper() == "BSUM": pass', "norms", ("BSUM",)),
    ],
)
def test_the_scan_finds_what_it_looks_for(source: str, registry: str, names: tuple[str, ...]) -> None:
    hits = scan.scan_source(source, registry)
    assert [h.names for h in hits] == [names]


@pytest.mark.parametrize(
    "source",
    [
        'if signal == "triangle": pass',  # not a kind-like name
        'if t.kind == "points": pass',  # not a registry entry (IEC points are the model's own)
        'label = "gaussian" if flag else "x"',  # no comparison
    ],
)
def test_the_scan_leaves_what_is_no_kind_comparison(source: str) -> None:
    assert not any(scan.scan_source(source, r) for r in scan.HOMES)
