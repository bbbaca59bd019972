"""The compiled controller: input checking, scalar and batch evaluation, explanations, and
the state an instance keeps between evaluations (DEFAULT := NC)."""

from __future__ import annotations

import contextlib
import difflib
import math
import numbers
import warnings
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

from fuzzyctl.diagnostics import Diagnostic, InputError
from fuzzyctl.engine.plan import Plan
from fuzzyctl.engine.ranges import check_columns, check_mode, check_values, declared_ranges
from fuzzyctl.engine.variables import VariableMap, inputs_of, outputs_of

if TYPE_CHECKING:  # numpy, the interpreter and explanations are imported when first used
    import numpy as np
    import numpy.typing as npt

    from fuzzyctl.engine import explain as explain_mod
    from fuzzyctl.engine.reference.interp import Interpreter
    from fuzzyctl.model import FunctionBlock

_INF = math.inf


class Controller:
    """Evaluates one function block.  Create it with :func:`fuzzyctl.compile`.

    An instance keeps the previous value of each output for ``DEFAULT := NC`` (and for outputs
    without DEFAULT): :meth:`reset` forgets them.  Batch rows are successive evaluations of
    the same instance, in order, as a PLC cycle would see them."""

    def __init__(self, plan: Plan, *, specialise: bool = True, model: FunctionBlock | None = None) -> None:
        self.plan = plan
        self.name = plan.name
        #: the function block compiled (None when built from a plan alone)
        self.model = model
        #: name -> range and terms of each input / output, in declaration order
        self.inputs: VariableMap = inputs_of(plan, model)
        self.outputs: VariableMap = outputs_of(plan, model)
        self._state: list[float | None] = [None] * len(plan.outputs)
        self._required = tuple(i.name for i in plan.inputs if i.default is None)
        self._degree = tuple(i.degree for i in plan.inputs)
        #: name -> (low, high) of each input that declares a RANGE (engine/ranges.py)
        self.input_ranges: dict[str, tuple[float, float]] = declared_ranges(self.inputs)
        #: what an input outside its RANGE does when a call does not say: "warn" (the
        #: result as computed, and an InputRangeWarning), "clamp", "raise" or "ignore"
        self.out_of_range = "warn"
        #: what compiling decided with a warning (a universe taken from the terms, a term
        #: defined twice, ...): :class:`~fuzzyctl.diagnostics.Diagnostic` objects
        self.warnings: tuple[Diagnostic, ...] = ()
        self._jfl: Any = None
        if plan.options.emulate == "jfuzzylogic":
            # another tool's arithmetic (1000-point sets, ...): one evaluator serves every path
            from fuzzyctl.engine.compat.jfl import JflEvaluator

            self._jfl = JflEvaluator(plan)
            specialise = False
        self._specialise = specialise
        self._interp_obj: Interpreter | None = None
        # the generated evaluators, made on first use (None: not yet; False: the plan uses
        # something the generator does not implement, the interpreter evaluates it)
        self._fast_fn: Callable[[list[float], list[float | None]], list[float]] | bool | None = None
        self._batch_fn: Any = None

    @property
    def _interp(self) -> Interpreter:
        if self._interp_obj is None:
            from fuzzyctl.engine.reference.interp import Interpreter

            self._interp_obj = Interpreter(self.plan)
        return self._interp_obj

    @property
    def _fast(self) -> Callable[[list[float], list[float | None]], list[float]] | None:
        """The generated scalar evaluator (:mod:`fuzzyctl.ir.render.pysrc`), or None."""
        if self._fast_fn is None:
            self._fast_fn = False
            if self._specialise:
                from fuzzyctl.ir.programs.scalar import build_scalar
                from fuzzyctl.ir.render.pysrc import specialise
                from fuzzyctl.ir.state import CodegenError

                with contextlib.suppress(CodegenError):  # the interpreter evaluates it
                    self._fast_fn = specialise(build_scalar(self.plan))
        return self._fast_fn if callable(self._fast_fn) else None

    @property
    def _batch(self) -> Any:
        """The generated numpy evaluator (:mod:`fuzzyctl.ir.render.npsrc`), or None."""
        if self._batch_fn is None:
            self._batch_fn = False
            if self._specialise:
                from fuzzyctl.ir.programs.evaluator import build_fast
                from fuzzyctl.ir.render.npsrc import vectorise
                from fuzzyctl.ir.state import CodegenError

                with contextlib.suppress(CodegenError):  # the interpreter evaluates it
                    self._batch_fn = vectorise(build_fast(self.plan, "np"))
        return self._batch_fn or None

    # ------------------------------------------------------------------ inputs

    def _values(self, inputs: Mapping[str, Any], out_of_range: str | None = None) -> list[float]:
        _check_names(inputs, self.inputs)
        values: list[float] = []
        for i, spec in enumerate(self.plan.inputs):
            if spec.name in inputs:
                raw = inputs[spec.name]
            elif spec.default is not None:
                raw = spec.default
            else:
                raise InputError(f"missing input {spec.name!r} (inputs: {', '.join(self.inputs)})")
            v = _number(spec.name, raw)
            if self._degree[i] and not 0.0 <= v <= 1.0:
                raise InputError(f"input {spec.name!r} is used as a degree and must be in [0, 1], got {v}")
            values.append(v)
        return self._in_range(values, out_of_range)

    def _in_range(self, values: list[float], mode: str | None) -> list[float]:
        """The input values after the RANGE check (engine/ranges.py): unchanged unless
        ``mode`` (default: :attr:`out_of_range`) is "clamp"."""
        mode = self.out_of_range if mode is None else check_mode(mode)
        return check_values(self.input_ranges, tuple(self.inputs), values, mode)

    # ------------------------------------------------------------------ evaluation

    def evaluate(
        self,
        inputs: Mapping[str, Any] | None = None,
        /,
        *,
        out_of_range: str | None = None,
        **values_by_name: Any,
    ) -> dict[str, float]:
        """Evaluate once: ``evaluate({"temp": 20.0, ...})`` or ``evaluate(temp=20.0, ...)`` ->
        ``{"valve": 35.7, ...}``.  Values are real numbers (numpy scalars and 0-d arrays too).
        ``out_of_range`` ("warn", "clamp", "raise", "ignore"; default :attr:`out_of_range`):
        what an input outside its declared RANGE does (docs/engine.md)."""
        values = self._values(merge_inputs(inputs, values_by_name), out_of_range)
        fast = self._fast
        res: list[float] | None = None
        if self._jfl is not None:
            res = [float(v[0]) for v in self._jfl.run([[v] for v in values], self._state, 1)]
        elif fast is not None:
            try:
                res = fast(values, self._state)
            except (ArithmeticError, ValueError):  # Python raises where C gives inf/NaN (1/0, log(0))
                # take the IEEE value
                res = None
        if res is None:
            rec = self._interp.run(values, self._state)
            res = [o.value for o in rec.outputs]
        plan = self.plan
        return {plan.outputs[i].name: res[i] for i in range(len(res)) if plan.outputs[i].is_output}

    def evaluate_reference(
        self, inputs: Mapping[str, Any] | None = None, /, **values_by_name: Any
    ) -> dict[str, float]:
        """Evaluate through the interpreter (the unspecialised path), for cross-checks."""
        if self._jfl is not None:  # that profile has one evaluator
            return self.evaluate(inputs, **values_by_name)
        values = self._values(merge_inputs(inputs, values_by_name))
        rec = self._interp.run(values, self._state)
        return {o.name: r.value for o, r in zip(self.plan.outputs, rec.outputs, strict=True) if o.is_output}

    def explain(
        self,
        inputs: Mapping[str, Any] | None = None,
        /,
        *,
        out_of_range: str | None = None,
        **values_by_name: Any,
    ) -> explain_mod.Explanation:
        """Evaluate once and return every intermediate result (this counts as an evaluation:
        the NC state advances); ``.plot()`` draws it.  ``out_of_range`` as in :meth:`evaluate`."""
        from fuzzyctl.engine import explain as explain_mod

        values = self._values(merge_inputs(inputs, values_by_name), out_of_range)
        rec = (
            self._jfl.record(values, self._state)
            if self._jfl is not None
            else self._interp.run(values, self._state)
        )
        named = dict(zip(self.inputs, values, strict=True))
        return explain_mod.build(self.plan, named, rec)

    def evaluate_batch(
        self,
        data: Any,
        *,
        chunk: int = 16384,
        on_invalid: str = "raise",
        out_of_range: str | None = None,
        rows: int | None = None,
    ) -> dict[str, npt.NDArray[np.float64]]:
        """Evaluate many samples: ``data`` maps input names to equal-length sequences (a dict of
        arrays, a pandas/polars DataFrame, ...).  Returns a dict of float64 arrays.

        ``on_invalid``: ``"raise"`` (default) refuses a NaN or infinite input with the row;
        ``"nan"`` gives NaN outputs for such rows, skips them (the NC state carries over them
        from the previous valid row) and warns with their count (:class:`InvalidRowsWarning`).
        ``out_of_range`` as in :meth:`evaluate`; "warn" warns once, with a count per input.

        ``rows``: the number of rows when no column gives it (a model without inputs, or every
        input left to its default): by default a DataFrame's length, else one row (what
        :meth:`evaluate` gives); with columns it must equal their length."""
        import numpy as np

        if on_invalid not in ("raise", "nan"):
            raise ValueError(f"on_invalid must be 'raise' or 'nan', not {on_invalid!r}")
        columns = _columns(data)
        _check_names(columns, self.inputs)
        n = None
        arrays: list[npt.NDArray[np.float64] | None] = []
        for i, spec in enumerate(self.plan.inputs):
            if spec.name in columns:
                arr = _column_array(spec.name, columns[spec.name], finite=on_invalid == "raise")
            elif spec.default is not None:
                arr = None
            else:
                raise InputError(f"missing input {spec.name!r} (inputs: {', '.join(self.inputs)})")
            if arr is not None:
                if n is None:
                    n = len(arr)
                elif len(arr) != n:
                    raise InputError(f"input {spec.name!r} has {len(arr)} values, expected {n}")
                if self._degree[i]:
                    bad = np.flatnonzero((arr < 0.0) | (arr > 1.0))  # NaN compares False: kept
                    if bad.size:
                        raise InputError(
                            f"input {spec.name!r} is used as a degree and must be in [0, 1] "
                            f"(row {int(bad[0])}: {arr[bad[0]]})"
                        )
            arrays.append(arr)
        mode = self.out_of_range if out_of_range is None else check_mode(out_of_range)
        arrays = check_columns(self.input_ranges, tuple(self.inputs), arrays, mode)
        n = _row_count(data, n, rows)
        full = [
            a if a is not None else np.full(n, float(self.plan.inputs[i].default or 0.0))
            for i, a in enumerate(arrays)
        ]
        if on_invalid == "nan":
            valid = np.logical_and.reduce([np.isfinite(a) for a in full]) if full else np.ones(n, bool)
            n_bad = int(n - np.count_nonzero(valid))
            if n_bad:
                warnings.warn(InvalidRowsWarning(n_bad, n), stacklevel=2)
                kept = self._run_batch([a[valid] for a in full], n - n_bad, chunk)
                out = {k: np.full(n, np.nan) for k in kept}
                for k, v in kept.items():
                    out[k][valid] = v
                return out
        return self._run_batch(full, n, chunk)

    def _run_batch(
        self, full: list[npt.NDArray[np.float64]], n: int, chunk: int
    ) -> dict[str, npt.NDArray[np.float64]]:
        """The declared outputs for ``n`` rows of validated input columns."""
        import numpy as np

        result = {o.name: np.empty(n) for o in self.plan.outputs}
        for start in range(0, n, chunk):
            part = [a[start : start + chunk] for a in full]
            out = self._batch_chunk(part, min(chunk, n - start))
            for o, arr in zip(self.plan.outputs, out, strict=True):
                result[o.name][start : start + chunk] = arr
        return {k: v for k, v in result.items() if k in self.outputs}

    def _batch_chunk(self, part: list[npt.NDArray[np.float64]], m: int) -> list[npt.NDArray[np.float64]]:
        """``m`` rows (the count is given: a model without inputs has no column to tell it)."""
        import numpy as np

        if self._jfl is not None:
            got: list[npt.NDArray[np.float64]] = self._jfl.run(part, self._state, m)
            return got
        batch = self._batch
        if batch is not None:
            outs: list[npt.NDArray[np.float64]] = batch(part, self._state, m)
            return outs
        res = [np.empty(m) for _ in self.plan.outputs]
        for r in range(m):
            rec = self._interp.run([float(a[r]) for a in part], self._state)
            for k, o in enumerate(rec.outputs):
                res[k][r] = o.value
        return res

    def reset(self) -> None:
        """Forget the previous outputs (as after a cold restart): NC outputs start at 0."""
        self._state = [None] * len(self.plan.outputs)

    def __repr__(self) -> str:
        return f"Controller({self.name!r}, inputs={list(self.inputs)}, outputs={list(self.outputs)})"


class InvalidRowsWarning(UserWarning):
    """Rows of a batch with a NaN or infinite input got NaN outputs (``on_invalid="nan"``)."""

    def __init__(self, rows: int, total: int) -> None:
        super().__init__(f"{rows} of {total} rows have a NaN or infinite input: their outputs are NaN")
        self.rows = rows
        self.total = total


def merge_inputs(inputs: Mapping[str, Any] | None, by_name: dict[str, Any]) -> Mapping[str, Any]:
    if inputs is None:
        return by_name
    if not isinstance(inputs, Mapping):
        raise InputError(f"inputs must be a mapping of names to values, not {type(inputs).__name__}")
    if by_name:
        both = sorted(set(inputs) & set(by_name))
        if both:
            raise InputError(f"input {both[0]!r} given twice (in the mapping and as a keyword)")
        return {**inputs, **by_name}
    return inputs


def _check_names(given: Mapping[str, Any], known: Mapping[str, Any]) -> None:
    """Unknown names first: a misspelt input would otherwise be reported as a missing one."""
    for name in given:
        if name not in known:
            close = difflib.get_close_matches(str(name), list(known), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else f" (inputs: {', '.join(known)})"
            raise InputError(f"unknown input {name!r}{hint}")


def _number(name: str, raw: Any) -> float:
    if type(raw).__module__ == "numpy" and getattr(raw, "ndim", None) == 0:  # numpy without importing it
        raw = raw.item()
    if isinstance(raw, float):
        v = raw
    elif isinstance(raw, numbers.Real):
        v = float(raw)
    else:
        raise InputError(f"input {name!r} must be a number, got {type(raw).__name__} {raw!r}")
    if not -_INF < v < _INF:
        raise InputError(f"input {name!r} must be a finite number, got {v}")
    return v


def _row_count(data: Any, n: int | None, rows: int | None) -> int:
    """The batch's rows: the columns' length, else ``rows``, else a DataFrame's length, else 1
    (a batch of a model without inputs is one evaluation per row, like ``evaluate({})``)."""
    if rows is not None and (isinstance(rows, bool) or not isinstance(rows, int) or rows < 0):
        raise InputError(f"rows must be a non-negative integer, not {rows!r}")
    if n is not None:
        if rows is not None and rows != n:
            raise InputError(f"rows={rows} but the input columns have {n} values")
        return n
    if rows is not None:
        return rows
    shape = getattr(data, "shape", None)
    if not isinstance(data, Mapping) and isinstance(shape, tuple) and shape:
        return int(shape[0])
    return 1


def _columns(data: Any) -> dict[str, Any]:
    if isinstance(data, Mapping):
        return {str(k): v for k, v in data.items()}
    cols = getattr(data, "columns", None)
    if cols is not None:
        return {str(c): data[c] for c in cols}
    raise InputError("batch data must map input names to columns (a dict of arrays or a DataFrame)")


def _check_rows(name: str, raw: Any) -> None:
    """Raise the :func:`_number` error of the first row that is not a number, naming it."""
    for i, v in enumerate(list(raw)):
        try:
            _number(name, v)
        except InputError as exc:
            raise InputError(f"{exc} (row {i})") from None


def _column_array(name: str, col: Any, finite: bool = True) -> npt.NDArray[np.float64]:
    import numpy as np

    raw = col.to_numpy() if hasattr(col, "to_numpy") else col
    try:
        arr = np.asarray(raw, dtype=np.float64)
    except (TypeError, ValueError):
        _check_rows(name, raw)
        raise InputError(f"input {name!r} is not numeric") from None
    if arr.ndim != 1:
        arr = arr.reshape(-1)
    if np.asarray(raw).dtype.kind in "USO":  # strings that happen to parse are still strings
        _check_rows(name, raw)
    # min and max are NaN or infinite when an element is: no temporary array
    if finite and arr.size and not (np.isfinite(arr.min()) and np.isfinite(arr.max())):
        bad = np.flatnonzero(~np.isfinite(arr))
        raise InputError(f"input {name!r} must be finite (row {int(bad[0])}: {arr[bad[0]]})")
    return arr
