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

#: Norm comparisons not moved onto the operators table yet, per file (the count only shrinks:
#: the test fails when a file compares more, or fewer without this table being lowered).
NORMS_NOT_YET: dict[str, int] = {
    "engine/explain.py": 1,
    "engine/lowering/jfl_rules.py": 1,
    "engine/reference/interp.py": 7,
    "engine/reference/pwl.py": 4,
    "engine/table_bound.py": 1,
    "ir/builders/fixed_bound.py": 7,
    "ir/builders/grid_pieces.py": 3,
    "ir/builders/quadrature.py": 4,
    "ir/builders/rules.py": 1,
    "ir/builders/terms.py": 3,
    "ir/kernels/columns.py": 11,
    "ir/kernels/scalar.py": 1,
    "ir/kernels/smooth_columns.py": 8,
    "ir/programs/evaluator.py": 6,
    "ir/programs/fixed_block.py": 6,
    "ir/programs/fixed_outputs.py": 1,
    "ir/programs/native.py": 4,
    "ir/programs/plc_block.py": 3,
    "ir/programs/rule_table.py": 7,
    "ir/programs/scalar.py": 4,
    "tune/gradient.py": 6,
    "tune/gradient_cog.py": 10,
    "tune/learning.py": 3,
}


def _found(registry: str) -> dict[str, list[scan.Hit]]:
    out: dict[str, list[scan.Hit]] = {}
    for hit in scan.scan(registry):
        if all((hit.path, name) in OTHER_MEANING for name in hit.names):
            continue
        out.setdefault(hit.path, []).append(hit)
    return out


@pytest.mark.parametrize("registry", ["shapes", "methods", "targets"])
def test_no_kind_name_is_compared_outside_its_registry(registry: str) -> None:
    found = {
        path: [f"{h.line}: {', '.join(h.names)}" for h in hits] for path, hits in _found(registry).items()
    }
    assert not found, f"{registry}: kind names compared outside the registry (read the entry): {found}"


def test_norm_names_are_compared_only_where_listed() -> None:
    found = {path: len(hits) for path, hits in _found("norms").items()}
    grown = {p: n for p, n in found.items() if n > NORMS_NOT_YET.get(p, 0)}
    assert not grown, f"norm names compared outside the operators table (read the Norm entry): {grown}"
    shrunk = {p: (n, found.get(p, 0)) for p, n in NORMS_NOT_YET.items() if found.get(p, 0) < n}
    assert not shrunk, f"fewer norm comparisons now, lower NORMS_NOT_YET: {shrunk}"


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
