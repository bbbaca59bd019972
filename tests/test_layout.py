"""The source keeps its layout: imports point down the stack, no private name crosses a file.

The stack (docs/engine.md, "Architecture"): the model and the registries at the bottom, then
the readers and the engine's layers (the plan, semantics, lowering, the reference, the
jFuzzyLogic profile), the IR, the engine's public API, the consumers (codegen, blocks,
analysis), the tools built on them (io, sim, tune, ...) and the adapters (runtime, studio,
CLI) on top.  A module may import from its own rank or below; lazy imports count too, since
they are how upward dependencies hide.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "fuzzyctl"

#: Rank of each package or module (the longest dotted prefix wins).
RANK: dict[str, float] = {
    # the model, the registries and what everything shares
    "fuzzyctl.model": 0,
    "fuzzyctl.kinds": 0,
    "fuzzyctl.diagnostics": 0,
    "fuzzyctl.limits": 0,
    "fuzzyctl.escape": 0,
    "fuzzyctl.files": 0,
    "fuzzyctl.gcpause": 0,
    "fuzzyctl.cache": 0,
    "fuzzyctl.extras": 0,
    "fuzzyctl.webguard": 0,
    "fuzzyctl.tables": 0,
    "fuzzyctl.formatspec": 0,  # the format registry's table: names, extensions, size limits
    "fuzzyctl.jsonsafe": 0,
    "fuzzyctl.validation": 1,
    "fuzzyctl.type2": 1,  # which consumers refuse interval type-2 systems (model + kinds)
    "fuzzyctl.engine.plan": 1,  # the lowered form: plain data every layer of the engine reads
    # readers and the engine by layer
    "fuzzyctl.fcl": 2,
    "fuzzyctl.engine.semantics": 2,
    # interval type-2 sets (lower/upper degrees, breakpoints): formulas the type-2 engine and
    # the type-2 IR builder both read
    "fuzzyctl.engine.type2_sets": 2,
    "fuzzyctl.formats": 3,
    "fuzzyctl.engine.lowering": 3,
    "fuzzyctl.engine.reference": 4,
    "fuzzyctl.engine.compat": 5,
    "fuzzyctl.ir": 6,
    "fuzzyctl.engine": 7,  # compile(), Controller, the native backend, explanations
    # the facade: fuzzyctl.load / fuzzyctl.compile
    "fuzzyctl.api": 7.5,
    # consumers of compiled controllers
    "fuzzyctl.codegen": 8,
    "fuzzyctl.blocks": 8,
    "fuzzyctl.analysis": 8,
    "fuzzyctl.checking": 8,
    "fuzzyctl.io": 9,
    "fuzzyctl.sim": 9,
    "fuzzyctl.tune": 9,
    "fuzzyctl.statement": 9,
    "fuzzyctl.control": 9,
    "fuzzyctl.display": 9,
    "fuzzyctl.console": 9,
    # adapters
    "fuzzyctl.runtime": 11,
    "fuzzyctl.studio": 11,
    "fuzzyctl.cli": 11,
    # the package: its lazy attributes reach everything (``import fuzzyctl`` elsewhere only
    # binds the name: what is used through it is imported where it is used, and counted there)
    "fuzzyctl": 12,
}


def _rank(module: str) -> float | None:
    parts = module.split(".")
    for i in range(len(parts), 0, -1):
        found = RANK.get(".".join(parts[:i]))
        if found is not None:
            return found
    return None


def _modules() -> Iterator[tuple[Path, str, ast.Module]]:
    for path in sorted(SRC.rglob("*.py")):
        name = ".".join(("fuzzyctl", *path.relative_to(SRC).with_suffix("").parts)).removesuffix(".__init__")
        yield path, name, ast.parse(path.read_text(encoding="utf-8"))


def _imports(tree: ast.Module) -> Iterator[tuple[int, str, list[str]]]:
    """(line, module, names) of every absolute import of fuzzyctl, lazy ones included."""
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.ImportFrom)
            and node.level == 0
            and (node.module or "").startswith("fuzzyctl")
        ):
            assert node.module is not None
            yield node.lineno, node.module, [a.name for a in node.names]
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith("fuzzyctl"):
                    yield node.lineno, alias.name, []


def test_every_module_has_a_rank() -> None:
    unranked = [name for _p, name, _t in _modules() if _rank(name) is None]
    assert not unranked, f"add these to RANK in {__file__}: {unranked}"


def test_imports_point_down_the_stack() -> None:
    upward = []
    for path, name, tree in _modules():
        own = _rank(name)
        assert own is not None
        for line, module, names in _imports(tree):
            # `from fuzzyctl import model` imports the module fuzzyctl.model
            targets = [f"fuzzyctl.{n}" for n in names if (SRC / n).exists() or (SRC / f"{n}.py").exists()]
            if module != "fuzzyctl":
                targets = [module]
            for target in targets:
                rank = _rank(target)
                if rank is not None and rank > own:
                    upward.append(
                        f"{path.relative_to(SRC.parent)}:{line}: {name} ({own}) imports {target} ({rank})"
                    )
    assert not upward, "imports pointing up the stack:\n" + "\n".join(upward)


def test_no_private_name_is_imported_from_another_file() -> None:
    crossing = []
    for path, _name, tree in _modules():
        for line, module, names in _imports(tree):
            dotted = [*module.split("."), *names]
            private = [n for n in dotted if n.startswith("_") and not n.startswith("__")]
            if private:
                crossing.append(
                    f"{path.relative_to(SRC.parent)}:{line}: from {module} import {', '.join(private)}"
                )
    assert not crossing, "private names imported across files (make them public or move them):\n" + "\n".join(
        crossing
    )


def test_the_checks_catch_what_they_look_for(tmp_path: Path) -> None:
    """The walkers above see lazy imports and private names (a check that cannot fail proves nothing)."""
    tree = ast.parse("def f():\n    from fuzzyctl.cli.app import _hidden\n")
    ((line, module, names),) = list(_imports(tree))
    assert (line, module, names) == (2, "fuzzyctl.cli.app", ["_hidden"])
    assert _rank("fuzzyctl.engine.lowering.lower") == 3
    assert _rank("fuzzyctl.engine.controller") == 7
    assert _rank("fuzzyctl.engine.plan") == 1


#: The packages that keep every function under LONGEST lines (issue 26: the engine, the IR
#: and the code generators); data tables are assignments, not functions, and do not count.
SHORT_FUNCTIONS = ("engine", "ir", "codegen", "kinds")
LONGEST = 100


def test_no_function_is_longer_than_a_screenful() -> None:
    long = []
    for path, _name, tree in _modules():
        if path.relative_to(SRC).parts[0] not in SHORT_FUNCTIONS:
            continue
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                assert node.end_lineno is not None
                lines = node.end_lineno - node.lineno + 1
                if lines > LONGEST:
                    long.append(f"{path.relative_to(SRC.parent)}:{node.lineno}: {node.name} ({lines} lines)")
    assert not long, f"functions over {LONGEST} lines (split them):\n" + "\n".join(long)
