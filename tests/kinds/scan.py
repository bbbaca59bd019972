"""Where the source compares a value against a kind name: a shape, a defuzzification method,
a code-generation target or dialect, a norm (AND/OR/ACT/ACCU).

A *kind comparison* is ``==``, ``!=``, ``in`` / ``not in`` or a ``match`` / ``case`` whose one
side is a string literal (or a tuple, list or set of them) naming an entry of a registry and
whose other side reads a kind-like value: a name or attribute called ``kind``, ``method``,
``target``, ``dialect``, ``shape``, ``op``, ``accu``... (possibly through ``.upper()`` /
``.lower()``), or a subscript / call of one.  The registry modules (``fuzzyctl/kinds/`` and
``engine/semantics/operators.py`` for norms) are where such decisions belong; anywhere else a
comparison means a decision that should be a field of the entry.

Used by tests/kinds/test_scan.py; runnable as a script to list what it finds::

    python -m tests.kinds.scan [shapes|methods|targets|norms]
"""

from __future__ import annotations

import ast
import itertools
import re
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from fuzzyctl.engine.semantics import operators
from fuzzyctl.kinds import methods, shapes, targets

SRC = Path(__file__).resolve().parents[2] / "src" / "fuzzyctl"

#: Names that hold a kind (the last part of a dotted name, lower-cased, without leading or
#: trailing underscores): what the value on the other side of the literal must be called.
_KINDISH = re.compile(
    r"(kind|kinds|shape|shapes|mf|mf_kind|term_kind|method|methods|defuzz|defuzzifier|meth"
    r"|target|targets|lang|language|dialect|dialects|backend_target"
    r"|op|ops|operator|and|or|and_op|or_op|act|accu|activation|accumulation|norm|tnorm|snorm"
    r"|and_method|or_method|imp|agg|implication|aggregation|name|upper|word|w|n|m|k|t|d)"
)


def _registry_names() -> dict[str, frozenset[str]]:
    norms = (
        set(operators.TNORMS)
        | set(operators.SNORMS)
        | set(operators.AND_ALIASES)
        | set(operators.OR_ALIASES)
        | set(operators.ACT_ALIASES)
        | set(operators.ACCU_NAMES)
        | set(operators.ACCU_ALIASES)
    )
    method_names = set(methods.METHODS)
    for m in methods.METHODS.values():
        for spelled in m.spellings.values():
            method_names |= set(spelled)
    return {
        "shapes": frozenset(shapes.SHAPES),
        "methods": frozenset(method_names),
        "targets": frozenset(targets.TARGETS) | frozenset(targets.DIALECTS) | frozenset(targets.ALIASES),
        "norms": frozenset(n.upper() for n in norms),
    }


NAMES = _registry_names()

#: Where each registry's decisions live (paths under src/fuzzyctl).
HOMES: dict[str, tuple[str, ...]] = {
    "shapes": ("kinds/",),
    "methods": ("kinds/",),
    "targets": ("kinds/",),
    "norms": ("kinds/", "engine/semantics/operators.py"),
}


@dataclass(frozen=True)
class Hit:
    path: str  # relative to src/fuzzyctl
    line: int
    registry: str
    names: tuple[str, ...]


def _kindish(node: ast.AST) -> bool:
    """A name, attribute, subscript or method call reading a kind-like value."""
    while True:
        if isinstance(node, ast.Call):
            node = node.func
            if isinstance(node, ast.Attribute) and node.attr in (
                "upper",
                "lower",
                "strip",
                "casefold",
                "get",
            ):
                node = node.value
            continue
        if isinstance(node, ast.Subscript):
            node = node.value
            continue
        if isinstance(node, ast.BoolOp):  # (d.method or "COG")
            node = node.values[0]
            continue
        break
    if isinstance(node, ast.Name):
        word = node.id
    elif isinstance(node, ast.Attribute):
        word = node.attr
    else:
        return False
    return bool(_KINDISH.fullmatch(word.strip("_").lower()))


def _literals(node: ast.AST) -> list[str]:
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return [node.value]
    if isinstance(node, ast.Tuple | ast.List | ast.Set):
        return [e.value for e in node.elts if isinstance(e, ast.Constant) and isinstance(e.value, str)]
    return []


def _pattern_literals(p: ast.pattern) -> list[str]:
    if isinstance(p, ast.MatchValue):
        return _literals(p.value)
    if isinstance(p, ast.MatchOr):
        return [s for q in p.patterns for s in _pattern_literals(q)]
    if isinstance(p, ast.MatchAs) and p.pattern is not None:
        return _pattern_literals(p.pattern)
    return []


def _compared(tree: ast.AST) -> Iterator[tuple[int, list[str]]]:
    """(line, literals) of every kind-like comparison against string literals."""
    for node in ast.walk(tree):
        if isinstance(node, ast.Compare):
            parts = [node.left, *node.comparators]
            for (a, b), op in zip(itertools.pairwise(parts), node.ops, strict=True):
                if not isinstance(op, ast.Eq | ast.NotEq | ast.In | ast.NotIn):
                    continue
                for lit_side, other in ((a, b), (b, a)):
                    lits = _literals(lit_side)
                    if lits and _kindish(other):
                        yield node.lineno, lits
        elif isinstance(node, ast.Match) and _kindish(node.subject):
            for case in node.cases:
                lits = _pattern_literals(case.pattern)
                if lits:
                    yield case.pattern.lineno, lits


def scan_source(text: str, registry: str, rel: str = "<source>") -> list[Hit]:
    """The kind comparisons of ``registry``'s names in Python source ``text``."""
    hits = []
    for line, lits in _compared(ast.parse(text)):
        found = tuple(s for s in lits if s in NAMES[registry])
        if found:
            hits.append(Hit(rel, line, registry, found))
    return hits


def scan_file(path: Path, registry: str) -> list[Hit]:
    return scan_source(path.read_text(encoding="utf-8"), registry, path.relative_to(SRC).as_posix())


def scan(registry: str) -> list[Hit]:
    """Every kind comparison of ``registry``'s names outside its home modules."""
    hits: list[Hit] = []
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).as_posix()
        if rel.startswith(HOMES[registry]):
            continue
        hits.extend(scan_file(path, registry))
    return hits


def main(argv: list[str]) -> None:
    for registry in argv or list(HOMES):
        hits = scan(registry)
        files = sorted({h.path for h in hits})
        print(f"{registry}: {len(hits)} comparisons in {len(files)} files")
        for h in hits:
            print(f"  {h.path}:{h.line}  {', '.join(h.names)}")


if __name__ == "__main__":
    main(sys.argv[1:])
