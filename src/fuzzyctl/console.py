"""Console views of what the engine computes, for a terminal (``rich``): an explanation as
tables and text plots.  ``fuzzyctl explain`` prints them; a script prints them the same way:

```python
>>> import fuzzyctl
>>> ctl = fuzzyctl.compile(fuzzyctl.load("examples/tank.fcl"))
>>> views = explanation_views(ctl.explain({"error": 0.0, "rate": 0.0}))
>>> [view.title for view in views[:4]]  # then each output's accumulated set
['inputs', 'fuzzification (degree of each term)', 'rules (condition degree, then each conclusion)', 'outputs']
>>> from rich.console import Console
>>> Console(width=100).print(*views)  # doctest: +SKIP

```

(:mod:`fuzzyctl.display` has the HTML views for Jupyter.)
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from fuzzyctl.engine.explain import Explanation


def explanation_views(e: Explanation, *, width: int = 64) -> list[Any]:
    """The inputs, the term degrees, the rules, the outputs, then per output its Takagi-Sugeno
    terms or its accumulated set drawn ``width`` characters wide: rich renderables in the
    order ``fuzzyctl explain`` prints them."""
    from rich.table import Table
    from rich.text import Text

    from fuzzyctl.engine.plot import ascii_plot

    inputs = Table(title="inputs")
    inputs.add_column("input", overflow="fold")
    inputs.add_column("value", justify="right", overflow="fold")
    for k, v in e.inputs.items():
        inputs.add_row(k, f"{v:.10g}")
    terms = Table(title="fuzzification (degree of each term)")
    for col in ("variable", "term", "degree"):
        terms.add_column(col, justify="right" if col == "degree" else "left", overflow="fold")
    for t in (*e.terms, *e.chained):
        terms.add_row(t.variable, t.term, f"{t.degree:.6g}")
    views: list[Any] = [inputs, terms, _rules(e), _outputs(e)]
    for o in e.outputs:
        if o.kind == "ts" and o.weights:
            ts = Table(title=f"{o.name}: Takagi-Sugeno terms")
            for col in ("term", "weight", "z"):
                ts.add_column(col, justify="left" if col == "term" else "right", overflow="fold")
            for name, w, z in o.weights:
                ts.add_row(name, f"{w:.6g}", f"{z:.6g}")
            views.append(ts)
        elif o.kind in ("mamdani", "singleton"):
            views.append(Text.assemble((o.name, "bold"), ": accumulated set"))
            views.append(Text(ascii_plot(o, width=width)))
    return views


def _rules(e: Explanation) -> Any:
    from rich.table import Table

    rules = Table(title="rules (condition degree, then each conclusion)")
    for col in ("block", "rule", "degree", "conclusion", "weight"):
        rules.add_column(col, justify="right" if col in ("degree", "weight") else "left", overflow="fold")
    for r in e.rules:
        concl = ", ".join(f"{c.variable} IS {c.term}" if c.term else c.variable for c in r.conclusions)
        weights = ", ".join(f"{c.weight:g}" for c in r.conclusions)
        style = "" if r.fired else "dim"
        rules.add_row(r.block or "", r.label, f"{r.degree:.6g}", concl, weights, style=style)
    return rules


def _outputs(e: Explanation) -> Any:
    from rich.table import Table

    outs = Table(title="outputs")
    for col in ("output", "value", "method", "accumulation", "fired"):
        outs.add_column(col, justify="right" if col == "value" else "left", overflow="fold")
    for o in e.outputs:
        outs.add_row(
            o.name,
            f"{o.value:.10g}",
            o.method,
            o.accumulation or "per rule",
            ("yes" if math.isfinite(o.value) else "yes (undefined: NaN)") if o.fired else "no (default)",
        )
    return outs
