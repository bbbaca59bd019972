"""What the studio computes about a knowledge base: the diagnostics of ``fuzzyctl check``
tied to the element they concern, the conformance level, display ranges, and the engine's
evaluations for the 3D display, the curve recorder and explanations.

The browser edits the model in fuzzyctl's JSON form (docs/formats.md); every request
carries it, so the server keeps no editing state.  Compiled controllers are cached by
the model's content.
"""

from __future__ import annotations

import hashlib
import json
import math
import threading
from collections import OrderedDict
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import numpy.typing as npt

from fuzzyctl.diagnostics import Diagnostic, DiagnosticError, FuzzyctlError, has_errors
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.model import (
    DefuzzifyBlock,
    Document,
    FunctionBlock,
    FuzzifyBlock,
    Param,
    PointsMF,
    Ref,
    ShapeMF,
    SingletonMF,
    SingletonsMF,
    Span,
    Term,
)
from fuzzyctl.studio import type2view

FloatArray = npt.NDArray[np.float64]

# ---------------------------------------------------------------------------- model I/O


def document_from_json(data: dict[str, Any], *, validated: bool = True) -> Document:
    """The model from its JSON form; a malformed one is a :class:`FuzzyctlError` naming
    the JSON path, an invalid one (points out of order, a degree above 1) a
    :class:`DiagnosticError` with the JSON paths.  ``validated=False`` leaves the validation
    to the caller: ``/api/check``, whose answer for an invalid model is its report."""
    from fuzzyctl.formats.json.reader import from_dict
    from fuzzyctl.validation import at_json_paths, validate

    try:
        document = from_dict(data)
    except DiagnosticError:
        raise
    except (ValueError, TypeError, KeyError) as exc:
        raise FuzzyctlError(f"invalid model: {exc}") from None
    if not validated:
        return document
    # the rules every reader applies (issue 25): what the studio evaluates and saves, check accepts
    refused = [d for d in at_json_paths(validate(document)) if d.is_error]
    if refused:
        raise DiagnosticError(refused)
    return document


def document_to_json(document: Document) -> dict[str, Any]:
    from fuzzyctl.formats.json.writer import to_dict

    return to_dict(document)


def fcl_text(document: Document) -> str:
    # (the FCL form with interval type-2 terms; a type-1 model is written as fuzzyctl.fcl does)
    from fuzzyctl.formats.fcl.type2 import write

    return write(document)


def fcl_losses(document: Document) -> list[str]:
    """What the model holds that FCL cannot write (a FIS rule weight, fuzzylite's
    lock-range, ...): saving as FCL would drop it, so the studio says so first."""
    from fuzzyctl import formats

    return [str(loss) for loss in formats.get("fcl").losses(document)]


def content_key(document: Document) -> str:
    """A hash of what the model means (source positions and comments left out)."""
    return hashlib.sha256(repr(document.blocks).encode("utf-8")).hexdigest()


# ---------------------------------------------------------------------------- checking


@dataclass
class Report:
    """``fuzzyctl check`` for one text: diagnostics (each with the element it concerns),
    the conformance level and its features, and the parsed document when it has no errors."""

    ok: bool
    diagnostics: list[dict[str, Any]]
    level: str | None
    features: list[dict[str, str]]
    document: Document | None
    parsed: Document | None = None
    """The document as parsed, also when the checks found errors (None after a syntax
    error): the rule and term editors read their lines from it."""

    def to_dict(self) -> dict[str, Any]:
        return {
            "ok": self.ok,
            "diagnostics": self.diagnostics,
            "level": self.level,
            "features": self.features,
        }


def check_text(text: str, path: str | None = None) -> Report:
    """Everything ``fuzzyctl check`` says about ``text``: the language checks, then (when
    they pass) what the engine refuses or decides, as ``cli/lang.py`` does."""
    from fuzzyctl.engine.support import unsupported
    from fuzzyctl.fcl import conformance, load_text

    try:
        result = load_text(text, path)
    except DiagnosticError as exc:
        return Report(False, [_diag(d, None) for d in exc.diagnostics], None, [], None, None)
    diagnostics: list[Diagnostic] = list(result.diagnostics)
    document = result.document
    if document is not None and not has_errors(diagnostics):
        seen = {(d.code, d.span.line if d.span else None) for d in diagnostics}
        for fb in document.blocks:
            for d in [*unsupported(fb), *type2view.lower_diagnostics(fb)]:
                if (d.code, d.span.line if d.span else None) not in seen:
                    diagnostics.append(replace(d, file=d.file or path))
    ok = document is not None and not has_errors(diagnostics)
    elements = _elements(document) if document is not None else []
    level = None
    features: list[dict[str, str]] = []
    if ok and document is not None:
        feats = conformance.features(document, result.spellings)
        level = str(conformance.level(feats))
        features = [
            {"level": str(f.level), "table": f.table, "element": f.element, "detail": f.detail} for f in feats
        ]
    return Report(
        ok,
        [_diag(d, _element_of(d.span, elements)) for d in diagnostics],
        level,
        features,
        document if ok else None,
        document,
    )


def _diag(d: Diagnostic, element: str | None) -> dict[str, Any]:
    out = d.to_dict()
    out["end_line"] = d.span.end_line if d.span else None
    out["end_column"] = d.span.end_column if d.span else None
    out["element"] = element
    return out


Position = tuple[int, int]


def _extent(span: Span | None) -> tuple[Position, Position] | None:
    if span is None:
        return None
    end_line = span.end_line or span.line
    end_column = span.end_column if span.end_line else 10**9  # no end: the rest of the line
    return (span.line, span.column), (end_line, end_column or 10**9)


def _elements(document: Document) -> list[tuple[str, Position, Position]]:
    """Every element with a source position, as ``(id, start, end)`` (line, column).

    Ids: ``var:<name>`` (declaration, FUZZIFY / DEFUZZIFY block), ``term:<var>:<term>``,
    ``ruleblock:<i>``, ``rule:<i>:<j>`` (block index, rule index), ``block`` (the rest of
    the function block).  Only the first function block is mapped (the one edited)."""
    fb = document.main
    out: list[tuple[str, Position, Position]] = []

    def add(element: str, span: Span | None) -> None:
        extent = _extent(span)
        if extent is not None:
            out.append((element, *extent))

    add("block", fb.span)
    for v in fb.variables:
        add(f"var:{v.name}", v.span)
    term_blocks: list[FuzzifyBlock | DefuzzifyBlock] = [*fb.fuzzify, *fb.defuzzify]
    for blk in term_blocks:
        add(f"var:{blk.variable}", blk.span)
        for t in blk.terms:
            add(f"term:{blk.variable}:{t.name}", t.span)
    for i, rb in enumerate(fb.rule_blocks):
        add(f"ruleblock:{i}", rb.span)
        for j, rule in enumerate(rb.rules):
            add(f"rule:{i}:{j}", rule.span)
    return out


def _element_of(span: Span | None, elements: list[tuple[str, Position, Position]]) -> str | None:
    """The innermost element that contains the diagnostic's position."""
    if span is None:
        return None
    here = (span.line, span.column)
    best: tuple[tuple[int, int], str] | None = None
    for element, start, end in elements:
        if start <= here <= end:
            size = (end[0] - start[0], end[1] - start[1] if end[0] == start[0] else 10**9)
            if best is None or size <= best[0]:
                best = (size, element)
    return best[1] if best else None


# ---------------------------------------------------------------------------- ranges


def _constant_points(t: Term) -> list[float]:
    mf = t.mf
    values: list[Any] = []
    if isinstance(mf, PointsMF | SingletonsMF):
        values = [p.x for p in mf.points]
    elif isinstance(mf, SingletonMF):
        values = [mf.value]
    elif isinstance(mf, ShapeMF):
        params = [p for p in mf.params if isinstance(p, float | int)]
        if registry.flag(mf.kind, "centre_spread") and len(params) >= 2:  # a bump: around it
            centre, spread = float(params[0]), abs(float(params[1]))
            values = [centre - 3 * spread, centre + 3 * spread]
        elif not registry.flag(mf.kind, "takagi_sugeno"):
            values = params
    return [float(v) for v in values if isinstance(v, float | int) and math.isfinite(v)]


def display_ranges(fb: FunctionBlock, settings: dict[str, Any] | None = None) -> dict[str, list[float]]:
    """The range each input and output is drawn over: its RANGE, else the studio's
    setting, else the span of its terms (widened when it has no width)."""
    stored = (settings or {}).get("ranges", {}) if settings else {}
    out: dict[str, list[float]] = {}
    for v in (*fb.inputs, *fb.outputs):
        blk = fb.fuzzify_block(v.name) or fb.defuzzify_block(v.name)
        rng = (blk.range if blk is not None else None) or v.range
        if rng is not None and rng.low < rng.high:
            out[v.name] = [rng.low, rng.high]
            continue
        saved = stored.get(v.name) if isinstance(stored, dict) else None
        if (
            isinstance(saved, list)
            and len(saved) == 2
            and all(isinstance(x, int | float) for x in saved)
            and saved[0] < saved[1]
        ):
            out[v.name] = [float(saved[0]), float(saved[1])]
            continue
        xs = [x for t in (blk.terms if blk is not None else ()) for x in _constant_points(t)]
        if not xs:
            out[v.name] = [-100.0, 100.0]
            continue
        low, high = min(xs), max(xs)
        if high - low < 1e-9:
            pad = max(abs(low) * 0.1, 1.0)
            low, high = low - pad, high + pad
        out[v.name] = [low, high]
    return out


def views(document: Document, settings: dict[str, Any] | None) -> dict[str, Any]:
    """What the editors draw of a document just opened or imported, so that the browser
    needs no second check: display ranges, term curves, what FCL cannot write."""
    ranges = display_ranges(document.main, settings)
    return {"ranges": ranges, "curves": curves(document.main, ranges), "fcl_losses": fcl_losses(document)}


def curves(fb: FunctionBlock, ranges: dict[str, list[float]]) -> dict[str, dict[str, Any]]:
    """How each term of each input and output looks, for the editors: ``{"points":
    [[x, mu], ...]}`` (exact for piecewise-linear terms, 201 samples for smooth ones,
    extended flat to the range ends), ``{"singleton": x}``, ``{"spikes": [[x, mu], ...]}``,
    or ``{"text": ...}`` for terms given by variables or expressions; each also has
    ``"fcl"``, the term as the FCL text writes it (after ``:=``)."""
    from fuzzyctl.engine.semantics.shapes import membership_np, pwl_points
    from fuzzyctl.fcl.writer import mf_text

    out: dict[str, dict[str, Any]] = {}
    for v in (*fb.inputs, *fb.outputs):
        blk = fb.fuzzify_block(v.name) or fb.defuzzify_block(v.name)
        low, high = ranges[v.name]
        terms: dict[str, Any] = {}
        for t in blk.terms if blk is not None else ():
            mf = t.mf
            shape: Any = {"text": type(mf).__name__}
            if isinstance(mf, SingletonMF) and isinstance(mf.value, float | int):
                shape = {"singleton": float(mf.value)}
            elif isinstance(mf, PointsMF) and all(
                isinstance(c, float | int) for p in mf.points for c in (p.x, p.y)
            ):
                pts = [[_num(p.x), _num(p.y)] for p in mf.points]
                shape = {"points": _extend(pts, low, high)}
            elif isinstance(mf, SingletonsMF) and all(
                isinstance(c, float | int) for p in mf.points for c in (p.x, p.y)
            ):
                shape = {"spikes": [[_num(p.x), _num(p.y)] for p in mf.points]}
            elif (
                isinstance(mf, ShapeMF)
                and not registry.flag(mf.kind, "takagi_sugeno")
                and all(isinstance(p, float | int) for p in (*mf.params, mf.height))
            ):
                params = [_num(p) for p in mf.params]
                height = _num(mf.height)
                try:
                    exact = pwl_points(mf.kind, params, height)
                    if exact is not None:
                        pts = [[float(x), float(y)] for x, y in exact]
                        shape = {"points": _extend(pts, low, high)}
                    else:
                        xs = np.linspace(low, high, 201)
                        ys = membership_np(mf.kind, params, height, xs)
                        shape = {"points": [[float(a), float(b)] for a, b in zip(xs, ys, strict=True)]}
                except (ValueError, ZeroDivisionError, FloatingPointError):
                    pass
            shape["fcl"] = mf_text(mf)
            terms[t.name] = shape
        out[v.name] = terms
    type2view.add_lower_curves(fb, ranges, out)
    return out


def _num(p: Param) -> float:
    assert not isinstance(p, Ref)  # callers checked that every parameter is a number
    return float(p)


def _extend(points: list[list[float]], low: float, high: float) -> list[list[float]]:
    """IEC points are constant beyond the first and the last point: draw that to the
    range ends."""
    if not points:
        return points
    pts = sorted(points, key=lambda p: p[0])
    if low < pts[0][0]:
        pts.insert(0, [low, pts[0][1]])
    if high > pts[-1][0]:
        pts.append([high, pts[-1][1]])
    return pts


# ---------------------------------------------------------------------------- controllers


class ControllerCache:
    """Compiled controllers by model content and purpose (``"surface"``, ``"recorder"``,
    ...): a purpose keeps its own instance because ``DEFAULT := NC`` makes evaluation
    stateful.  Least recently used out first."""

    def __init__(self, size: int = 16) -> None:
        self.size = size
        self._items: OrderedDict[tuple[str, str], Any] = OrderedDict()
        self._lock = threading.Lock()

    def get(self, fb: FunctionBlock, purpose: str) -> Any:
        import fuzzyctl

        key = (content_key(Document((fb,))), purpose)
        with self._lock:
            if key in self._items:
                self._items.move_to_end(key)
                return self._items[key]
        controller = fuzzyctl.compile(fb, backend="python")  # recompiled on every edit: no C build
        with self._lock:
            self._items[key] = controller
            while len(self._items) > self.size:
                self._items.popitem(last=False)
        return controller


def pointwise(fb: FunctionBlock) -> FunctionBlock:
    """``fb`` with ``DEFAULT := NC`` read as a fresh start: where no rule fires, an output
    shows its DEFAULT value (0 without one), as one evaluation after a reset gives.  A grid
    evaluated as a batch would otherwise carry the previous grid point's value into the
    gaps, and the surface would depend on the order of the sweep."""
    outputs = tuple(
        replace(d, default=replace(d.default, no_change=False))
        if d.default is not None and d.default.no_change
        else d
        for d in fb.defuzzify
    )
    return fb if outputs == fb.defuzzify else replace(fb, defuzzify=outputs)


def _finite(values: Any) -> list[float | None]:
    return [float(v) if math.isfinite(v) else None for v in np.asarray(values, dtype=float).ravel()]


def surface(
    controller: Any,
    fb: FunctionBlock,
    *,
    x: str,
    y: str,
    z: str,
    fixed: dict[str, float],
    ranges: dict[str, list[float]],
    points: int,
    animate: str | None = None,
    step_percent: float = 10.0,
) -> dict[str, Any]:
    """The output ``z`` over a grid of inputs ``x`` and ``y`` (the others at ``fixed``),
    evaluated with ``evaluate_batch``; with ``animate`` one frame per ``step_percent`` of
    that input's range (the manual's 4D display)."""
    inputs = [v.name for v in fb.inputs]
    for name in (x, y):
        if name not in inputs:
            raise FuzzyctlError(f"{name!r} is not an input (inputs: {', '.join(inputs)})")
    if z not in [v.name for v in fb.outputs]:
        raise FuzzyctlError(f"{z!r} is not an output")
    if x == y:
        raise FuzzyctlError("choose two different inputs for X and Y")
    xs = np.linspace(ranges[x][0], ranges[x][1], points)
    ys = np.linspace(ranges[y][0], ranges[y][1], points)
    gx, gy = np.meshgrid(xs, ys)  # z[j][i] is at (xs[i], ys[j]), plotly's surface layout
    frames: list[dict[str, Any]] = []
    values: list[float | None] = [None]
    if animate is not None:
        if animate not in inputs or animate in (x, y):
            raise FuzzyctlError(f"animate: {animate!r} must be an input other than X and Y")
        steps = max(1, round(100.0 / step_percent))
        lo, hi = ranges[animate]
        values = [lo + (hi - lo) * k / steps for k in range(steps + 1)]
    for value in values:
        columns: dict[str, Any] = {x: gx.ravel(), y: gy.ravel()}
        for name in inputs:
            if name in (x, y):
                continue
            v = value if (name == animate and value is not None) else fixed.get(name, sum(ranges[name]) / 2)
            columns[name] = np.full(gx.size, float(v))
        controller.reset()
        out = controller.evaluate_batch(columns)[z].reshape(gx.shape)
        frames.append({"value": value, "z": [_finite(row) for row in out]})
    return {"x": xs.tolist(), "y": ys.tolist(), "frames": frames}


def explain(controller: Any, inputs: dict[str, float]) -> dict[str, Any]:
    """Term degrees, rule degrees, accumulated output sets and values at one point (a
    fresh evaluation: the controller is reset first)."""
    controller.reset()
    if type2view.is_type2(controller):
        return type2view.explain(controller, controller.model, inputs)
    result: dict[str, Any] = controller.explain(inputs).to_dict()
    return result


# ---------------------------------------------------------------------------- test signals


def test_signal(spec: dict[str, Any], t: FloatArray, length: float, low: float, high: float) -> FloatArray:
    """The curve generator of the Siemens manual (6.7) at times ``t``.

    ``constant`` (``value``), ``minimum`` / ``maximum`` (the input's range limits),
    ``zero``, and ``triangle``: from ``minimum`` to ``maximum`` and back, ``periods``
    periods per display ``length``; ``duty`` is the rising part of a period in percent
    (0: a falling saw-tooth, 100: a rising one); ``phase`` moves the signal right by that
    percentage of the display length."""
    kind = spec.get("kind", "constant")
    if kind == "constant":
        return np.full(t.shape, float(spec.get("value", 0.0)))
    if kind == "zero":
        return np.zeros(t.shape)
    if kind == "minimum":
        return np.full(t.shape, low)
    if kind == "maximum":
        return np.full(t.shape, high)
    if kind != "triangle":
        raise FuzzyctlError(f"unknown test signal {kind!r}")
    lo, hi = float(spec.get("min", low)), float(spec.get("max", high))
    period = length / float(spec.get("periods", 1.0))
    duty = float(spec.get("duty", 50.0)) / 100.0
    shift = float(spec.get("phase", 0.0)) / 100.0 * length
    tau = np.mod(t - shift, period) / period  # 0 <= tau < 1: where in the period
    if duty <= 0.0:
        return hi - (hi - lo) * tau
    if duty >= 1.0:
        return lo + (hi - lo) * tau
    rising = lo + (hi - lo) * tau / duty
    falling = hi - (hi - lo) * (tau - duty) / (1.0 - duty)
    return np.where(tau < duty, rising, falling)


def record(
    controller: Any,
    fb: FunctionBlock,
    *,
    signals: dict[str, dict[str, Any]],
    times: list[float],
    length: float,
    ranges: dict[str, list[float]],
    reset: bool,
) -> dict[str, Any]:
    """One stretch of the curve recorder: the inputs the test signals give at ``times``
    and the outputs the engine computes from them (successive cycles of one instance)."""
    t = np.asarray(times, dtype=float)
    columns: dict[str, FloatArray] = {}
    for v in fb.inputs:
        low, high = ranges[v.name]
        columns[v.name] = test_signal(
            signals.get(v.name, {"kind": "constant", "value": 0.0}), t, length, low, high
        )
    if reset:
        controller.reset()
    outputs = controller.evaluate_batch(columns) if len(t) else {o.name: np.empty(0) for o in fb.outputs}
    return {
        "t": t.tolist(),
        "values": {
            **{k: _finite(v) for k, v in columns.items()},
            **{k: _finite(v) for k, v in outputs.items()},
        },
    }


def dumps(data: Any) -> str:
    return json.dumps(data, allow_nan=False)
