"""What a compiled controller's inputs and outputs are, for inspection: ``ctl.inputs["temp"]``
gives the range and the terms (name, kind, parameters, breakpoints) and evaluates or plots
the membership functions.  ``ctl.inputs`` is a read-only mapping from names to
:class:`VariableInfo`, in declaration order, so ``"temp" in ctl.inputs`` and
``list(ctl.inputs)`` work on names as before."""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from fuzzyctl.engine.plan import OutputPlan, Plan, Slot, TermPlan

if TYPE_CHECKING:  # numpy is imported when a membership function is evaluated (cold start)
    import numpy as np
    import numpy.typing as npt
    from matplotlib.figure import Figure

    from fuzzyctl.model import FunctionBlock


@dataclass(frozen=True)
class TermInfo:
    """A term: ``kind`` is a shape kind (``"triangle"``, ``"gaussian"``, ...), ``"points"``,
    ``"singleton"``, ``"constant"``/``"linear"`` (Takagi-Sugeno) or ``"function"``.
    ``params`` are the shape's parameters (a parameter given by another variable appears as
    its name); ``points`` the breakpoints ``((x, y), ...)`` when the term is piecewise linear
    with constant parameters, else None."""

    name: str
    kind: str
    params: tuple[float | str, ...]
    points: tuple[tuple[float, float], ...] | None
    height: float | str = 1.0
    _plan: TermPlan | None = None

    def membership(self, x: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """The degree of membership at ``x`` (an array or a number)."""
        import numpy as np

        from fuzzyctl.engine.semantics import shapes

        xs = np.asarray(x, dtype=np.float64)
        if self.points is not None:
            return shapes.pwl_value_np(self.points, xs.reshape(-1)).reshape(xs.shape)
        if self.kind in shapes.TS_KINDS or any(isinstance(p, str) for p in self.params):
            raise ValueError(f"term {self.name!r} ({self.kind}) has no membership function of x alone")
        if isinstance(self.height, str):
            raise ValueError(f"term {self.name!r}: its height is given by variable {self.height!r}")
        params = [float(p) for p in self.params]
        return shapes.membership_np(self.kind, params, float(self.height), xs.reshape(-1)).reshape(xs.shape)


@dataclass(frozen=True)
class VariableInfo:
    """An input or output of a controller: its universe (``low``..``high``, None where the
    model gives none), its terms, and for outputs the defuzzification method and default."""

    name: str
    role: str  # "input" or "output"
    low: float | None
    high: float | None
    terms: tuple[TermInfo, ...]
    method: str | None = None
    default: float | None = None

    @property
    def range(self) -> tuple[float, float] | None:
        return (self.low, self.high) if self.low is not None and self.high is not None else None

    def term(self, name: str) -> TermInfo:
        for t in self.terms:
            if t.name == name:
                return t
        raise KeyError(f"{self.name} has no term {name!r} (terms: {', '.join(t.name for t in self.terms)})")

    def plot(self, **options: Any) -> Figure:
        """The terms as a matplotlib Figure (see :func:`fuzzyctl.engine.plot.plot_terms`)."""
        from fuzzyctl.engine.plot import plot_terms

        return plot_terms(self, **options)


class VariableMap(Mapping[str, VariableInfo]):
    """Names to :class:`VariableInfo`, in declaration order."""

    def __init__(self, items: list[VariableInfo]) -> None:
        self._items = {v.name: v for v in items}

    def __getitem__(self, name: str) -> VariableInfo:
        try:
            return self._items[name]
        except KeyError:
            raise KeyError(f"no variable {name!r} (names: {', '.join(self._items)})") from None

    def __iter__(self) -> Iterator[str]:
        return iter(self._items)

    def __len__(self) -> int:
        return len(self._items)

    def __repr__(self) -> str:
        return f"VariableMap({list(self._items)})"


def _param(p: Any, plan: Plan) -> float | str:
    return plan.inputs[p.index].name if isinstance(p, Slot) else float(p)


def _term(t: TermPlan, plan: Plan) -> TermInfo:
    return TermInfo(
        name=t.name,
        kind=t.kind,
        params=tuple(_param(p, plan) for p in t.params),
        points=t.pwl,
        height=_param(t.height, plan),
        _plan=t,
    )


def _range_of(fb: FunctionBlock | None, name: str, role: str) -> tuple[float | None, float | None]:
    if fb is None:
        return None, None
    block = fb.fuzzify_block(name) if role == "input" else fb.defuzzify_block(name)
    var = fb.variable(name)
    rng = (block.range if block else None) or (var.range if var else None)
    return (rng.low, rng.high) if rng is not None else (None, None)


def inputs_of(plan: Plan, fb: FunctionBlock | None) -> VariableMap:
    fuzzy = {plan.inputs[f.slot].name: f for f in plan.fuzzy_inputs}
    out = []
    for spec in plan.inputs:
        low, high = _range_of(fb, spec.name, "input")
        f = fuzzy.get(spec.name)
        terms = tuple(_term(t, plan) for t in f.terms) if f is not None else ()
        out.append(VariableInfo(spec.name, "input", low, high, terms, default=spec.default))
    return VariableMap(out)


def outputs_of(plan: Plan, fb: FunctionBlock | None) -> VariableMap:
    out = []
    for o in plan.outputs:
        if not o.is_output:
            continue
        low, high = _output_range(o, fb)
        out.append(
            VariableInfo(
                o.name,
                "output",
                low,
                high,
                tuple(_term(t, plan) for t in o.terms),
                method=o.method,
                default=o.default,
            )
        )
    return VariableMap(out)


def _output_range(o: OutputPlan, fb: FunctionBlock | None) -> tuple[float | None, float | None]:
    if o.low is not None and o.high is not None:
        return o.low, o.high
    return _range_of(fb, o.name, "output")
