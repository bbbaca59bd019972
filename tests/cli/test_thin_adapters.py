"""The adapters stay thin (issue 27, A1 and A2): the studio's ``create_app`` only assembles
its routers (at most 50 lines), and every CLI command parses, calls one library function and
prints (at most 40 lines of body: the docstring and the signature, which declares the
options, are not counted)."""

from __future__ import annotations

import ast
from pathlib import Path

import fuzzyctl

SRC = Path(fuzzyctl.__file__).parent
MAX_CREATE_APP = 50
MAX_COMMAND_BODY = 40


def _body_lines(node: ast.FunctionDef) -> int:
    body = node.body
    if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
        body = body[1:]  # the docstring
    return 0 if not body else (node.end_lineno or node.lineno) - body[0].lineno + 1


def _commands() -> dict[str, int]:
    """Every function a typer app registers as a command (``@app.command(...)``,
    ``@blocks_app.command(...)``), with its body's length."""
    out = {}
    for path in sorted((SRC / "cli").glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.FunctionDef) and any(
                isinstance(d, ast.Call) and isinstance(d.func, ast.Attribute) and d.func.attr == "command"
                for d in node.decorator_list
            ):
                out[f"{path.name}:{node.name}"] = _body_lines(node)
    return out


def test_every_cli_command_is_short() -> None:
    commands = _commands()
    assert len(commands) >= 15  # every command found: convert, eval, explain, tune, studio, serve, ...
    assert {"run.py:eval_", "tune.py:tune", "codegen.py:codegen", "blocks.py:xfuz"} <= set(commands)
    long = {name: n for name, n in commands.items() if n > MAX_COMMAND_BODY}
    assert long == {}


def test_create_app_only_assembles() -> None:
    tree = ast.parse((SRC / "studio" / "app.py").read_text(encoding="utf-8"))
    (create_app,) = [n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == "create_app"]
    assert (create_app.end_lineno or 0) - create_app.lineno + 1 <= MAX_CREATE_APP
    # the routes live in the routers, one module per area
    assert not [n for n in ast.walk(create_app) if isinstance(n, ast.FunctionDef) and n is not create_app]
    areas = {p.stem for p in (SRC / "studio" / "routes").glob("*.py")}
    assert {"files", "editing", "analysis", "simulation", "online"} <= areas


def test_the_measure_sees_a_long_body() -> None:
    long = ast.parse("def f():\n    '''doc'''\n" + "    x = 1\n" * 41)
    assert _body_lines(long.body[0]) == 41  # type: ignore[arg-type]
