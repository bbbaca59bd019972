"""``fuzzyctl check`` for a model in any format: what the language checks and the engine say.

An FCL file gets every check (syntax, keyword spellings, declarations, rules, reserved words,
jFuzzyLogic compatibility) and then what the engine reports.  A FIS, FLL, JSON, FPL or XFUZ
file is read by its reader (which refuses what it cannot read, with file:line) and its
model gets the checks that are about the model - declarations, terms, rules, functions -
and what the engine reports; the checks of FCL text do not apply to it and are named in
:data:`FCL_ONLY`, so a report can say what was not checked.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fuzzyctl.diagnostics import has_errors
from fuzzyctl.fcl import CheckContext, LoadResult
from fuzzyctl.fcl.checks import providers
from fuzzyctl.fcl.source import Source
from fuzzyctl.model import FunctionBlock

#: check providers about FCL text, not the model (fuzzyctl.fcl.checks)
FCL_ONLY_PROVIDERS = ("reserved", "jfuzzylogic")
#: what a report says the checks of another format leave out
FCL_ONLY = (
    "FCL syntax and keyword spellings",
    "identifiers that are FCL keywords (Table 7)",
    "what jFuzzyLogic would reject in FCL text",
)


def format_of(path: Path, format: str | None = None) -> str:
    """The format name of ``path`` (``format`` when given, else its extension)."""
    from fuzzyctl import formats

    return (formats.get(format) if format else formats.for_path(path)).name


def load_checked(
    path: Path, *, format: str | None = None, strict: bool = False, compat: str = "iec"
) -> LoadResult:
    """Read and check ``path`` in its format; when the checks pass, add what the engine
    reports (features it will not evaluate, decisions worth knowing) so that ``check`` never
    says OK to a file ``eval`` refuses (with the same ``strict`` and ``compat``).  A missing
    file, an unreadable one and a reader's refusal raise
    :class:`~fuzzyctl.diagnostics.DiagnosticError`."""
    from fuzzyctl.api import require_file
    from fuzzyctl.gcpause import gc_paused

    require_file(path)
    fmt = format_of(path, format)
    if fmt == "fcl":
        from fuzzyctl.fcl import load_file

        result = load_file(path, strict=strict, compat=compat)
    else:
        result = _load_model(path, fmt, strict, compat)
    if result.document is None or has_errors(result.diagnostics):
        return result
    with gc_paused():
        add_engine_diagnostics(result, compat, strict)
    return result


def _load_model(path: Path, fmt: str, strict: bool, compat: str) -> LoadResult:
    from fuzzyctl import formats
    from fuzzyctl.limits import read_input

    loaded = formats.read_path(path, fmt)
    try:
        text = read_input(path, fmt).decode("utf-8", "replace")
    except Exception:  # the reader read it: only the quoted lines of diagnostics are lost
        text = ""
    diagnostics = list(loaded.diagnostics)
    context = CheckContext(str(path), {"strict": strict, "compat": compat})
    for name, provider in providers().items():
        if name not in FCL_ONLY_PROVIDERS:
            diagnostics.extend(provider(loaded.document, context))
    return LoadResult(loaded.document, diagnostics, Source(text, str(path)))


def add_engine_diagnostics(result: LoadResult, compat: str, strict: bool) -> None:
    """Append what the engine says about each block (and the language checks did not)."""
    from dataclasses import replace

    from fuzzyctl.engine.support import unsupported

    # The engine validates models from every reader, so it re-finds some language errors;
    # keep only what the language checks did not already say about the same line.
    seen = {(d.code, d.span.line if d.span else None) for d in result.diagnostics}
    assert result.document is not None
    for fb in result.document.blocks:
        for d in unsupported(fb, compat=compat, strict=strict):
            if (d.code, d.span.line if d.span else None) not in seen:
                result.diagnostics.append(replace(d, file=d.file or result.source.path))


@dataclass
class CheckReport:
    """What ``fuzzyctl check`` reports about one file: the load result with every
    diagnostic, its format, the conformance features and level (when it loads) and, when
    asked, the data check list of Table 11 per function block."""

    file: Path
    format: str
    result: LoadResult
    features: list[Any] = field(default_factory=list)
    level: Any = None
    checklists: dict[str, list[Any]] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.result.ok

    @property
    def not_checked(self) -> list[str]:
        """The checks of FCL text that a model read from another format did not get."""
        return [] if self.format == "fcl" else list(FCL_ONLY)

    def to_dict(self) -> dict[str, object]:
        out: dict[str, object] = {
            "file": str(self.file),
            "ok": self.ok,
            "format": self.format,
            "diagnostics": [d.to_dict() for d in self.result.diagnostics],
            "not_checked": self.not_checked,
        }
        if self.ok:
            out["level"] = str(self.level)
            out["features"] = [f.__dict__ | {"level": str(f.level)} for f in self.features]
            if self.checklists:
                out["checklist"] = {
                    name: {row.item: row.value for row in rows} for name, rows in self.checklists.items()
                }
        return out


def check_file(
    path: Path,
    *,
    format: str | None = None,
    strict: bool = False,
    compat: str = "iec",
    checklist: bool = False,
) -> CheckReport:
    """Check ``path`` (:func:`load_checked`) and, when it loads, measure the conformance
    level its model needs as FCL and (``checklist``) Table 11's data check list."""
    from fuzzyctl.fcl import conformance
    from fuzzyctl.gcpause import gc_paused

    result = load_checked(path, format=format, strict=strict, compat=compat)
    report = CheckReport(path, format_of(path, format), result)
    doc = result.document
    if not result.ok or doc is None:
        return report
    with gc_paused():
        report.features = conformance.features(doc, result.spellings)
    report.level = conformance.level(report.features)
    if checklist:
        report.checklists = {
            fb.name or "": conformance.checklist(fb, bool(doc.comments) or has_comments(fb))
            for fb in doc.blocks
        }
    return report


def has_comments(fb: FunctionBlock) -> bool:
    """Whether any element of ``fb`` carries a comment (an item of Table 11)."""
    from fuzzyctl.fcl.checks import term_blocks

    items: list[object] = [fb, *fb.variables, *fb.fuzzify, *fb.defuzzify, *fb.rule_blocks]
    for block in term_blocks(fb):
        items.extend(block.terms)
    for rb in fb.rule_blocks:
        items.extend(rb.rules)
    return any(getattr(i, "comments", ()) or getattr(i, "placed_comments", ()) for i in items)
