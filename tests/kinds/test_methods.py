"""The methods registry (fuzzyctl/kinds/methods.py): every entry complete, every named
implementation resolving to a callable, the format tables derived from it, and no method
name compared outside the registry in the engine and the code generators."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from fuzzyctl import model
from fuzzyctl.fcl import keywords
from fuzzyctl.formats.fis import names as fis
from fuzzyctl.formats.fll import names as fll
from fuzzyctl.kinds import methods as M

SRC = Path(__file__).resolve().parents[2] / "src" / "fuzzyctl"


@pytest.mark.parametrize("code", sorted(M.METHODS))
def test_every_entry_is_complete(code: str) -> None:
    m = M.METHODS[code]
    assert m.code == code and m.title
    assert set(m.spellings) == set(M.FORMATS), "a spelling tuple per format (empty: not expressible)"
    assert m.spellings["fcl"] and m.spellings["json"] == (code,)
    assert set(m.notes) == set(m.spellings["fcl"]), "a note per FCL spelling"
    kinds = [m.integrating, m.maximum is not None, m.weighted is not None]
    assert sum(kinds) == 1 or m.on_pieces, "integrating, a maximum or weighted: at most one"
    assert not m.bisects or m.integrating
    assert not m.takagi_sugeno or m.weighted is not None
    for what in ("reference", "ir", "numpy"):
        path = getattr(m, what)
        if what == "numpy" and not path:
            continue  # no hand-written kernel: a batch renders the IR
        assert re.fullmatch(r"fuzzyctl(\.\w+)+:\w+(\.\w+)*", path), (what, path)
        assert callable(M.implementation(path)), (what, path)
    if m.lowers_to is not None:
        assert m.lowers_to in M.METHODS and M.METHODS[m.lowers_to].lowers_to is None


def test_spellings_are_unambiguous_per_format() -> None:
    for fmt in M.FORMATS:
        names = [s.upper() for m in M.METHODS.values() for s in m.spellings[fmt]]
        assert len(names) == len(set(names)), fmt


def test_the_format_tables_are_the_registry() -> None:
    assert frozenset(M.METHODS) == model.DEFUZZ_METHODS
    assert {k: v[0] for k, v in keywords.METHOD_SYNONYMS.items()} == M.spelled("fcl")
    assert M.spelled("fis") == fis.DEFUZZ_METHODS and M.spelled("fll") == fll.DEFUZZIFIERS
    # what the readers accept maps onto codes; every written spelling reads back
    for fmt in ("fis", "fll"):
        for code, word in M.written(fmt).items():
            assert M.spelled(fmt)[word] == code


def test_lowering_evaluates_every_name_as_a_method_without_aliases() -> None:
    for name, code in M.lowering_aliases().items():
        assert code in M.METHODS and M.METHODS[code].lowers_to is None, name


#: Files that still compare method names, and why (the list only shrinks: the test fails
#: when a listed file is clean).  Everything else reads the registry.
NOT_YET: dict[str, str] = {}


def _comparisons(path: Path) -> list[int]:
    """Lines comparing with a method name (a string constant next to ==, != or in)."""
    found = []
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.Compare):
            for part in [node.left, *node.comparators]:
                consts = [part] if isinstance(part, ast.Constant) else getattr(part, "elts", [])
                if any(isinstance(c, ast.Constant) and c.value in M.METHODS for c in consts):
                    found.append(node.lineno)
    return found


def test_no_method_name_is_compared_outside_the_registry() -> None:
    found = {}
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).as_posix()
        if rel.startswith("kinds/"):
            continue
        lines = _comparisons(path)
        if lines:
            found[rel] = lines
    new = {f: lines for f, lines in found.items() if f not in NOT_YET}
    assert not new, f"method names compared outside fuzzyctl/kinds (read the entry): {new}"
    cleaned = sorted(set(NOT_YET) - set(found))
    assert not cleaned, f"clean now, drop from NOT_YET: {cleaned}"
