"""The public facade: ``load()`` a fuzzy system from any supported format and
``compile()`` it into something that evaluates."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from fuzzyctl.model import Document, FunctionBlock

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from fuzzyctl.engine.controller import Controller
    from fuzzyctl.engine.variables import VariableInfo


def load(path_or_text: str | Path, *, format: str | None = None, strict: bool = False) -> Document:
    """Read a fuzzy system from a file path or from source text.

    ``format`` (``"fcl"``, ...) overrides detection by file extension; text that is not an
    existing path is parsed as FCL unless ``format`` says otherwise.  ``strict``: refuse, as
    a strict IEC 61131-7 tool would, FCL whose identifiers are reserved keywords (Table 7).
    Raises :class:`fuzzyctl.diagnostics.DiagnosticError` with file:line:column diagnostics
    when the input is not valid."""
    from fuzzyctl import formats
    from fuzzyctl.diagnostics import DiagnosticError, error
    from fuzzyctl.fcl import load_file, load_text

    fmt = (format or "").lower() or None
    if isinstance(path_or_text, Path) or _looks_like_path(path_or_text):
        path = Path(path_or_text)
        fmt = fmt or (path.suffix.lower().lstrip(".") or "fcl")
        if fmt == "fcl":
            return load_file(path, strict=strict).raise_for_errors()
        return formats.read_path(path, fmt).document
    if fmt not in (None, "fcl"):
        return formats.read_text(str(path_or_text), fmt).document
    text = str(path_or_text)
    if not text.strip():
        raise DiagnosticError([error("empty input: no FUNCTION_BLOCK", code="empty")])
    return load_text(text, strict=strict).raise_for_errors()


def _looks_like_path(value: str) -> bool:
    """Text holding a newline, ';' or ':=', starting with '{' or '[', or longer than any path
    is source; anything else is taken as a path (a missing file is then reported as such,
    not parsed as FCL)."""
    if "\n" in value or ";" in value or ":=" in value or len(value) > 4096:
        return False
    if value.lstrip()[:1] in ("{", "["):  # JSON, a FIS section
        return False
    return "FUNCTION_BLOCK" not in value.upper() or Path(value).exists()


def compile(
    model: Document | FunctionBlock, *, block: str | None = None, backend: str = "python", **options: Any
) -> Controller:
    """Turn a model into a :class:`~fuzzyctl.engine.Controller` (see ``fuzzyctl.engine``).

    ``block`` names the function block of a document (default: the first); ``backend`` is
    ``"python"``, ``"interpreted"`` or ``"native"`` (generated C compiled into a cached
    shared library, see docs/codegen.md; without a C compiler it warns and uses the Python
    path); ``compat="fuzzylite"`` etc. reproduces other tools' semantics (default
    IEC 61131-7).  ``strict=True`` refuses what a strict IEC 61131-7 reading refuses and the
    engine otherwise settles with a warning: an output without RANGE whose terms do not fall
    to 0, identifiers that are Table 7 keywords.  Raises
    :class:`~fuzzyctl.diagnostics.DiagnosticError` for what the engine cannot evaluate."""
    from fuzzyctl.engine.compile import compile_block

    if options.get("strict"):
        _refuse_reserved(model)

    if backend == "native":
        from fuzzyctl.codegen.native import compile_native

        reference = compile_block(model, block=block, backend="interpreted", **options)
        return compile_native(reference.plan, reference.model)
    return compile_block(model, block=block, backend=backend, **options)


def _refuse_reserved(model: Document | FunctionBlock) -> None:
    from fuzzyctl.diagnostics import DiagnosticError, has_errors
    from fuzzyctl.fcl.reserved import check_reserved_words

    doc = model if isinstance(model, Document) else Document((model,))
    found = check_reserved_words(doc, doc.path, strict=True)
    if has_errors(found):
        raise DiagnosticError(found)


def plot_terms(variable: VariableInfo, *, points: int = 1001, ax: Axes | None = None) -> Figure:
    """The membership functions of a variable as a labelled matplotlib Figure:
    ``fuzzyctl.plot_terms(ctl.inputs["temp"]).savefig("temp.png")`` (as scikit-fuzzy's
    ``view()`` or simpful's ``plot_variable``)."""
    from fuzzyctl.engine.plot import plot_terms as draw

    return draw(variable, points=points, ax=ax)
