"""The closed loop: a plant, a controller structure, setpoints, disturbances, and the clock.

The controller runs every ``period`` seconds (its PLC cycle) and its commands are held until
the next call while the plant model is integrated (a zero-order hold).  One cycle at time t:

1. measure the plant (plus optional seeded Gaussian sensor noise);
2. read the setpoint profiles at t;
3. call the structure with the signals ``{"t", setpoints..., measurements...}``;
4. add the disturbance profiles, saturate every plant input to its actuator range;
5. record the row, integrate the plant from t to t + period.

:class:`Loop` can be driven one step at a time (``loop.step()``, for an interactive front
end that shows the loop as it runs) or at once (``loop.run(duration)`` -> :class:`Trace`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from fuzzyctl.diagnostics import InputError
from fuzzyctl.files import write_atomic
from fuzzyctl.sim.integrate import FixedStep, Integrator
from fuzzyctl.sim.plant import Plant
from fuzzyctl.sim.profiles import Profile
from fuzzyctl.sim.structures import Structure


class Trace:
    """The recorded signals of a run: one float64 array per column, ``trace["angle"]``.

    Columns: ``t``, the setpoints, the measurements, the plant inputs as applied (after
    disturbances and saturation), then the structure's internal signals (``fb.<name>`` for
    the fuzzy block's inputs and outputs, ``pid.<term>`` for the PID block)."""

    def __init__(
        self, columns: Mapping[str, npt.ArrayLike], *, units: Mapping[str, str] | None = None
    ) -> None:
        self.columns = {k: np.asarray(v, dtype=np.float64) for k, v in columns.items()}
        self.units = dict(units or {})

    def __getitem__(self, name: str) -> npt.NDArray[np.float64]:
        try:
            return self.columns[name]
        except KeyError:
            raise InputError(
                f"no signal {name!r} in the trace (signals: {', '.join(self.columns)})"
            ) from None

    def __contains__(self, name: object) -> bool:
        return name in self.columns

    def __len__(self) -> int:
        return len(self.columns["t"]) if "t" in self.columns else 0

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.columns)

    def rows(self) -> Iterator[dict[str, float]]:
        for i in range(len(self)):
            yield {k: float(v[i]) for k, v in self.columns.items()}

    def to_csv(self, path: str | Path) -> Path:
        """Write the trace as CSV (header of signal names, ``repr`` floats), atomically."""
        path = Path(path)
        names = list(self.columns)
        data = np.column_stack([self.columns[n] for n in names]) if names else np.empty((0, 0))
        lines = [",".join(names)]
        lines.extend(",".join(repr(float(v)) for v in row) for row in data)
        write_atomic(path, "\n".join(lines) + "\n")
        return path

    @classmethod
    def from_csv(cls, path: str | Path) -> Trace:
        text = Path(path).read_text().splitlines()
        names = text[0].split(",")
        data = np.array([[float(x) for x in line.split(",")] for line in text[1:] if line], dtype=np.float64)
        data = data.reshape(-1, len(names))
        return cls({n: data[:, i] for i, n in enumerate(names)})


class Loop:
    """A closed loop that can be stepped.

    ``setpoints`` and ``disturbances`` map names to :class:`~fuzzyctl.sim.profiles.Profile`
    (or any ``t -> value`` callable).  Setpoint names become signals the structure reads;
    disturbance names are plant inputs: added to the structure's command when the structure
    drives that input, the input's value otherwise.  ``noise`` maps measurement names to the
    standard deviation of Gaussian noise added to them (``seed`` makes it repeatable)."""

    def __init__(
        self,
        plant: Plant[Any],
        structure: Structure,
        *,
        period: float,
        setpoints: Mapping[str, Profile | Callable[[float], float]] | None = None,
        disturbances: Mapping[str, Profile | Callable[[float], float]] | None = None,
        integrator: Integrator | None = None,
        noise: Mapping[str, float] | None = None,
        seed: int = 0,
    ) -> None:
        if not (period > 0 and math.isfinite(period)):
            raise InputError(f"period (the controller cycle) must be > 0 s, got {period}")
        self.plant, self.structure, self.period = plant, structure, float(period)
        self.setpoints = dict(setpoints or {})
        self.disturbances = dict(disturbances or {})
        self.integrator = integrator or FixedStep(min(0.01, self.period))
        self.noise = dict(noise or {})
        self.seed = seed
        measured = [p.name for p in plant.outputs]
        inputs = [p.name for p in plant.inputs]
        for name in self.setpoints:
            if name in measured or name in inputs or name == "t":
                raise InputError(f"setpoint name {name!r} is already a signal of the {plant.kind} plant")
        for name in self.disturbances:
            plant.input_port(name)
        for name in structure.drives:
            if name not in inputs:
                raise InputError(
                    f"the controller drives {name!r}, which is not an input of the {plant.kind} plant "
                    f"(inputs: {', '.join(inputs)})"
                )
        for name in self.noise:
            if name not in measured:
                raise InputError(
                    f"noise on {name!r}: not a measurement of the {plant.kind} plant ({', '.join(measured)})"
                )
        self.columns: tuple[str, ...] = (
            "t",
            *self.setpoints,
            *measured,
            *(n for n in inputs if n not in measured),
            *structure.internal_names(),
        )
        self.units = {p.name: p.unit for p in (*plant.outputs, *plant.inputs)}
        self.units["t"] = "s"
        self.reset()

    def reset(self) -> None:
        """Back to t = 0 with the plant's initial state and a fresh controller."""
        self.k = 0
        self.state = self.plant.start()
        self.structure.reset()
        self._rng = np.random.default_rng(self.seed)
        self.last: dict[str, float] = {}

    @property
    def t(self) -> float:
        """The current time [s] (a whole number of periods)."""
        return self.k * self.period

    def measure(self) -> dict[str, float]:
        """The plant's measurements now (with noise if configured)."""
        y = self.plant.measure(self.state)
        for name, sigma in self.noise.items():
            y[name] += float(self._rng.normal(0.0, sigma))
        return y

    def cycle(self) -> dict[str, float]:
        """One controller cycle: returns the row recorded at its start time."""
        t = self.t
        y = self.measure()
        w = {name: float(profile(t)) for name, profile in self.setpoints.items()}
        signals = {"t": t, **w, **y}
        commands = self.structure.step(signals, self.period)
        applied: dict[str, float] = {}
        for port in self.plant.inputs:
            value = commands.get(port.name, port.default)
            if not math.isfinite(value):
                raise InputError(f"the controller commanded {port.name} = {value} at t = {t:g} s")
            if port.name in self.disturbances:
                d = float(self.disturbances[port.name](t))
                value = value + d if port.name in commands else d
            applied[port.name] = min(max(value, port.low), port.high)
        row = {"t": t, **w, **y}
        for name, value in applied.items():
            row.setdefault(name, value)
        row.update(self.structure.internals)
        self.state = self.plant.advance(self.state, applied, t, self.period, self.integrator)
        self.k += 1
        self.last = row
        return row

    def step(self, dt: float | None = None) -> dict[str, float]:
        """Advance by ``dt`` seconds (default: one period; rounded to whole periods, at least
        one) and return the last recorded row."""
        n = 1 if dt is None else max(1, round(dt / self.period))
        row: dict[str, float] = {}
        for _ in range(n):
            row = self.cycle()
        return row

    def run(self, duration: float, *, progress: Callable[[int, int], None] | None = None) -> Trace:
        """Run ``duration`` seconds from the current state and return what was recorded
        (``progress(done, total)`` is called every 1 % of the cycles)."""
        if not duration > 0:
            raise InputError(f"duration must be > 0 s, got {duration}")
        n = max(1, round(duration / self.period))
        data = {name: np.full(n + 1, np.nan) for name in self.columns}
        every = max(1, n // 100)
        for i in range(n):
            row = self.cycle()
            for name, value in row.items():
                if name in data:
                    data[name][i] = value
            if progress is not None and (i % every == 0 or i == n - 1):
                progress(i + 1, n)
        # The final state is measured too, so the trace ends at t = duration.
        final = {"t": self.t, **{k: float(p(self.t)) for k, p in self.setpoints.items()}, **self.measure()}
        for name in self.columns:
            data[name][n] = final.get(name, data[name][n - 1])
        return Trace(data, units=self.units)
