"""The analysis' findings as diagnostics at file:line, for ``fuzzyctl check --analyze``
(docs/analyze.md, "In check"): gaps at the output's declaration, rules at their RULE line.
Gaps and dead rules are errors under ``strict``; everything else is a warning."""

from __future__ import annotations

from typing import TYPE_CHECKING

from fuzzyctl.diagnostics import Diagnostic, Severity

if TYPE_CHECKING:
    from fuzzyctl.analysis.report import Analysis
    from fuzzyctl.model import Document, FunctionBlock, Span


def _rule_spans(fb: FunctionBlock) -> dict[str, Span | None]:
    spans: dict[str, Span | None] = {}
    for rb, rule in fb.rules():
        spans.setdefault(rule.label, rule.span)
        spans.setdefault(f"{rb.name}.{rule.label}", rule.span)
    return spans


def _var_span(fb: FunctionBlock, name: str) -> Span | None:
    v = fb.variable(name)
    return v.span if v is not None else fb.span


def diagnostics(
    doc: Document, *, strict: bool = False, epsilon: float = 0.0, delta: float | None = None
) -> list[Diagnostic]:
    """Analyse every block of ``doc`` (no surface sampling: only table findings)."""
    from fuzzyctl.analysis import analyze

    file = doc.path
    out: list[Diagnostic] = []
    for fb in doc.blocks:
        res = analyze(fb, epsilon=epsilon, delta=delta, surface=False)
        where = f" in block {fb.name}" if len(doc.blocks) > 1 and fb.name else ""
        out += block_diagnostics(fb, res, file, strict=strict, where=where)
    return out


def block_diagnostics(
    fb: FunctionBlock, res: Analysis, file: str | None, *, strict: bool = False, where: str = ""
) -> list[Diagnostic]:
    """The findings of ``res`` (the analysis of ``fb``) at the places in ``fb`` they concern;
    ``where`` is added after each finding's kind (" in block B")."""
    hard = Severity.ERROR if strict else Severity.WARNING
    out: list[Diagnostic] = []
    rules = _rule_spans(fb)
    by_output: dict[str, int] = {}
    for g in res.gaps:
        by_output[g.output] = by_output.get(g.output, 0) + 1
    for output, n in by_output.items():
        first = next(g for g in res.gaps if g.output == output)
        box = ", ".join(f"{k} in [{lo:.6g}, {hi:.6g}]" for k, (lo, hi) in first.box.items())
        out.append(
            Diagnostic(
                hard,
                f"gap{where}: no rule concluding {output} fires in {n} box(es) of the input space, "
                f"e.g. {box} (the output falls to DEFAULT there)",
                _var_span(fb, output),
                file,
                "analyze-gap",
            )
        )
    for r in res.dead_rules:
        out.append(
            Diagnostic(hard, f"dead rule{where}: rule {r} can never fire", rules.get(r), file, "analyze-dead")
        )
    for c in res.conflicts:
        out.append(
            Diagnostic(
                Severity.WARNING,
                f"conflict{where}: rules {c.rules[0]} and {c.rules[1]} conclude {c.output} IS "
                f"{c.terms[0]} / {c.terms[1]} together (joint degree {c.joint_degree:.3g})",
                rules.get(c.rules[1]),
                file,
                "analyze-conflict",
            )
        )
    for red in res.redundant:
        out.append(
            Diagnostic(
                Severity.WARNING,
                f"{red.kind} rule{where}: rule {red.rule} is covered by rule {red.covered_by}",
                rules.get(red.rule),
                file,
                "analyze-redundant",
            )
        )
    for u in res.unused_terms:
        out.append(
            Diagnostic(
                Severity.WARNING,
                f"unused term{where}: {u.variable}.{u.term} ({u.reason})",
                _var_span(fb, u.variable),
                file,
                "analyze-unused",
            )
        )
    for m in res.monotonicity:
        for lower, higher in m.offending:
            out.append(
                Diagnostic(
                    Severity.WARNING,
                    f"monotonicity{where}: rules {lower} < {higher} conclude {m.output} against the "
                    f"declared {m.declared}{m.input}",
                    rules.get(higher),
                    file,
                    "analyze-monotone",
                )
            )
    return out
