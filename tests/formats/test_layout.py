"""The shape of the formats (issue 27, A3): every format is a subpackage with a reader, a
writer and the names both use, the reader and the writer never import each other, and the
registry (:mod:`fuzzyctl.formats` and its table :mod:`fuzzyctl.formatspec`) is the one list of
formats - no other module of fuzzyctl spells one out."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from fuzzyctl import formats

FORMATS = Path(formats.__file__).parent
SRC = FORMATS.parent
KINDS = SRC / "kinds"
PACKAGES = sorted(p.name for p in FORMATS.iterdir() if (p / "__init__.py").is_file() and p.name != "common")


def _module_name(path: Path) -> str:
    parts = path.relative_to(SRC.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imported(path: Path) -> set[str]:
    """Every module ``path`` imports, at module level or inside a function (``from A import b``
    counts A and, when it is a module, A.b; relative imports resolved)."""
    package = _module_name(path).rsplit(".", 1)[0] if path.name != "__init__.py" else _module_name(path)
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*anchor, *([base] if base else [])])
            out.add(base)
            out.update(f"{base}.{alias.name}" for alias in node.names)
    return out


def _file(module: str) -> Path | None:
    base = SRC.parent.joinpath(*module.split("."))
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def _reach(module: str, package: str) -> set[str]:
    """The modules of ``package`` that ``module`` imports, directly or through others of the
    package; the package's ``__init__`` (the registry entry, which loads both sides on first
    use) is not followed."""
    seen: set[str] = set()
    todo = [module]
    while todo:
        path = _file(todo.pop())
        if path is None:
            continue
        for name in _imported(path):
            if name.startswith(package + ".") and name not in seen and _file(name) is not None:
                seen.add(name)
                todo.append(name)
    return seen


def test_the_registry_names_one_subpackage_per_format() -> None:
    assert sorted(formats.KNOWN_NAMES) == PACKAGES
    assert [f.name for f in formats.available()] == list(formats.KNOWN_NAMES)


@pytest.mark.parametrize("name", PACKAGES)
def test_every_format_has_the_same_shape(name: str) -> None:
    for module in ("__init__", "reader", "writer", "names"):
        assert (FORMATS / name / f"{module}.py").is_file(), f"formats/{name}/{module}.py"
    fmt = formats.get(name)
    assert fmt.extensions and all(e.startswith(".") for e in fmt.extensions)
    assert 0 < fmt.max_bytes <= 128 * 2**20


@pytest.mark.parametrize("name", PACKAGES)
def test_reader_and_writer_never_import_each_other(name: str) -> None:
    package = f"fuzzyctl.formats.{name}"
    reader, writer = f"{package}.reader", f"{package}.writer"
    assert writer not in _reach(reader, package)
    assert reader not in _reach(writer, package)
    assert not {reader, writer} & _reach(f"{package}.names", package)


def test_the_shared_modules_import_no_format() -> None:
    for path in (FORMATS / "common").glob("*.py"):
        own = {n for n in _imported(path) if n.startswith("fuzzyctl.formats.")}
        assert not {n for n in own if n.split(".")[2] in PACKAGES}, path.name


def test_the_import_check_sees_an_import() -> None:
    # the check above must be able to fail: the FIS reader reaches its names and rules
    package = "fuzzyctl.formats.fis"
    assert {f"{package}.names", f"{package}.rules"} <= _reach(f"{package}.reader", package)
    assert f"{package}.names" in _reach(f"{package}.writer", package)


# ---------------------------------------------------------------------------- one list

_NAME = r"\.?(?:fcl|fis|fll|fpl|xfuz|json)\b"
#: three format names in a row ("FCL, FIS, FLL", "fcl, fis or json", ".fcl/.fis/.fll")
LISTED = re.compile(rf"(?<![\w/.]){_NAME}(?:(?:\s*,\s*|\s*/\s*|\s+or\s+|,\s+or\s+){_NAME}){{2,}}", re.I)
NAMES = {"fcl", "fis", "fll", "fpl", "xfuz", "json"}


def _format_lists(path: Path) -> list[str]:
    """Where ``path`` spells out a list of formats: a literal sequence or mapping with two or
    more format names or extensions, or a string (not a docstring) listing three."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docstrings = {
        id(node.value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant)
    }
    found = []
    for node in ast.walk(tree):
        items: list[ast.expr | None] = []
        if isinstance(node, ast.List | ast.Tuple | ast.Set):
            items = list(node.elts)
        elif isinstance(node, ast.Dict):
            items = list(node.keys)
        words = [
            i.value.lower().lstrip(".")
            for i in items
            if isinstance(i, ast.Constant) and isinstance(i.value, str)
        ]
        if sum(w in NAMES for w in words) >= 2:
            found.append(f"{path.name}:{node.lineno}: {words}")
        text = node.value if isinstance(node, ast.Constant) and id(node) not in docstrings else None
        if isinstance(text, str) and LISTED.search(text):
            found.append(f"{path.name}:{node.lineno}: {node.value[:60]!r}")
    return found


def test_no_list_of_formats_outside_the_registry() -> None:
    found = [
        hit
        for path in sorted(SRC.rglob("*.py"))
        # kinds/: each entry's spellings are keyed by format name (tests/kinds checks the keys)
        if FORMATS not in path.parents and KINDS not in path.parents and path.name != "formatspec.py"
        for hit in _format_lists(path)
    ]
    for path in sorted((SRC / "studio" / "static").rglob("*")):
        if path.suffix in (".js", ".html"):
            text = path.read_text(encoding="utf-8")
            found += [f"{path.name}: {m.group(0)!r}" for m in LISTED.finditer(text)]
    assert found == []


def test_the_list_check_sees_a_list(tmp_path: Path) -> None:
    planted = tmp_path / "planted.py"
    planted.write_text('EXT = (".fcl", ".fis")\nHELP = "a model: FCL, FIS or FLL"\n', encoding="utf-8")
    assert len(_format_lists(planted)) == 2
