"""The optimisers, from well-kept libraries: CMA-ES (``cma``), differential evolution,
least squares and L-BFGS-B (``scipy.optimize``).  All of them work on ``u`` in the unit box
(:mod:`fuzzyctl.tune.space`), ask an :class:`Evaluator` for costs (which counts the
budget, keeps the best candidate and the history, and reports progress), and stop with
the best candidate so far when the budget runs out or the user presses Ctrl-C."""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.tune.data import loss_value
from fuzzyctl.tune.problems import DataProblem

Arr = npt.NDArray[np.float64]
Progress = Callable[[int, int, float], None]
OPTIMIZERS = ("cmaes", "de", "lsq", "lbfgsb")
#: CMA-ES initial step: a tenth of each parameter's range (a refinement of a working system).
SIGMA0 = 0.1


class _Stop(Exception):
    """The budget is spent."""


@dataclass
class Outcome:
    """What an optimiser found."""

    best: Arr
    best_cost: float
    evaluations: int
    history: list[tuple[int, float, float]]  # (evaluation, cost, best so far)
    interrupted: bool = False
    message: str = ""
    seconds: float = 0.0
    notes: list[str] = field(default_factory=list)


class Evaluator:
    """Costs of candidates through an executor, within a budget of evaluations."""

    def __init__(self, problem: Any, execu: Any, budget: int, progress: Progress | None = None) -> None:
        self.problem = problem
        self.execu = execu
        self.budget = budget
        self.progress = progress
        self.evaluations = 0
        self.best: Arr | None = None
        self.best_cost = math.inf
        self.history: list[tuple[int, float, float]] = []

    def remaining(self) -> int:
        return self.budget - self.evaluations

    def record(self, u: Arr, cost: float) -> None:
        self.evaluations += 1
        if not math.isfinite(cost):
            cost = math.inf
        if cost < self.best_cost:
            self.best_cost = cost
            self.best = np.array(u, dtype=np.float64)
        self.history.append((self.evaluations, cost, self.best_cost))
        if self.progress is not None:
            self.progress(self.evaluations, self.budget, self.best_cost)

    def _batch(self, method: str, cands: Sequence[Arr]) -> list[list[Any]]:
        """``method`` of every task of every candidate in one batch, the parts of each
        candidate together (in the order of ``cands``)."""
        if self.evaluations and len(cands) > self.remaining():
            raise _Stop
        keys = self.problem.task_keys()
        items = [(np.asarray(c, dtype=np.float64), k) for c in cands for k in keys]
        parts = self.execu.map(method, items)
        m = len(keys)
        return [parts[i * m : (i + 1) * m] for i in range(len(cands))]

    def costs(self, cands: Sequence[Arr]) -> list[float]:
        out = []
        for c, parts in zip(cands, self._batch("task", cands), strict=True):
            cost = float(self.problem.combine(parts))
            self.record(np.asarray(c), cost)
            out.append(cost)
        return out

    def residuals(self, cands: Sequence[Arr]) -> list[Arr]:
        """Residual vectors (data problems), each counted as one evaluation."""
        out = []
        for c, parts in zip(cands, self._batch("residuals", cands), strict=True):
            r = np.concatenate(parts)
            self.record(np.asarray(c), _loss(self.problem, r))
            out.append(r)
        return out

    def jacobian(self, u: Arr) -> Arr:
        parts = self.execu.map(
            "jacobian", [(np.asarray(u, dtype=np.float64), k) for k in self.problem.task_keys()]
        )
        return np.vstack([J for _r, J in parts])

    def outcome(self, u0: Arr, started: float, interrupted: bool, message: str) -> Outcome:
        best = self.best if self.best is not None else np.asarray(u0, dtype=np.float64)
        return Outcome(
            best,
            self.best_cost,
            self.evaluations,
            self.history,
            interrupted,
            message,
            time.perf_counter() - started,
        )


def _loss(problem: DataProblem, r: Arr) -> float:
    a = np.abs(r)
    return loss_value(problem.loss, float(np.dot(r, r)), float(a.sum()), float(a.max(initial=0.0)), len(r))


def run(
    optimizer: str,
    problem: Any,
    execu: Any,
    u0: Arr,
    *,
    budget: int,
    seed: int,
    progress: Progress | None = None,
    options: dict[str, Any] | None = None,
) -> Outcome:
    """Minimise ``problem``'s cost from ``u0`` with ``optimizer`` (one of :data:`OPTIMIZERS`)."""
    if optimizer not in OPTIMIZERS:
        raise FuzzyctlError(f"unknown optimizer {optimizer!r} (known: {', '.join(OPTIMIZERS)})")
    if budget < 1:
        raise FuzzyctlError(f"the budget must be at least 1 evaluation, got {budget}")
    ev = Evaluator(problem, execu, budget, progress)
    started = time.perf_counter()
    opts = dict(options or {})
    message = ""
    interrupted = False
    try:
        if optimizer == "cmaes":
            message = _cmaes(ev, u0, seed, opts)
        elif optimizer == "de":
            message = _de(ev, u0, seed, opts)
        else:
            if not isinstance(problem, DataProblem):
                raise FuzzyctlError(
                    f"--optimizer {optimizer} needs data (--data): a closed-loop cost has no "
                    "gradient; use cmaes or de"
                )
            message = _lsq(ev, problem, u0, optimizer)
    except _Stop:
        message = "budget spent"
    except KeyboardInterrupt:
        interrupted = True
        message = "interrupted: kept the best candidate so far"
    out = ev.outcome(u0, started, interrupted, message)
    if optimizer in ("lsq", "lbfgsb") and isinstance(problem, DataProblem):
        out.notes.append(
            "gradient: closed form"
            if problem.gradient_note is None
            else f"gradient: finite differences ({problem.gradient_note})"
        )
    return out


# --------------------------------------------------------------------------- CMA-ES


def _cmaes(ev: Evaluator, u0: Arr, seed: int, opts: dict[str, Any]) -> str:
    from fuzzyctl.extras import require

    require(("cma",), "the CMA-ES optimiser (--optimizer cmaes)")
    import cma

    rng = np.random.default_rng(seed)
    n = len(u0)
    options: dict[str, Any] = {
        "bounds": [0.0, 1.0],
        "seed": math.nan,  # leave numpy's global generator alone ...
        "randn": lambda *shape: rng.standard_normal(shape),  # ... and draw from ours
        "verbose": -9,
        "maxfevals": ev.budget,
        "tolfun": 0.0,
        "tolx": 1e-9,
    }
    if n == 1:
        # cma refuses one dimension; a second, inert coordinate keeps it working.
        return _cmaes_1d(ev, u0, seed)
    if "popsize" in opts:
        options["popsize"] = int(opts["popsize"])
    es = cma.CMAEvolutionStrategy(list(u0), float(opts.get("sigma0", SIGMA0)), options)
    ev.costs([u0])
    while not es.stop():
        xs = es.ask()
        if len(xs) > ev.remaining():
            return "budget spent"
        fs = ev.costs([np.clip(np.asarray(x), 0.0, 1.0) for x in xs])
        es.tell(xs, fs)
    return "converged: " + ", ".join(f"{k}" for k in es.stop())


def _cmaes_1d(ev: Evaluator, u0: Arr, seed: int) -> str:
    from fuzzyctl.extras import require

    require(("cma",), "the CMA-ES optimiser (--optimizer cmaes)")
    import cma

    rng = np.random.default_rng(seed)
    es = cma.CMAEvolutionStrategy(
        [float(u0[0]), 0.5],
        SIGMA0,
        {"bounds": [0.0, 1.0], "seed": math.nan, "randn": lambda *s: rng.standard_normal(s), "verbose": -9},
    )
    ev.costs([u0])
    while not es.stop():
        xs = es.ask()
        if len(xs) > ev.remaining():
            return "budget spent"
        fs = ev.costs([np.clip(np.asarray(x[:1]), 0.0, 1.0) for x in xs])
        es.tell(xs, fs)
    return "converged"


# --------------------------------------------------------------------------- differential evolution


def _de(ev: Evaluator, u0: Arr, seed: int, opts: dict[str, Any]) -> str:
    from scipy.optimize import differential_evolution

    n = len(u0)
    # Population: 15 per parameter as scipy advises, fewer when the budget would otherwise
    # allow less than ~20 generations (at least 5 members).
    mult = int(opts.get("popsize", max(1, min(15, ev.budget // (20 * n) if n else 15))))
    pop = max(5, mult * n)
    maxiter = max(0, ev.budget // pop - 1)

    def mapper(_func: Any, xs: Any) -> list[float]:
        return ev.costs([np.asarray(x, dtype=np.float64) for x in xs])

    def stop(intermediate_result: Any) -> bool:  # the name tells scipy the new signature
        return ev.remaining() < pop

    # The first population: the system as written, half of the rest spread around it (a
    # tenth of each range, as CMA-ES starts) and half anywhere in the box (Latin hypercube):
    # a refinement of a working system with room for a global search.
    rng = np.random.default_rng(seed)
    near = (pop - 1) // 2
    far = pop - 1 - near
    strata = (rng.permuted(np.tile(np.arange(far), (n, 1)), axis=1).T + rng.random((far, n))) / max(far, 1)
    init = np.vstack(
        [np.clip(u0, 0.0, 1.0), np.clip(u0 + SIGMA0 * rng.standard_normal((near, n)), 0.0, 1.0), strata]
    )
    res = differential_evolution(
        lambda x: math.inf,  # never called: every evaluation goes through mapper
        bounds=[(0.0, 1.0)] * n,
        init=init,
        maxiter=maxiter,
        rng=rng,
        workers=mapper,
        updating="deferred",
        polish=False,
        tol=0.0,
        callback=stop,
    )
    return str(res.message)


# --------------------------------------------------------------------------- gradient methods


def _lsq(ev: Evaluator, problem: DataProblem, u0: Arr, optimizer: str) -> str:
    from scipy.optimize import least_squares, minimize

    closed = problem.gradient_note is None
    last: dict[str, Any] = {}

    def residual(u: Arr) -> Arr:
        key = u.tobytes()
        if last.get("key") != key:
            last["key"], last["r"] = key, ev.residuals([u])[0]
        r: Arr = last["r"]
        return r

    def jac(u: Arr) -> Arr:
        if closed:
            return ev.jacobian(u)
        # Forward differences of the engine's residuals, the perturbed candidates evaluated
        # together (in parallel on Dask) and counted in the budget.
        h = 1e-6
        base = residual(u)
        steps = []
        for j in range(len(u)):
            v = u.copy()
            v[j] = v[j] + h if v[j] + h <= 1.0 else v[j] - h
            steps.append(v)
        rs = ev.residuals(steps)
        return np.column_stack(
            [(r - base) / (s[j] - u[j]) for j, (r, s) in enumerate(zip(rs, steps, strict=True))]
        )

    if optimizer == "lsq" and problem.loss == "rmse":
        res = least_squares(
            residual, np.clip(u0, 0.0, 1.0), jac=jac, bounds=(0.0, 1.0), method="trf", max_nfev=ev.budget
        )
        return str(res.message)

    def fun(u: Arr) -> tuple[float, Arr]:
        r = residual(u)
        J = jac(u)
        n = len(r)
        if problem.loss == "rmse":
            f = math.sqrt(float(np.dot(r, r)) / n)
            g = J.T @ r / (n * f) if f > 0 else np.zeros(len(u))
        elif problem.loss == "mae":
            f = float(np.mean(np.abs(r)))
            g = J.T @ np.sign(r) / n
        else:  # max error: a subgradient through the worst sample
            k = int(np.argmax(np.abs(r)))
            f = float(abs(r[k]))
            g = J[k] * np.sign(r[k])
        return f, g

    res = minimize(
        fun,
        np.clip(u0, 0.0, 1.0),
        jac=True,
        method="L-BFGS-B",
        bounds=[(0.0, 1.0)] * len(u0),
        options={"maxfun": ev.budget, "maxiter": ev.budget},
    )
    return str(res.message)
