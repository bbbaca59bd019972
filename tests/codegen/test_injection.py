"""No code injection through a model file (issue 14, point 1).

Every reader (FCL, FIS, FLL, JSON, FPL, XFUZ) is given a small system with a hostile string
(comment terminators of C and ST, newlines, line splices, trigraphs, quotes, NUL, ``]]>``,
``${``, Unicode line separators and bidirectional controls, 20,000 characters) in each of
its text fields in turn.  The reader may refuse it (a :class:`DiagnosticError`) or accept it;
when it accepts, the generated C, Structured Text and the evaluators of ``compile()``
(Python, numpy, the native backend's C) must be the benign system's code token for token -
whatever the hostile text did, it stayed inside a comment or was refused as a name
(:class:`CodegenError`).  Then the issue's reproducer and every hostile label are built by
the native backend and run."""

from __future__ import annotations

import json
import os
import warnings
from collections.abc import Iterator
from functools import cache
from pathlib import Path
from typing import Any

import pytest

import fuzzyctl
import fuzzyctl.formats.json.writer  # used as fuzzyctl.formats.json.writer (the registry imports it lazily)
from fuzzyctl.cli.app import main
from fuzzyctl.codegen import CodegenError, generate_c, generate_st, lower_block
from fuzzyctl.diagnostics import DiagnosticError
from fuzzyctl.engine.native import NativeController
from fuzzyctl.ir.programs.evaluator import build_fast
from fuzzyctl.ir.programs.native import build_native
from fuzzyctl.ir.programs.plc_block import build_program
from fuzzyctl.ir.render.c import render_c, render_native
from fuzzyctl.ir.render.npsrc import render_np
from fuzzyctl.ir.render.pysrc import render_py
from fuzzyctl.ir.render.st import render_st
from fuzzyctl.model import Document
from tests.codegen import hostile as H

FIELDS = {
    "fcl": [p for p in H.PLACEHOLDERS],
    "fis": ["QQfbQQ", "QQinQQ", "QQoutQQ", "QQtermQQ", "QQotermQQ", "QQhiQQ"],
    "fll": [
        "QQfbQQ",
        "QQinQQ",
        "QQoutQQ",
        "QQtermQQ",
        "QQotermQQ",
        "QQblockQQ",
        "QQcmtQQ",
        "QQvcmtQQ",
        "QQdefQQ",
        "QQhiQQ",
    ],
    "fpl": [
        "QQfbQQ",
        "QQinQQ",
        "QQoutQQ",
        "QQtermQQ",
        "QQotermQQ",
        "QQlabelQQ",
        "QQblockQQ",
        "QQcmtQQ",
        "QQhiQQ",
    ],
    "json": ["QQfbQQ", "QQinQQ", "QQoutQQ", "QQtermQQ", "QQotermQQ", "QQlabelQQ", "QQblockQQ", "QQcmtQQ"],
    "xfuz": ["term", "comment"],
}


@cache
def _benign_fcl() -> Document:
    return fuzzyctl.load(H.fill(H.FCL, None, ""), format="fcl")


def _source(fmt: str, field: str | None, text: str) -> str:
    if fmt == "json":
        return H.json_model(_benign_fcl(), field, text)
    if fmt == "xfuz":
        return _xfuz(field, text)
    return H.fill(H.TEMPLATES[fmt], field, text)


@cache
def _xfuz_base() -> dict[str, Any]:
    text, _ = fuzzyctl.formats.convert(_benign_fcl(), "xfuz", lossy=True)
    data = json.loads(text)
    assert isinstance(data, dict)
    return data


def _xfuz(field: str | None, text: str) -> str:
    data = json.loads(json.dumps(_xfuz_base()))
    if field == "term":
        data["FA"][0:4] = H.xfuz_words(text)
    elif field == "comment":
        data["comment"] = text
    return json.dumps(data)


def _load(fmt: str, source: str) -> Document | None:
    """The document, or None when the reader refused the file (with a diagnostic)."""
    try:
        return fuzzyctl.load(source, format=fmt)
    except DiagnosticError as exc:
        assert exc.diagnostics, "a refusal names what is wrong"
        return None


def _code(doc: Document) -> dict[str, list[str] | None]:
    """The code tokens of everything generated from ``doc`` (None: refused as a name).  The
    plan is lowered once and given to each generator (generate_c / generate_st do the same
    per call; the CLI test below goes through them)."""
    plan = lower_block(doc)
    out: dict[str, list[str] | None] = {}
    try:
        header, source = render_c(build_program(plan, "c"))
        out["c"] = [*H.c_tokens(header), "FILE", *H.c_tokens(source)]
    except CodegenError:
        out["c"] = None
    try:
        out["st"] = list(H.st_tokens(render_st(build_program(plan, "st"))))
    except CodegenError:
        out["st"] = None
    # the evaluators of compile(): Python (single), numpy (batch), C (native backend)
    out["python"] = render_py(build_fast(plan, "py"))[0].split()
    out["numpy"] = render_np(build_fast(plan, "np"))[0].split()
    out["native"] = list(H.c_tokens(render_native(build_native(plan))))
    return out


@cache
def _benign_code(fmt: str) -> dict[str, list[str] | None]:
    doc = _load(fmt, _source(fmt, None, ""))
    assert doc is not None, f"the benign {fmt} template must load"
    code = _code(doc)
    assert all(v is not None for v in code.values()), f"the benign {fmt} system must generate"
    return code


def _cases() -> Iterator[Any]:
    for fmt, fields in FIELDS.items():
        for field in fields:
            yield pytest.param(fmt, field, id=f"{fmt}-{field.strip('Q')}")


@pytest.mark.parametrize(("fmt", "field"), list(_cases()))
def test_hostile_text_is_refused_or_inert(fmt: str, field: str) -> None:
    benign = _benign_code(fmt)
    accepted = 0
    for key, text in H.HOSTILE.items():
        doc = _load(fmt, _source(fmt, field, text))
        if doc is None:
            continue
        accepted += 1
        code = _code(doc)
        for target, tokens in code.items():
            if tokens is None:
                continue  # refused by the generator: a name it cannot write
            assert tokens == benign[target], f"{fmt} {field} {key}: the {target} code changed"
    # the fields that are free text in the format must have been accepted (and so tested)
    free = {"QQlabelQQ", "QQblockQQ", "QQcmtQQ", "QQvcmtQQ", "comment", "term"}
    if fmt in ("json", "xfuz") and field in free:
        assert accepted == len(H.HOSTILE)


def test_free_text_reaches_the_generated_comments() -> None:
    """The JSON label arrives in the C and ST comments, made inert (so the test above did test
    what it claims, and the text is still there for a reader)."""
    doc = fuzzyctl.load(H.json_model(_benign_fcl(), "QQlabelQQ", H.HOSTILE["issue-14"]), format="json")
    source = generate_c(doc)["QQfbQQ.c"]
    assert (
        '/* RULE 1 * / { extern int system(const char * ); system("touch pwned"); } / * (block QQblockQQ) */'
        in source
    )
    st = generate_st(doc)
    assert (
        '(* RULE 1 * / { extern int system(const char * ); system("touch pwned"); } / * (block QQblockQQ) *)'
        in st
    )


@pytest.fixture
def private_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("FUZZYCTL_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.mark.parametrize("target", ["py", "np", "c"])
def test_evaluator_renderers_refuse_a_name_that_is_not_an_identifier(target: str) -> None:
    """The evaluators of compile() print only the program's own names, each through the
    target's identifier check: a name that got into the program some other way is refused."""
    plan = lower_block(_benign_fcl())
    fp = build_native(plan) if target == "c" else build_fast(plan, target)  # type: ignore[arg-type]
    fp.inputs[0] = H.HOSTILE["c-close"]
    render = {"py": render_py, "np": render_np, "c": render_native}[target]
    with pytest.raises(CodegenError, match="generated name"):
        render(fp)  # type: ignore[operator]


def _labelled(labels: list[str]) -> Document:
    """The tank example with hostile rule labels, rule-block and term names (JSON: free text)."""
    tank = fuzzyctl.load(Path(__file__).parents[2] / "examples" / "tank.fcl")
    data = fuzzyctl.formats.json.writer.to_dict(tank)
    block = data["blocks"][0]
    rules = block["rule_blocks"][0]["rules"]
    for k, label in enumerate(labels):
        rules[k]["label"] = label
    block["rule_blocks"][0]["name"] = H.HOSTILE["c-close"]
    text = json.dumps(data)
    return fuzzyctl.load(text, format="json")


def test_native_backend_on_the_issue_reproducer(private_cache: Path) -> None:
    doc = _labelled([H.HOSTILE["issue-14"]])
    reference = fuzzyctl.compile(doc, backend="python")  # the default may be native itself
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a fallback to Python would hide a refused build
        native = fuzzyctl.compile(doc, backend="native")
    assert isinstance(native, NativeController)
    for error, rate in ((-3.0, -0.7), (0.3, 0.1), (3.5, 0.9), (1.0, 0.2)):
        got = native.evaluate({"error": error, "rate": rate})["dheat"]
        assert got == pytest.approx(reference.evaluate({"error": error, "rate": rate})["dheat"], abs=1e-12)
    assert not list(private_cache.rglob("pwned")) and not Path("pwned").exists()


def test_native_backend_on_every_hostile_label(private_cache: Path) -> None:
    doc = _labelled(list(H.HOSTILE.values()))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        native = fuzzyctl.compile(doc, backend="native")
    assert isinstance(native, NativeController)
    reference = fuzzyctl.compile(doc)
    assert native.evaluate({"error": 2.5, "rate": -0.2}) == pytest.approx(
        reference.evaluate({"error": 2.5, "rate": -0.2}), abs=1e-12
    )
    assert not list(private_cache.rglob("pwned"))


def test_cli_codegen_on_a_hostile_model(private_cache: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = private_cache / "evil.json"
    src.write_text(json.dumps(fuzzyctl.formats.json.writer.to_dict(_labelled([H.HOSTILE["issue-14"]]))))
    assert main(["codegen", str(src), "--lang", "c", "-o", str(private_cache / "gen")]) == 0
    c_file = (private_cache / "gen" / "tank.c").read_text()
    assert list(H.c_tokens(c_file)) == list(
        H.c_tokens(
            generate_c(fuzzyctl.load(os.fspath(Path(__file__).parents[2] / "examples" / "tank.fcl")))[
                "tank.c"
            ]
        )
    )
    assert main(["codegen", str(src), "--lang", "st", "--dialect", "scl"]) == 0
    st = capsys.readouterr().out
    assert "touch pwned" in st and list(H.st_tokens(st))  # the text is there, in a comment
    # a hostile name is renamed to an identifier (files named by it), the original text only
    # in the rename table of the header comment, made inert there
    bad = json.loads(src.read_text())
    bad["blocks"][0]["name"] = H.HOSTILE["c-close"]
    src.write_text(json.dumps(bad))
    assert main(["codegen", str(src), "--lang", "c", "-o", str(private_cache / "gen2")]) == 0
    assert sorted(p.name for p in (private_cache / "gen2").iterdir()) == ["PWNED.c", "PWNED.h"]
    renamed = (private_cache / "gen2" / "PWNED.c").read_text()
    assert "renamed for the target" in (private_cache / "gen2" / "PWNED.h").read_text()
    assert list(H.c_tokens(renamed)) == list(H.c_tokens(c_file))
