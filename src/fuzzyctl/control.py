"""A fuzzy controller as a python-control system (``pip install 'fuzzyctl[control]'``).

:func:`iosys` wraps a compiled controller as a :class:`control.NonlinearIOSystem` that
``control.interconnect`` and ``control.input_output_response`` accept: its inputs and outputs
are the function block's, its map the engine's.  A static map has no states; an output named
in ``integrate`` is followed by an integrator (the fuzzy PI of IEC 61131-7 figure A.13b, the
``fuzzy_pi`` structure of ``fuzzyctl simulate``) whose value is a state of the system and
replaces that output.  ``dt=0`` gives a continuous-time system; ``dt=period`` a discrete one
that does what ``fuzzyctl simulate`` does each controller cycle (the block evaluated once per
period, the command held), so a loop closed with a zero-order-hold plant reproduces
``fuzzyctl simulate`` to rounding.

:func:`nonlinearity` gives a one-input, one-output block as a
:class:`control.DescribingFunctionNonlinearity` for ``control.describing_function`` and
``control.describing_function_response`` (limit cycles from the Nyquist plot); see
docs/control.md.

python-control is imported here only, when this module is imported: ``import fuzzyctl`` never
needs it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from fuzzyctl.diagnostics import InputError

if TYPE_CHECKING:
    from fuzzyctl.engine.controller import Controller
    from fuzzyctl.model import Document, FunctionBlock

    ControllerLike = Controller | Document | FunctionBlock | str | Path

try:
    import control as _ct
except ModuleNotFoundError as exc:  # pragma: no cover - the extra is installed for the tests
    raise ModuleNotFoundError(
        "fuzzyctl.control needs python-control: pip install 'fuzzyctl[control]'", name="control"
    ) from exc

__all__ = ["FuzzyNonlinearity", "Integral", "initial_state", "iosys", "nonlinearity"]


@dataclass(frozen=True)
class Integral:
    """An integrator after a fuzzy output: ``U' = gain * output``, ``U`` held in
    ``[low, high]`` (the limit is also the anti-windup: ``U`` never runs past it), starting at
    ``initial``.  The same parameters as ``fuzzyctl simulate``'s ``fuzzy_pi`` structure.

    ```python
    >>> Integral(gain=2.0, low=0.0, high=100.0).clip(150.0)
    100.0

    ```
    """

    gain: float = 1.0
    low: float = -math.inf
    high: float = math.inf
    initial: float = 0.0

    def __post_init__(self) -> None:
        if not self.low < self.high:
            raise InputError(f"integrate: needs low < high, got [{self.low}, {self.high}]")

    def clip(self, value: float) -> float:
        """``value`` limited to ``[low, high]``."""
        return min(max(value, self.low), self.high)


def _compile(controller: ControllerLike, block: str | None) -> Controller:
    import fuzzyctl
    from fuzzyctl.engine.controller import Controller

    if isinstance(controller, Controller):
        if block is not None:
            raise InputError("block: give it only with a model or a file, not a compiled Controller")
        return controller
    model = fuzzyctl.load(controller) if isinstance(controller, str | Path) else controller
    # "ignore", not compile's "warn": the same numbers, but a simulation or a describing
    # function calls the map thousands of times, far outside the ranges by design (an
    # amplitude sweep), and one warning per call would bury the output
    return fuzzyctl.compile(model, block=block, out_of_range="ignore")


def iosys(
    controller: ControllerLike,
    *,
    integrate: Mapping[str, Integral | float] | None = None,
    dt: float = 0,
    name: str | None = None,
    block: str | None = None,
    out_of_range: str | None = None,
) -> Any:
    """The controller as a :class:`control.NonlinearIOSystem`.

    ``controller`` is a compiled :class:`~fuzzyctl.engine.controller.Controller`, a model or a
    file (compiled with :func:`fuzzyctl.compile`).  Inputs and outputs carry the block's
    names.  ``integrate={"dheat": Integral(gain, low, high)}`` (or just a gain) integrates
    that output: the system gets a state of that name and its output ``dheat`` is the
    integrated value.  ``dt=0``: continuous time; ``dt > 0``: sampled every ``dt`` s, the
    integrator a forward sum ``U += gain * output * dt`` as in ``fuzzyctl simulate``.
    ``out_of_range`` (``"clamp"``, ``"warn"``, ``"raise"``, ``"ignore"``; docs/engine.md):
    what an input outside its range does; default: the controller's own setting, and
    ``"ignore"`` (the engine's numbers, no warning per call) for a model compiled here.

    ```python
    >>> import control, fuzzyctl.control
    >>> sys = fuzzyctl.control.iosys("examples/tank.fcl", integrate={"dheat": 1.0}, dt=1.0)
    >>> sys.input_labels, sys.output_labels, sys.state_labels
    (['error', 'rate'], ['dheat'], ['dheat'])

    ```
    """
    ctl = _compile(controller, block)
    ins, outs = list(ctl.inputs), list(ctl.outputs)
    integrals = {
        k: v if isinstance(v, Integral) else Integral(gain=float(v)) for k, v in (integrate or {}).items()
    }
    for out in integrals:
        if out not in outs:
            raise InputError(
                f"integrate: {out!r} is not an output of {ctl.name} (outputs: {', '.join(outs)})"
            )
    if not (dt >= 0 and math.isfinite(dt)):
        raise InputError(f"dt must be 0 (continuous) or a period > 0 s, got {dt}")
    states = [o for o in outs if o in integrals]
    where = {o: i for i, o in enumerate(states)}

    def fuzzy(u: Any) -> dict[str, float]:
        values = dict(zip(ins, (float(v) for v in np.atleast_1d(u)), strict=True))
        return ctl.evaluate(values, out_of_range=out_of_range)

    def after_cycle(x: Any, f: Mapping[str, float]) -> np.ndarray:
        # the integrators' values after one period (discrete time)
        return np.array(
            [integrals[o].clip(float(x[where[o]]) + integrals[o].gain * f[o] * dt) for o in states]
        )

    def update(t: float, x: Any, u: Any, params: Any) -> np.ndarray:
        f = fuzzy(u)
        if dt:
            return after_cycle(x, f)
        rates = []
        for o in states:
            spec, value, rate = integrals[o], float(x[where[o]]), integrals[o].gain * f[o]
            # held at a limit while the rate pushes outward: no windup
            stuck = (value >= spec.high and rate > 0) or (value <= spec.low and rate < 0)
            rates.append(0.0 if stuck else rate)
        return np.array(rates)

    def output(t: float, x: Any, u: Any, params: Any) -> np.ndarray:
        f = fuzzy(u)
        held = after_cycle(x, f) if dt else [integrals[o].clip(float(x[where[o]])) for o in states]
        return np.array([held[where[o]] if o in where else f[o] for o in outs])

    extra: dict[str, Any] = {"states": states} if states else {}  # a static map: no states at all
    return _ct.NonlinearIOSystem(
        update if states else None, output, inputs=ins, outputs=outs, dt=dt, name=name or ctl.name, **extra
    )


def initial_state(system: Any, integrate: Mapping[str, Integral | float]) -> np.ndarray:
    """The integrators' ``initial`` values in the order of ``system``'s states (for
    ``control.input_output_response(..., X0=...)``).

    ```python
    >>> import fuzzyctl.control as fc
    >>> sys = fc.iosys("examples/tank.fcl", integrate={"dheat": fc.Integral(initial=5.0)})
    >>> fc.initial_state(sys, {"dheat": fc.Integral(initial=5.0)})
    array([5.])

    ```
    """
    values = {k: v.clip(v.initial) if isinstance(v, Integral) else 0.0 for k, v in integrate.items()}
    return np.array([values.get(s, 0.0) for s in system.state_labels])


class FuzzyNonlinearity(_ct.DescribingFunctionNonlinearity):  # type: ignore[misc]
    """A one-input, one-output fuzzy map ``u = f(e)`` as python-control's static
    nonlinearity (its describing function is computed numerically by python-control)."""

    def __init__(
        self, controller: Controller, input: str, output: str, out_of_range: str | None = None
    ) -> None:
        super().__init__()
        self.controller, self.input, self.output = controller, input, output
        self.out_of_range = out_of_range

    def __call__(self, x: float) -> float:
        out = self.controller.evaluate({self.input: float(x)}, out_of_range=self.out_of_range)
        return float(out[self.output])

    def _isstatic(self) -> bool:
        return True


def nonlinearity(
    controller: ControllerLike,
    *,
    output: str | None = None,
    block: str | None = None,
    out_of_range: str | None = None,
) -> FuzzyNonlinearity:
    """A one-input controller as a :class:`control.DescribingFunctionNonlinearity`, for
    ``control.describing_function(N, A)`` and the limit cycles of
    ``control.describing_function_response(G, N, amplitudes)``.

    The map must not keep state between calls (an output with ``DEFAULT := NC`` that no rule
    reaches would): the describing function assumes a static map.  ``out_of_range`` as
    for :func:`iosys` (an amplitude sweep goes past the input's range by design: the map
    there is what the terms give, e.g. the saturation of shoulder terms).

    ```python
    >>> import control, fuzzyctl.control
    >>> N = fuzzyctl.control.nonlinearity("tests/data/control/saturation.fcl")
    >>> round(control.describing_function(N, 2.0)[0].real, 3)   # the saturation's: 0.609
    np.float64(0.609)

    ```
    """
    ctl = _compile(controller, block)
    if len(ctl.inputs) != 1:
        raise InputError(
            f"a describing function needs a one-input controller; {ctl.name} has {len(ctl.inputs)}"
            f" ({', '.join(ctl.inputs)})"
        )
    outs = list(ctl.outputs)
    if output is None:
        if len(outs) != 1:
            raise InputError(
                f"{ctl.name} has {len(outs)} outputs: choose one with output= ({', '.join(outs)})"
            )
        output = outs[0]
    elif output not in outs:
        raise InputError(f"output {output!r} is not an output of {ctl.name} (outputs: {', '.join(outs)})")
    return FuzzyNonlinearity(ctl, next(iter(ctl.inputs)), output, out_of_range)
