"""``fuzzyctl.tune(...)``: tune the parameters a user frees against data or the plant."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fuzzyctl.diagnostics import InputError
from fuzzyctl.model import Document, FunctionBlock
from fuzzyctl.tune import optimize, parallel, plant
from fuzzyctl.tune.data import LOSSES, Columns, read_table, require, split
from fuzzyctl.tune.problems import DataProblem, PlantProblem
from fuzzyctl.tune.space import Space, build_space

#: Significant digits (of each parameter's range) written to the tuned file.
DIGITS = 6


@dataclass
class TuneResult:
    """A tuning run: the tuned document, costs before and after, what changed, the history."""

    document: Document
    original: Document
    block_index: int
    kind: str  # "data" or "plant"
    optimizer: str
    seed: int
    budget: int
    evaluations: int
    seconds: float
    workers: int
    interrupted: bool
    message: str
    cost_name: str
    before: float
    after: float
    table: list[tuple[str, float, float]]  # (what, before, after): errors or per-scenario costs
    changes: list[tuple[str, float, float]]
    history: list[tuple[int, float, float]]
    notes: list[str] = field(default_factory=list)
    problem: Any = field(default=None, repr=False)
    traces: tuple[list[Any], list[Any]] = field(default=([], []), repr=False)

    @property
    def block(self) -> FunctionBlock:
        return self.document.blocks[self.block_index]

    def write_fcl(self, path: str | Path) -> Path:
        """The tuned document as FCL (comments kept, one added saying how it was tuned)."""
        from fuzzyctl.files import write_atomic
        from fuzzyctl.formats.fcl.type2 import write  # (type-1 models: fuzzyctl.fcl's text)

        path = Path(path)
        write_atomic(path, write(self.document))
        return path

    def write_report(self, directory: str | Path) -> dict[str, Path]:
        """report.md, report.json, cost history and before/after plots (PNG and HTML)."""
        from fuzzyctl.tune.report import write_report

        return write_report(self, Path(directory))

    def save(self, path: str | Path, report: str | Path | None = None) -> dict[str, str]:
        """Write the tuned FCL to ``path`` and, given ``report``, the report directory; the
        files written by kind (``fcl``, ``md``, ``json``, ...)."""
        files = {"fcl": str(self.write_fcl(path))}
        if report is not None:
            files.update({k: str(v) for k, v in self.write_report(report).items()})
        return files

    def to_dict(self, files: dict[str, str] | None = None) -> dict[str, Any]:
        """What ``fuzzyctl tune --json`` prints: the run (costs, changes, history) and the
        files written."""
        from fuzzyctl.tune.report import as_dict

        return {**as_dict(self), "files": dict(files or {})}


def _document(model: Document | FunctionBlock | str | Path) -> Document:
    import fuzzyctl

    if isinstance(model, Document):
        return model
    if isinstance(model, FunctionBlock):
        return Document((model,))
    return fuzzyctl.load(model)


def tune(
    model: Document | FunctionBlock | str | Path,
    *,
    data: str | Path | Mapping[str, Any] | Any | None = None,
    output: str | Sequence[str] | None = None,
    plant_config: str | Path | None = None,
    cost: str | Mapping[str, float] | None = None,
    free: str | Sequence[str] | None = "all",
    optimizer: str | None = None,
    budget: int | None = None,
    seed: int = 0,
    loss: str = "rmse",
    validation: float = 0.2,
    validation_data: str | Path | Mapping[str, Any] | Any | None = None,
    block: str | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    client: Any = None,
    runtime: str | None = None,
    keep_zero: bool | None = None,
    progress: optimize.Progress | None = None,
    options: dict[str, Any] | None = None,
    widen: bool = False,
) -> TuneResult:
    """Tune the parameters ``free`` names (see :func:`fuzzyctl.tune.space.parse_free`) of a
    function block against ``data`` (columns named like the inputs, and ``output``: the
    target columns) or against the closed loop of a ``fuzzyctl simulate`` configuration
    (``plant_config``, with ``cost`` and scenarios from its ``[tune]`` table).

    ``optimizer``: ``"cmaes"`` (default for the plant), ``"de"``, ``"lsq"`` (default for
    data: least squares with the closed-form gradient where it holds) or ``"lbfgsb"``;
    ``budget`` evaluations (default 200); ``workers`` Dask worker processes on this machine
    (default: one per CPU; 0 runs in this process), or ``scheduler`` / ``client`` for an
    existing cluster.  ``keep_zero`` (default: True against the plant, False against data)
    keeps abscissae and singletons at 0 where they are: the loop's equilibrium.  Ctrl-C
    stops the search and keeps the best candidate so far.

    Interval type-2 terms: their lower functions are free with their term (scale and lag,
    or an explicit function kept below the upper one; :mod:`fuzzyctl.tune.type2`).
    ``widen``: a type-1 block is first made type-2 with lower functions equal to the upper
    ones (scale 1, lag 0: the same outputs), then only the lower functions are tuned."""
    if (data is None) == (plant_config is None):
        raise InputError("give either data (--data) or a plant configuration (--plant)")
    if loss not in LOSSES:
        raise InputError(f"--loss must be one of {', '.join(LOSSES)}, got {loss!r}")
    doc = _document(model)
    try:
        fb = doc.block(block)
    except KeyError as exc:
        raise InputError(str(exc.args[0])) from None
    index = doc.blocks.index(fb)
    if widen:
        doc, fb = _widened(doc, index)
    kind = "data" if data is not None else "plant"
    space = build_space(
        fb, free, keep_zero=kind == "plant" if keep_zero is None else keep_zero, lower_only=widen
    )
    opt = optimizer or ("lsq" if kind == "data" else "cmaes")
    if opt not in optimize.OPTIMIZERS:
        raise InputError(f"--optimizer must be one of {', '.join(optimize.OPTIMIZERS)}, got {opt!r}")
    if kind == "plant" and opt in ("lsq", "lbfgsb"):
        raise InputError(
            f"--optimizer {opt} needs data (--data): a closed-loop cost has no gradient; use cmaes or de"
        )
    if budget is None:
        budget = 200
    problem: DataProblem | PlantProblem
    if kind == "data":
        problem = _data_problem(space, fb, data, output, loss, validation, validation_data, seed)
        cost_name = f"training {loss.upper() if loss != 'max' else 'max error'}"
    else:
        assert plant_config is not None
        problem = _plant_problem(space, doc, index, plant_config, cost, runtime)
        cost_name = "cost"
    execu = parallel.executor(workers, scheduler, client)
    try:
        execu.bind(problem)
        outcome = optimize.run(
            opt, problem, execu, space.initial(), budget=budget, seed=seed, progress=progress, options=options
        )
        workers_used = execu.workers
    finally:
        execu.close()
    return _result(doc, index, fb, space, problem, kind, opt, seed, budget, outcome, workers_used, cost_name)


def _widened(doc: Document, index: int) -> tuple[Document, FunctionBlock]:
    from fuzzyctl.diagnostics import FuzzyctlError
    from fuzzyctl.engine.type2 import Type2Controller
    from fuzzyctl.tune.type2 import widen

    fb = widen(doc.blocks[index])
    if not fb.is_type2:
        raise InputError("--widen: the block has no fuzzy-set term to give a lower function")
    try:
        Type2Controller(fb)  # what the type-2 engine does not evaluate is said here, once
    except FuzzyctlError as exc:
        raise InputError(f"--widen: {exc}") from None
    blocks = list(doc.blocks)
    blocks[index] = fb
    return dataclasses.replace(doc, blocks=tuple(blocks)), fb


def _data_problem(
    space: Space,
    fb: FunctionBlock,
    data: Any,
    output: str | Sequence[str] | None,
    loss: str,
    validation: float,
    validation_data: Any,
    seed: int,
) -> DataProblem:
    where = str(data) if isinstance(data, str | Path) else "data"
    cols = read_table(data)
    outs = [v.name for v in fb.outputs]
    targets = (
        [output]
        if isinstance(output, str)
        else list(output)
        if output is not None
        else [o for o in outs if o in cols]
    )
    if not targets:
        raise InputError(f"{where}: no column names an output of {fb.name} ({', '.join(outs)}); use --output")
    for t in targets:
        if t not in outs:
            raise InputError(f"--output {t!r} is not an output of {fb.name} (outputs: {', '.join(outs)})")
    needed = [v.name for v in fb.inputs if v.initial is None]
    require(cols, [*needed, *targets], where)
    valid: Columns | None
    if validation_data is not None:
        valid = read_table(validation_data, what="validation data")
        require(valid, [*needed, *targets], str(validation_data))
        train = cols
    else:
        s = split(cols, validation, seed)
        train, valid = s.train, s.validation
    return DataProblem(space, tuple(targets), train, valid, loss)


def _plant_problem(
    space: Space, doc: Document, index: int, config: str | Path, cost: Any, runtime: str | None
) -> PlantProblem:
    scenarios, weights = plant.load_scenarios(config, cost=cost)
    name = plant.controlled_block(scenarios[0].config, doc)
    fb = doc.blocks[index]
    if name is not None and fb.name is not None and name != fb.name:
        raise InputError(f"{config}: the loop runs function block {name!r}, not {fb.name!r} (use --block)")
    # The loop runs the file being tuned, not the one its [controller] names.
    return PlantProblem(space, doc, index, scenarios, weights, runtime)


def _result(
    doc: Document,
    index: int,
    fb: FunctionBlock,
    space: Space,
    problem: DataProblem | PlantProblem,
    kind: str,
    opt: str,
    seed: int,
    budget: int,
    outcome: optimize.Outcome,
    workers: int,
    cost_name: str,
) -> TuneResult:
    # Costs are recomputed here, in this process, for the original and for the tuned block
    # as it is written (rounded to DIGITS): the report is about the file on disk.
    tuned = space.decode(outcome.best, digits=DIGITS)
    before, table_before, extra_before = _evaluate(problem, fb)
    after, table_after, extra_after = _evaluate(problem, tuned)
    notes = list(space.notes) + list(outcome.notes)
    if not after < before:
        tuned, after, table_after, extra_after = fb, before, table_before, extra_before
        notes.append("no candidate improved on the system as written: it is kept unchanged")
    changes = [] if tuned is fb else space.changes(outcome.best, digits=DIGITS)
    table = [(k, table_before[k], table_after[k]) for k in table_before]
    comment = (
        f"Tuned by fuzzyctl tune ({opt}, seed {seed}, {outcome.evaluations} evaluations"
        f"{', interrupted' if outcome.interrupted else ''}): {cost_name} {before:.6g} -> {after:.6g}."
    )
    if tuned is not fb:
        tuned = dataclasses.replace(tuned, comments=(*fb.comments, comment))
    blocks = list(doc.blocks)
    blocks[index] = tuned
    new_doc = dataclasses.replace(doc, blocks=tuple(blocks))
    result = TuneResult(
        new_doc,
        doc,
        index,
        kind,
        opt,
        seed,
        budget,
        outcome.evaluations,
        outcome.seconds,
        workers,
        outcome.interrupted,
        outcome.message,
        cost_name,
        before,
        after,
        table,
        changes,
        outcome.history,
        notes,
        problem,
    )
    result.traces = (extra_before, extra_after)
    return result


def _evaluate(
    problem: DataProblem | PlantProblem, fb: FunctionBlock
) -> tuple[float, dict[str, float], list[Any]]:
    """The cost, the report's rows and (plant) the traces of one system."""
    if isinstance(problem, DataProblem):
        parts = [problem.task(fb, k) for k in problem.task_keys()]
        return float(problem.combine(parts)), problem.scores(fb), []
    rows: dict[str, float] = {}
    traces = []
    values = []
    for k, sc in enumerate(problem.scenarios):
        trace = problem.run(fb, k)
        v = plant.metrics(sc, trace, list(problem.weights))
        v["cost"] = plant.weighted(v, problem.weights)
        values.append(v)
        traces.append(trace)
        rows[f"{sc.name}: cost"] = v["cost"]
        for term in problem.weights:
            rows[f"{sc.name}: {term}"] = v[term]
    return float(problem.combine(values)), rows, traces


def check_budget(budget: int) -> int:
    if budget < 1 or not math.isfinite(budget):
        raise InputError(f"--budget must be at least 1, got {budget}")
    return budget


__all__ = ["TuneResult", "tune"]
