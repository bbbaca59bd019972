"""Round trips keep what a system computes: FIS -> model -> FIS, FLL -> model -> FLL and
FCL -> FIS -> FCL over every file of the corpus (extra suite) and of the vendored conformance data
(identical files counted once per set), evaluated with the engine on random inputs.

For each file: read it (A), convert it (``Format.adapt`` + ``write``) and read the result
back (B; for FCL -> FIS -> FCL, B is the FIS and C the FCL written from it), then evaluate A
and B (and C) on the same random input sequence with ``evaluate_batch`` and require every
output to agree within 1e-9 (absolute).  Inputs are
drawn uniformly over each input's range widened by 10% on both sides (lock-range, shoulders
and "nothing fired" are exercised); inputs used as degrees over [0, 1].  1000 inputs per
file.  A file with a smooth Mamdani output costs ~4 ms per input (adaptive quadrature), so
there, when the file read back lowers to the very same evaluation plan as the original
(``Controller`` evaluates nothing but its plan), the outputs are equal for every input and
the 1000 are not evaluated; a plan that differs in anything (a renamed variable, a term
written in another form) is evaluated on all 1000.

A file is counted in one category, the first that applies: unreadable (the reader rejects
it, see tests/formats/rejected.tsv), not expressible (the target lacks a feature: the
reasons are counted), not evaluable (the engine refuses the original, e.g. an output
without RANGE whose terms are not bounded), or compared.  The counts and reasons are
printed in the "conformance measurements" section.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl import model as m
from fuzzyctl.diagnostics import DiagnosticError, FuzzyctlError
from fuzzyctl.engine.controller import Controller
from fuzzyctl.formats import decode, get
from tests.extras import real_files

TOLERANCE = 1e-9
PATHS = {"fis": ("fis", ("fis",)), "fll": ("fll", ("fll",)), "fcl": ("fcl", ("fis", "fcl"))}
CASES = [
    pytest.param(kind, p.values[0], marks=p.marks, id=f"{kind}:{p.id}")
    for kind in PATHS
    for p in real_files(kind)
]


def _normal(name: str) -> str:
    """Writers may rename identifiers (``LDL-Level`` -> ``LDL_Level``)."""
    return re.sub(r"[^A-Za-z0-9_]", "_", name)


def _matching(names_a: tuple[str, ...], names_b: tuple[str, ...]) -> dict[str, str]:
    """Each name of A to its name in B: the same once normalised, else (a keyword renamed
    ``if`` -> ``if_2``) the name at the same position; writers keep the order."""
    normal_b = {_normal(x): x for x in names_b}
    assert len(names_a) == len(names_b), (names_a, names_b)
    return {a: normal_b.get(_normal(a), b) for a, b in zip(names_a, names_b, strict=True)}


def _input_box(fb: m.FunctionBlock, name: str) -> tuple[float, float]:
    block = fb.fuzzify_block(name)
    var = fb.variable(name)
    rng = (block.range if block else None) or (var.range if var else None)
    if rng is not None and math.isfinite(rng.low) and math.isfinite(rng.high) and rng.high > rng.low:
        low, high = rng.low, rng.high
    else:  # no RANGE: the span of the terms' literal parameters
        xs: list[float] = []
        for term in block.terms if block else ():
            mf = term.mf
            if isinstance(mf, m.ShapeMF):
                xs += [float(p) for p in mf.params if not isinstance(p, m.Ref) and math.isfinite(float(p))]
            elif isinstance(mf, m.PointsMF):
                xs += [float(p.x) for p in mf.points if not isinstance(p.x, m.Ref)]
        low, high = (min(xs), max(xs)) if xs else (0.0, 1.0)
        high = high if high > low else low + 1.0
    pad = 0.1 * (high - low)
    return low - pad, high + pad


SAMPLES = 1000


def _smooth(controller: Controller) -> bool:
    """A Mamdani output integrated by adaptive quadrature (not piecewise linear)."""
    return any(o.kind == "mamdani" and not (o.exact and o.grid is not None) for o in controller.plan.outputs)


def _inputs(controller: Controller, fb: m.FunctionBlock, seed: int) -> dict[str, np.ndarray]:
    n = SAMPLES
    rng = np.random.default_rng(seed)
    data = {}
    for spec in controller.plan.inputs:
        if spec.degree:
            data[spec.name] = rng.random(n)
        else:
            low, high = _input_box(fb, spec.name)
            data[spec.name] = low + (high - low) * rng.random(n)
    return data


def _worst(a: Controller, b: Controller, data: dict[str, np.ndarray]) -> float:
    """Largest absolute difference between the outputs of two controllers."""
    inputs_b = _matching(a.inputs, b.inputs)
    ra = a.evaluate_batch(data)
    rb = b.evaluate_batch({inputs_b[k]: v for k, v in data.items()})
    outputs_b = _matching(a.outputs, b.outputs)
    worst = 0.0
    for name, va in ra.items():
        vb = rb[outputs_b[name]]
        same = (np.isnan(va) & np.isnan(vb)) | (va == vb)
        with np.errstate(invalid="ignore"):
            err = np.where(same, 0.0, np.abs(va - vb))
        worst = max(worst, float(np.where(np.isnan(err), np.inf, err).max()))
    return worst


@pytest.mark.parametrize(("path", "source"), CASES)
def test_round_trip_keeps_evaluation(path: str, source: Path, record_property: pytest.RecordProperty) -> None:
    kind, targets = PATHS[path]
    chain = " -> ".join([kind, *targets]) if path == "fcl" else f"{kind} -> model -> {kind}"
    label = f"round trip {chain}, files"

    def report(category: str, detail: str = "") -> None:
        record_property("roundtrip", f"{label}\t{category}\t{detail}")

    try:
        original = get(kind).read(decode(source.read_bytes()), str(source)).document
    except DiagnosticError:
        report("unreadable")
        return
    documents = [original]
    for target in targets:
        fmt = get(target)
        adapted, losses = fmt.adapt(documents[-1])
        if losses:
            reasons = {re.sub(r"'[^']*'|\b\d+(\.\d+)?\b", "…", loss.reason) for loss in losses}
            report(f"not expressible in {target}", "\x1f".join(sorted(reasons)))
            return
        documents.append(fmt.read(fmt.write(adapted), None).document)
    try:
        first = fuzzyctl.compile(original)
    except (DiagnosticError, FuzzyctlError) as exc:
        codes = sorted({d.code for d in getattr(exc, "diagnostics", []) if d.is_error} or {"error"})
        report("not evaluable", ", ".join(c or "error" for c in codes))
        return
    data = _inputs(first, original.main, seed=len(source.name))
    assert all(len(v) == SAMPLES for v in data.values())
    worst = 0.0
    evaluated = 0
    for doc in documents[1:]:
        again = fuzzyctl.compile(doc)
        if _smooth(first) and again.plan == first.plan:
            continue  # the same plan computes the same outputs for every input
        worst = max(worst, _worst(first, again, data))
        evaluated += 1
    report("compared", "evaluated on 1000 inputs" if evaluated else "the same evaluation plan")
    assert worst <= TOLERANCE, f"{source.name}: {chain} changes the outputs by up to {worst:.3g}"
