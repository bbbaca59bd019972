"""An initial fuzzy system from data (``fuzzyctl learn``), like MATLAB's ``genfis``:

* **grid partition**: N triangular terms per input forming a partition of unity (each
  term peaks where its neighbours reach 0; ramps at the ends), or N Gaussians at the same
  centres crossing at 0.5 (``shape="gauss"``), one rule per combination;
* **clustering** (scipy's k-means++ on the standardised inputs and output, seeded; the
  best of five starts):
  one rule per cluster, a Gaussian term per input at the cluster centre with the spread of
  its members (floored at range / (2 K) so that no rule is a spike);

then the consequents by linear least squares, the ANFIS hybrid step: for the conditions as
they are, the output is linear in the consequents, ``y = Phi theta`` with ``Phi`` the
normalised firing strengths (times the inputs for first-order Takagi-Sugeno), taken from
the closed form of :mod:`fuzzyctl.tune.gradient`.

* ``kind="tsk"``: a first-order Takagi-Sugeno system, one ``Linear`` output term per rule,
  METHOD WTAVER (``numpy.linalg.lstsq``);
* ``kind="mamdani"``: singleton outputs under CoGS: the per-rule optimum is grouped into
  ``out_terms`` linguistic singletons (k-means in one dimension), each rule concludes the
  nearest one, and the singleton positions are refitted by bounded least squares
  (``scipy.optimize.lsq_linear``) within the output's RANGE.

AND is PROD by default: with a grid partition the products of the terms again sum to one,
so the system interpolates multilinearly between the rule centres; MIN (what the PLC
blocks' Basic level has) gives kinks along the diagonals.  The errors reported are those
of the engine evaluating the written file.
"""

from __future__ import annotations

import itertools
import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from fuzzyctl.diagnostics import InputError
from fuzzyctl.engine.compile import COMPAT_PROFILES
from fuzzyctl.engine.lowering.lower import lower
from fuzzyctl.kinds import norms
from fuzzyctl.model import (
    And,
    Conclusion,
    Default,
    DefuzzifyBlock,
    Document,
    FunctionBlock,
    FuzzifyBlock,
    Is,
    Point,
    PointsMF,
    Range,
    Rule,
    RuleBlock,
    ShapeMF,
    SingletonMF,
    Term,
    Variable,
    VarKind,
)
from fuzzyctl.tune import gradient
from fuzzyctl.tune.data import Columns, read_table, require, rows, split

Arr = npt.NDArray[np.float64]
METHODS = ("grid", "cluster")
KINDS = ("tsk", "mamdani")
SHAPES = ("triangle", "gauss")
_NAMES = {
    2: ("low", "high"),
    3: ("low", "medium", "high"),
    4: ("lowest", "low", "high", "highest"),
    5: ("lowest", "low", "medium", "high", "highest"),
    7: ("lowest", "lower", "low", "medium", "high", "higher", "highest"),
}
# (at most 7 characters: the Siemens configuration tool takes 7, its manual 6.4)
_OUT_NAMES = {
    3: ("negative", "zero", "positive"),
    5: ("nb", "ns", "ze", "ps", "pb"),
    7: ("nb", "nm", "ns", "ze", "ps", "pm", "pb"),
}


@dataclass
class LearnResult:
    """A learned system and its errors on the training and validation rows."""

    document: Document
    method: str
    kind: str
    rules: int
    scores: dict[str, float]
    notes: list[str] = field(default_factory=list)

    @property
    def block(self) -> FunctionBlock:
        return self.document.main

    def write_fcl(self, path: str | Path) -> Path:
        from fuzzyctl.formats.fcl.type2 import write  # (type-1 models: fuzzyctl.fcl's text)

        path = Path(path)
        path.write_text(write(self.document), encoding="utf-8")
        return path

    def to_dict(self, file: str | Path | None = None) -> dict[str, Any]:
        """What ``fuzzyctl learn --json`` prints: the file written, the rule count and the
        errors on the training and validation rows."""
        return {"file": None if file is None else str(file), "rules": self.rules, **self.scores}


def default_terms(method: str, inputs: int) -> int:
    """Grid: 5 terms per input for one or two inputs, 3 for three or four, then 2 (the
    number of rules grows as terms ** inputs).  Clustering: 10 clusters."""
    if method == "cluster":
        return 10
    return 5 if inputs <= 2 else 3 if inputs <= 4 else 2


def _sig(v: float, digits: int = 8) -> float:
    return float(f"{v:.{digits}g}")


def readable_range(lo: float, hi: float) -> tuple[float, float]:
    """``lo..hi`` rounded outward to two significant digits of its span: the data's
    0.00438..9.99467 becomes 0..10, -2.96505..2.99416 becomes -3..3 (what a person would write,
    and what the grid's points then follow)."""
    if not hi > lo:
        return lo, hi
    e = math.floor(math.log10(hi - lo)) - 1
    step = 10.0**e
    digits = max(0, -e)
    tol = 1e-9  # a bound on the division's rounding: 0.7 / 0.1 is 6.999999999999999
    low = float(f"{math.floor(lo / step + tol) * step:.{digits}f}")
    high = float(f"{math.ceil(hi / step - tol) * step:.{digits}f}")
    return min(low, lo), max(high, hi)


def _names(n: int, prefix: str = "t") -> tuple[str, ...]:
    return _NAMES.get(n, tuple(f"{prefix}{k + 1}" for k in range(n)))


def learn(
    data: str | Path | Mapping[str, Any] | Any,
    *,
    inputs: Sequence[str],
    output: str,
    method: str = "grid",
    kind: str = "tsk",
    terms: int | None = None,
    out_terms: int = 7,
    and_op: str = "PROD",
    validation: float = 0.2,
    validation_data: str | Path | Mapping[str, Any] | Any | None = None,
    seed: int = 0,
    name: str | None = None,
    shape: str = "triangle",
    type2: bool = False,
    budget: int = 100,
) -> LearnResult:
    """Learn a fuzzy system mapping ``inputs`` to ``output`` from a table (CSV/Parquet path,
    mapping of columns or DataFrame); see the module docstring for the methods.
    ``type2``: the learned system is then widened into an interval type-2 one (every
    fuzzy-set term gets a lower function, scale 1 and lag 0, equal to the upper one) and
    the lower functions' scale and lag are tuned on the training rows (``budget``
    evaluations), kept only when they lower the training error."""
    if method not in METHODS:
        raise InputError(f"--method must be one of {', '.join(METHODS)}, got {method!r}")
    if kind not in KINDS:
        raise InputError(f"--type must be one of {', '.join(KINDS)}, got {kind!r}")
    if shape not in SHAPES:
        raise InputError(f"--shape must be one of {', '.join(SHAPES)}, got {shape!r}")
    if type2 and kind != "tsk":
        raise InputError(
            "--type2 needs --type tsk: the Mamdani systems learned here have singleton outputs "
            "(COGS), which interval type-2 inference does not define"
        )
    and_op = and_op.upper()
    if not norms.keeps_lines(and_op):
        raise InputError(f"--and must be MIN or PROD, got {and_op!r}")
    inputs = list(dict.fromkeys(inputs))
    if not inputs:
        raise InputError("--inputs names no column")
    if output in inputs:
        raise InputError(f"{output!r} is both an input and the output")
    cols = read_table(data)
    require(cols, [*inputs, output], str(data) if isinstance(data, str | Path) else "data")
    parts_val: Columns | None
    if validation_data is not None:
        parts_val = read_table(validation_data, what="validation data")
        require(parts_val, [*inputs, output], str(validation_data))
        parts_train = cols
    else:
        s = split(cols, validation, seed)
        parts_train, parts_val = s.train, s.validation
    n_terms = terms if terms is not None else default_terms(method, len(inputs))
    if n_terms < (1 if method == "cluster" else 2):
        raise InputError(f"--terms must be at least {1 if method == 'cluster' else 2}, got {n_terms}")
    if method == "grid" and n_terms ** len(inputs) > 5000:
        raise InputError(
            f"a grid of {n_terms} terms on {len(inputs)} inputs has {n_terms ** len(inputs)} rules; "
            "use fewer --terms or --method cluster"
        )
    n = rows(parts_train)
    for i in inputs:
        lo, hi = float(np.min(parts_train[i])), float(np.max(parts_train[i]))
        if not hi > lo:
            raise InputError(f"input {i!r} is constant in the training data ({lo}): it cannot be partitioned")
    if method == "cluster" and n < n_terms:
        raise InputError(f"{n} training rows are too few for {n_terms} clusters")

    fuzz, antecedents = (
        _grid(parts_train, inputs, n_terms, shape)
        if method == "grid"
        else _clusters(parts_train, inputs, output, n_terms, seed)
    )
    y = parts_train[output]
    y_lo, y_hi = float(np.min(y)), float(np.max(y))
    pad = 0.1 * (y_hi - y_lo) or 1.0
    out_range = Range(*readable_range(y_lo - pad, y_hi + pad))
    block_name = name or "learned"
    variables = (*(Variable(i, VarKind.INPUT) for i in inputs), Variable(output, VarKind.OUTPUT))
    # Per-rule consequents first (Takagi-Sugeno, or zero-order for the Mamdani grouping).
    order = 1 if kind == "tsk" else 0
    fb = _assemble(block_name, variables, fuzz, antecedents, output, out_range, and_op, order, None)
    theta = _fit_rules(fb, parts_train, inputs, output)
    notes: list[str] = []
    if kind == "tsk":
        fb = _set_linear(fb, output, theta, len(inputs))
    else:
        fb, note = _mamdani(
            fb,
            parts_train,
            inputs,
            output,
            theta,
            out_terms,
            out_range,
            antecedents,
            fuzz,
            variables,
            and_op,
            seed,
        )
        notes.append(note)
        if not norms.is_min(and_op.upper()):
            notes.append("the Siemens FUZZY block takes AND MIN: learn with --and min (and_op='min') for it")
    fb = _with_comment(fb, method, kind, inputs, output, n, and_op)
    if type2:
        fb, note = _widened(fb, parts_train, output, seed, budget)
        notes.append(note)
    doc = Document((fb,))
    scores = _scores(doc, parts_train, parts_val, inputs, output)
    return LearnResult(doc, method, kind, len(antecedents), scores, notes)


# --------------------------------------------------------------------------- antecedents


def _grid(
    cols: Columns, inputs: Sequence[str], n: int, shape: str = "triangle"
) -> tuple[list[FuzzifyBlock], list[tuple[str, ...]]]:
    fuzz = []
    names_per_input = []
    for i in inputs:
        lo, hi = readable_range(float(np.min(cols[i])), float(np.max(cols[i])))
        centres = [_sig(lo + (hi - lo) * k / (n - 1), 8) for k in range(n)]
        centres[0], centres[-1] = lo, hi
        names = _names(n)
        ts = []
        # Gaussians cross their neighbours at 0.5, as the triangles do (MATLAB genfis's
        # default shape; not for the PLC blocks, which take points only).
        sigma = _sig((centres[1] - centres[0]) / (2.0 * math.sqrt(2.0 * math.log(2.0))))
        for k, c in enumerate(centres):
            if shape == "gauss":
                ts.append(Term(names[k], ShapeMF("gaussian", (c, sigma))))
                continue
            pts: list[tuple[float, float]] = []
            if k > 0:
                pts.append((centres[k - 1], 0.0))
            pts.append((c, 1.0))
            if k < n - 1:
                pts.append((centres[k + 1], 0.0))
            ts.append(Term(names[k], PointsMF(tuple(Point(x, y) for x, y in pts))))
        fuzz.append(FuzzifyBlock(i, tuple(ts), Range(lo, hi)))
        names_per_input.append(names)
    return fuzz, list(itertools.product(*names_per_input))


def _clusters(
    cols: Columns, inputs: Sequence[str], output: str, k: int, seed: int
) -> tuple[list[FuzzifyBlock], list[tuple[str, ...]]]:
    from scipy.cluster.vq import kmeans2

    names = [*inputs, output]
    X = np.column_stack([cols[c] for c in names])
    mean, std = X.mean(axis=0), X.std(axis=0)
    std[std == 0] = 1.0
    Z = (X - mean) / std
    # k-means++ from five seeds, the partition with the least within-cluster sum of squares
    best: tuple[float, Arr, npt.NDArray[np.int_]] | None = None
    for attempt in range(5):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # "One of the clusters is empty": handled below
            c, lab = kmeans2(Z, k, minit="++", seed=seed * 7919 + attempt)
        sse = float(np.sum((Z - c[lab]) ** 2))
        if best is None or sse < best[0]:
            best = (sse, c, lab)
    assert best is not None
    centres = best[1] * std + mean
    labels = best[2]
    order = np.lexsort(centres[:, ::-1].T)  # by the first input, then the next ...
    fuzz = []
    for d, i in enumerate(inputs):
        lo, hi = readable_range(float(np.min(cols[i])), float(np.max(cols[i])))
        floor = (hi - lo) / (2.0 * k)
        ts = []
        for rank, ci in enumerate(order):
            members = X[labels == ci, d]
            sigma = max(float(np.std(members)) if len(members) > 1 else 0.0, floor)
            mean_c = min(max(float(centres[ci, d]), lo), hi)
            ts.append(Term(f"c{rank + 1}", ShapeMF("gaussian", (_sig(mean_c), _sig(sigma)))))
        fuzz.append(FuzzifyBlock(i, tuple(ts), Range(lo, hi)))
    return fuzz, [tuple(f"c{r + 1}" for _ in inputs) for r in range(k)]


# --------------------------------------------------------------------------- consequents


def _assemble(
    name: str,
    variables: tuple[Variable, ...],
    fuzz: Sequence[FuzzifyBlock],
    antecedents: Sequence[tuple[str, ...]],
    output: str,
    out_range: Range,
    and_op: str,
    order: int,
    conclusions: Sequence[str] | None,
    out_terms: Sequence[Term] | None = None,
    accu: str = "MAX",
) -> FunctionBlock:
    inputs = [v.name for v in variables if v.kind is VarKind.INPUT]
    rules = []
    for r, ante in enumerate(antecedents):
        conds = [Is(i, t) for i, t in zip(inputs, ante, strict=True)]
        cond = conds[0] if len(conds) == 1 else And(tuple(conds))
        target = conclusions[r] if conclusions is not None else f"r{r + 1}"
        rules.append(Rule(str(r + 1), cond, (Conclusion(output, target),)))
    if out_terms is None:
        mf = (lambda: ShapeMF("linear", (0.0,) * (len(inputs) + 1))) if order else (lambda: SingletonMF(0.0))
        out_terms = [Term(f"r{r + 1}", mf()) for r in range(len(antecedents))]
    method = "WTAVER" if order else "COGS"
    # Shared singletons (Mamdani) keep the last value when no rule fires, as the PLC blocks do
    # (a grid partition always fires a rule; the DEFAULT would never be used)
    default = Default(no_change=True) if conclusions is not None else Default(0.0)
    defz = DefuzzifyBlock(output, tuple(out_terms), out_range, method, default)
    rb = RuleBlock("rules", tuple(rules), and_op=and_op, accu=accu)
    return FunctionBlock(name, variables, tuple(fuzz), (defz,), (rb,))


def _design(fb: FunctionBlock, cols: Columns, inputs: Sequence[str], output: str) -> tuple[Arr, list[int]]:
    """Columns d y / d (consequent parameter) at the training rows: the output is linear in
    the consequents, so these are exactly the regressors of the least-squares problem."""
    plan, _ = lower(fb, COMPAT_PROFILES["iec"])
    assert plan is not None and gradient.unsupported(plan, [output]) is None
    oi = next(k for k, o in enumerate(plan.outputs) if o.name == output)
    vals = [cols[i] for i in inputs]
    _y, g = gradient.forward(plan, vals, [output])[output]
    n = rows(cols)
    terms = plan.outputs[oi].terms
    npar = len(terms[0].params)
    cols_out = []
    for t in range(len(terms)):
        for p in range(npar):
            cols_out.append(g.get(("out", oi, t, p), np.zeros(n)))
    return np.column_stack(cols_out), [npar]


def _fit_rules(fb: FunctionBlock, cols: Columns, inputs: Sequence[str], output: str) -> Arr:
    phi, _ = _design(fb, cols, inputs, output)
    return ridge(phi, cols[output])


RIDGE = 1e-10


def ridge(phi: Arr, y: Arr) -> Arr:
    """Least squares with a small ridge, ``min |phi theta - y|^2 + lam |theta|^2`` with
    ``lam = RIDGE * mean(diag(phi' phi))``: on a grid partition the columns of a first-order
    system are linearly dependent (the terms interpolate any linear function exactly), and
    rules with few samples make the problem ill-conditioned; the ridge picks the small
    solution, as the ANFIS recursive estimator does with its initial covariance."""
    p = phi.shape[1]
    lam = RIDGE * float(np.mean(np.sum(phi * phi, axis=0))) or RIDGE
    a = np.vstack([phi, math.sqrt(lam) * np.eye(p)])
    b = np.concatenate([y, np.zeros(p)])
    theta, *_ = np.linalg.lstsq(a, b, rcond=None)
    return np.asarray(theta, dtype=np.float64)


def _set_linear(fb: FunctionBlock, output: str, theta: Arr, m: int) -> FunctionBlock:
    import dataclasses

    d = fb.defuzzify[0]
    terms = tuple(
        Term(t.name, ShapeMF("linear", tuple(_sig(float(v)) for v in theta[k * (m + 1) : (k + 1) * (m + 1)])))
        for k, t in enumerate(d.terms)
    )
    return dataclasses.replace(fb, defuzzify=(dataclasses.replace(d, terms=terms),))


def _mamdani(
    fb: FunctionBlock,
    cols: Columns,
    inputs: Sequence[str],
    output: str,
    theta: Arr,
    out_terms: int,
    out_range: Range,
    antecedents: Sequence[tuple[str, ...]],
    fuzz: Sequence[FuzzifyBlock],
    variables: tuple[Variable, ...],
    and_op: str,
    seed: int,
) -> tuple[FunctionBlock, str]:
    from scipy.optimize import lsq_linear

    plc = norms.is_min(and_op.upper())  # what the Siemens FUZZY block takes
    z = np.clip(theta, out_range.low, out_range.high)
    k = max(1, min(out_terms, len(np.unique(np.round(z, 12)))))
    if k < len(z):
        from scipy.cluster.vq import kmeans2

        centres, labels = kmeans2(z.reshape(-1, 1), k, seed=seed, minit="++")
        centres = centres.reshape(-1)
        rank = np.argsort(np.argsort(centres))
        assign = [int(rank[c]) for c in labels]
        start = np.sort(centres)
    else:
        idx = np.argsort(z)
        assign = [int(v) for v in np.argsort(idx)]
        start = z[idx]
    names = _OUT_NAMES.get(k, tuple(f"o{j + 1}" for j in range(k)))
    terms = [Term(names[j], SingletonMF(_sig(float(start[j])))) for j in range(k)]
    # Both passes build the same rules on the same inputs; only the conclusions differ.
    assemble = partial(
        _assemble, fb.name or "learned", variables, fuzz, antecedents, output, out_range, and_op, 0
    )
    fb2 = assemble(
        [names[a] for a in assign],
        terms,
        "SUM" if plc else "MAX",  # the sum the PLC blocks compute, as the gradient takes it
    )
    phi, _ = _design(fb2, cols, inputs, output)
    used = phi.any(axis=0)
    pos = np.array(start, dtype=np.float64)
    if used.any():
        sol = lsq_linear(phi[:, used], cols[output], bounds=(out_range.low, out_range.high))
        pos[used] = sol.x
    # Keep the linguistic order: the names follow the values.
    order = np.argsort(pos, kind="stable")
    rename = {names[int(j)]: names[r] for r, j in enumerate(order)}
    terms = [Term(names[r], SingletonMF(_sig(float(pos[int(j)])))) for r, j in enumerate(order)]
    fb3 = assemble(
        [rename[names[a]] for a in assign],
        terms,
        # ACCU NSUM: the IEC sum the Siemens block computes; under CoGS its normalisation
        # cancels, so the file computes exactly the SUM fitted above.  (With AND PROD, which
        # the block does not take, MAX fits examples/surface.csv better: validation RMSE 0.055 vs 0.077.)
        "NSUM" if plc else "MAX",
    )
    return fb3, f"{len(antecedents)} rules share {k} output singletons"


def _with_comment(
    fb: FunctionBlock, method: str, kind: str, inputs: Sequence[str], output: str, n: int, and_op: str
) -> FunctionBlock:
    import dataclasses

    what = "first-order Takagi-Sugeno" if kind == "tsk" else "Mamdani with singleton outputs (CoGS)"
    how = "grid partition" if method == "grid" else "k-means clustering"
    text = (
        f"Learned by fuzzyctl learn from {n} rows: {what}, {how} of {', '.join(inputs)} -> {output}, "
        f"AND {and_op}, consequents by least squares."
    )
    return dataclasses.replace(fb, comments=(text,))


def _widened(
    fb: FunctionBlock, train: Columns, output: str, seed: int, budget: int
) -> tuple[FunctionBlock, str]:
    from fuzzyctl.tune.api import tune

    result = tune(
        fb, data=train, output=output, widen=True, validation=0.0, seed=seed, budget=budget, workers=0
    )
    return (
        result.block,
        f"interval type-2: training RMSE {result.before:.6g} -> {result.after:.6g} (lower scale/lag)",
    )


def _scores(
    doc: Document, train: Columns, val: Columns | None, inputs: Sequence[str], output: str
) -> dict[str, float]:
    import fuzzyctl
    from fuzzyctl.fcl import load_text
    from fuzzyctl.formats.fcl.type2 import write  # (type-1 models: fuzzyctl.fcl's text)

    # Evaluate what is written: the file read back, through the public compile().
    written = load_text(write(doc)).raise_for_errors()
    # (validation rows may lie outside the training rows' ranges: no warning)
    ctl = fuzzyctl.compile(written, backend="python", out_of_range="ignore")
    out: dict[str, float] = {}
    for label, cols in (("training", train), ("validation", val)):
        if cols is None:
            continue
        ctl.reset()
        pred = ctl.evaluate_batch({i: cols[i] for i in inputs})[output]
        r = pred - cols[output]
        out[f"{label} RMSE"] = float(math.sqrt(float(np.mean(r * r))))
        out[f"{label} MAE"] = float(np.mean(np.abs(r)))
        out[f"{label} max error"] = float(np.max(np.abs(r)))
        out[f"{label} rows"] = float(len(r))
    return out
