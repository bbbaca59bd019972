"""Rich displays in Jupyter: a controller, a variable, an explanation or an analysis shown as HTML (tables,
the terms plotted, the explain chart) and PNG.

``import fuzzyctl`` in an IPython kernel calls :func:`register`, which teaches IPython's
display formatters these types by name (nothing is imported until an object is shown, and the
engine's classes stay free of display code).  The same HTML is available outside Jupyter:

```python
>>> import fuzzyctl
>>> ctl = fuzzyctl.compile(fuzzyctl.load("examples/tank.fcl"))
>>> html = controller_html(ctl)
>>> "<table" in html and "RULE" in html and "data:image/png;base64," in html
True

```
"""

from __future__ import annotations

import base64
import html
import io
import math
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from fuzzyctl.analysis.report import Analysis
    from fuzzyctl.engine.controller import Controller
    from fuzzyctl.engine.explain import Explanation
    from fuzzyctl.engine.variables import VariableInfo

__all__ = [
    "analysis_html",
    "controller_html",
    "explanation_html",
    "explanation_png",
    "figure_png",
    "register",
    "variable_html",
    "variable_png",
]

#: (module, class name) -> its HTML renderer.  Only HTML is registered, not PNG as well: the HTML
#: embeds the plot already, and a PNG rendering too would draw every figure twice per display
#: (variable_png and explanation_png are there for callers who want the picture alone).
_TYPES = {
    ("fuzzyctl.engine.controller", "Controller"): "controller_html",
    ("fuzzyctl.engine.variables", "VariableInfo"): "variable_html",
    ("fuzzyctl.engine.explain", "Explanation"): "explanation_html",
    ("fuzzyctl.analysis.report", "Analysis"): "analysis_html",
}


def _num(v: float | str | None) -> str:
    if v is None:
        return ""
    if isinstance(v, str):
        return html.escape(v)
    return "nan" if math.isnan(v) else f"{v:.6g}"


def figure_png(fig: Figure) -> bytes:
    """A matplotlib figure as PNG bytes (the figure is closed: a notebook shows it once).

    ```python
    >>> import fuzzyctl
    >>> ctl = fuzzyctl.compile(fuzzyctl.load("examples/tank.fcl"))
    >>> figure_png(ctl.inputs["error"].plot())[:4]
    b'\\x89PNG'

    ```
    """
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=80, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()


def _img(png: bytes, alt: str) -> str:
    return f'<img alt="{html.escape(alt)}" src="data:image/png;base64,{base64.b64encode(png).decode()}"/>'


def _table(head: list[str], rows: list[list[str]]) -> str:
    th = "".join(f"<th>{h}</th>" for h in head)
    body = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in row) + "</tr>" for row in rows)
    return f"<table><thead><tr>{th}</tr></thead><tbody>{body}</tbody></table>"


def variable_png(variable: VariableInfo) -> bytes:
    """The terms of a variable plotted, as PNG."""
    return figure_png(variable.plot())


def variable_html(variable: VariableInfo, *, plot: bool = True) -> str:
    """A variable: role, range, its terms as a table and plotted.

    ```python
    >>> import fuzzyctl
    >>> ctl = fuzzyctl.compile(fuzzyctl.load("examples/tank.fcl"))
    >>> "<td>pos_big</td>" in variable_html(ctl.inputs["error"], plot=False)
    True

    ```
    """
    rng = f"{_num(variable.low)} .. {_num(variable.high)}" if variable.range else "(from the terms)"
    extra = f", {html.escape(variable.method)}" if variable.method else ""
    rows = [
        [html.escape(t.name), html.escape(t.kind), ", ".join(_num(p) for p in t.params)]
        for t in variable.terms
    ]
    out = f"<b>{html.escape(variable.role)} {html.escape(variable.name)}</b> [{rng}]{extra}"
    out += _table(["term", "kind", "parameters"], rows)
    if plot and variable.terms:
        out += _img(variable_png(variable), f"terms of {variable.name}")
    return f"<div>{out}</div>"


def controller_html(controller: Controller, *, plot: bool = True) -> str:
    """A controller: its variables (ranges, terms, plots) and its rule table."""
    from fuzzyctl.fcl.writer import rule_text

    parts = [f"<h4>FUNCTION_BLOCK {html.escape(controller.name or '')}</h4>"]
    for var in (*controller.inputs.values(), *controller.outputs.values()):
        parts.append(variable_html(var, plot=plot))
    model = controller.model
    if model is not None:
        rows = [
            [html.escape(block.name or ""), f"<code>{html.escape(rule_text(rule))}</code>"]
            for block in model.rule_blocks
            for rule in block.rules
        ]
        parts.append("<b>rules</b>" + _table(["block", "rule"], rows))
    return "<div>" + "".join(parts) + "</div>"


def explanation_png(explanation: Explanation) -> bytes:
    """The explain chart (accumulated output sets and values) as PNG."""
    return figure_png(explanation.plot())


def explanation_html(explanation: Explanation, *, plot: bool = True) -> str:
    """One evaluation explained: inputs, term degrees, the rules that fired, the outputs and
    the explain chart.

    ```python
    >>> import fuzzyctl
    >>> ctl = fuzzyctl.compile(fuzzyctl.load("examples/tank.fcl"))
    >>> "fired" in explanation_html(ctl.explain(error=5, rate=0), plot=False)
    True

    ```
    """
    ins = [[html.escape(k), _num(v)] for k, v in explanation.inputs.items()]
    terms = [[html.escape(t.variable), html.escape(t.term), _num(t.degree)] for t in explanation.terms]
    rules = [
        [html.escape(r.block or ""), html.escape(r.label), _num(r.degree)]
        for r in explanation.rules
        if r.fired
    ]
    outs = [[html.escape(o.name), _num(o.value)] for o in explanation.outputs]
    parts = [
        "<b>inputs</b>" + _table(["input", "value"], ins),
        "<b>term degrees</b>" + _table(["variable", "term", "degree"], terms),
        f"<b>rules fired</b> ({len(rules)} of {len(explanation.rules)})"
        + _table(["block", "rule", "degree"], rules),
        "<b>outputs</b>" + _table(["output", "value"], outs),
    ]
    if plot:
        parts.append(_img(explanation_png(explanation), "explain chart"))
    return "<div>" + "".join(parts) + "</div>"


def analysis_html(analysis: Analysis) -> str:
    """The findings of :func:`fuzzyctl.analyze`: counts as a table, then each finding (rules
    at file:line) as text.

    ```python
    >>> import fuzzyctl
    >>> html = analysis_html(fuzzyctl.analyze(fuzzyctl.load("examples/tank.fcl")))
    >>> "<td>gaps</td><td>0</td>" in html and "surface dheat" in html
    True

    ```
    """
    counts = [
        ["gaps", str(len(analysis.gaps))],
        ["gap fraction", _num(analysis.gap_fraction)],
        ["coverage index", _num(analysis.coverage_index)],
        ["conflicts", str(len(analysis.conflicts))],
        ["dead rules", str(len(analysis.dead_rules))],
        ["redundant rules", str(len(analysis.redundant))],
        ["unused terms", str(len(analysis.unused_terms))],
    ]
    title = f"<b>analysis of {html.escape(analysis.block or '')}</b>"
    findings = html.escape("\n".join(analysis.lines()))
    return f"<div>{title}{_table(['finding', 'count'], counts)}<pre>{findings}</pre></div>"


def register(ip: Any = None) -> bool:
    """Teach IPython's display formatters fuzzyctl's types (by name: no import now); returns
    whether an IPython shell was there.  ``import fuzzyctl`` calls it."""
    if ip is None:
        try:
            from IPython import get_ipython
        except ImportError:
            return False
        ip = get_ipython()
    if ip is None:
        return False
    formatters = ip.display_formatter.formatters
    this = globals()
    for (module, name), html_fn in _TYPES.items():
        formatters["text/html"].for_type_by_name(module, name, this[html_fn])
    return True


def load_ipython_extension(ip: Any) -> None:
    """``%load_ext fuzzyctl.display`` (when fuzzyctl was imported before IPython started)."""
    register(ip)
