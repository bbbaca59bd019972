"""Every shape kind of model.SHAPES against an independent implementation (scikit-fuzzy or
pyfuzzylite, run in their own venv: tests/peers), and the scalar formulas against the numpy
ones."""

from __future__ import annotations

import numpy as np
import pytest

from fuzzyctl import model as m
from fuzzyctl.engine.semantics import shapes
from tests import peers

X = np.linspace(-2.0, 12.0, 2801)

# kind, params, independent reference (evaluated in the peer venv with x bound)
CASES: list[tuple[str, tuple[float, ...], str]] = [
    ("triangle", (1, 4, 7), "fuzz.trimf(x, [1, 4, 7])"),
    ("trapezoid", (1, 3, 6, 9), "fuzz.trapmf(x, [1, 3, 6, 9])"),
    ("gaussian", (5, 1.3), "fuzz.gaussmf(x, 5, 1.3)"),
    ("gaussian2", (3, 1, 6, 2), "fuzz.gauss2mf(x, 3, 1, 6, 2)"),
    ("bell", (5, 2, 3), "fuzz.gbellmf(x, 2, 3, 5)"),
    ("sigmoid", (5, 2), "fuzz.sigmf(x, 5, 2)"),
    ("psigmoid", (3, 2, 7, -1.5), "fuzz.psigmf(x, 3, 2, 7, -1.5)"),
    ("dsigmoid_pos", (3, 2, 7, 1.5), "np.maximum(fuzz.dsigmf(x, 3, 2, 7, 1.5), 0.0)"),
    ("dsigmoid", (3, 2, 7, 1.5), "fl.SigmoidDifference('', 3, 2, 1.5, 7).membership(x)"),
    ("sshape", (2, 8), "fuzz.smf(x, 2, 8)"),
    ("zshape", (2, 8), "fuzz.zmf(x, 2, 8)"),
    ("pishape", (1, 4, 5, 9), "fuzz.pimf(x, 1, 4, 5, 9)"),
    ("cosine", (5, 4), "fl.Cosine('', 5, 4).membership(x)"),
    ("ramp", (2, 8), "fl.Ramp('', 2, 8).membership(x)"),
    ("ramp", (8, 2), "fl.Ramp('', 8, 2).membership(x)"),
    ("rectangle", (3, 6), "fl.Rectangle('', 3, 6).membership(x)"),
    ("spike", (5, 3), "fl.Spike('', 5, 3).membership(x)"),
    ("concave", (5, 8), "fl.Concave('', 5, 8).membership(x)"),
    ("concave", (5, 2), "fl.Concave('', 5, 2).membership(x)"),
    ("cosine_half", (5, 2), "fl.Cosine('', 5, 4).membership(x)"),
    ("arc", (2, 6), "fl.Arc('', 2, 6).membership(x)"),
    ("arc", (6, 2), "fl.Arc('', 6, 2).membership(x)"),
    ("semiellipse", (2, 6), "fl.SemiEllipse('', 2, 6).membership(x)"),
    ("binary", (4, 10), "fl.Binary('', 4, math.inf).membership(x)"),
    ("binary", (4, 0), "fl.Binary('', 4, -math.inf).membership(x)"),
]


def test_every_fuzzy_set_kind_is_covered() -> None:
    covered = {k for k, _p, _f in CASES}
    assert set(m.SHAPES) - covered == {"constant", "linear"}  # Takagi-Sugeno terms: test_semantics


@pytest.mark.parametrize(("kind", "params", "ref"), CASES, ids=[f"{k}{p}" for k, p, _r in CASES])
def test_shape_against_independent_implementation(kind: str, params: tuple[float, ...], ref: str) -> None:
    want = peers.membership(ref, X)
    vec = shapes.membership_np(kind, params, 1.0, X)
    scal = np.array([shapes.membership(kind, params, 1.0, float(x)) for x in X])
    np.testing.assert_allclose(vec, want, rtol=0, atol=1e-12)
    np.testing.assert_allclose(scal, vec, rtol=0, atol=1e-15)


def test_height_scales_and_parameters_may_be_arrays() -> None:
    p = (np.array([1.0, 2.0]), np.array([4.0, 4.0]), np.array([7.0, 9.0]))
    got = shapes.membership_np("triangle", p, 0.5, np.array([3.0, 3.0]))
    np.testing.assert_allclose(got, [0.5 * 2 / 3, 0.5 * 0.5])


def test_points_vertical_edges_and_constant_extension() -> None:
    pts = shapes.pwl_points("points", (1, 0.2, 2, 0.0, 2, 1.0, 3, 0.5))
    assert pts is not None
    assert shapes.pwl_value(pts, 0.0) == 0.2  # constant before the first point
    assert shapes.pwl_value(pts, 2.0) == 1.0  # upper value on the edge
    assert shapes.pwl_value(pts, 1.5) == pytest.approx(0.1)
    assert shapes.pwl_value(pts, 2.5) == pytest.approx(0.75)
    assert shapes.pwl_value(pts, 9.0) == 0.5  # constant after the last
    np.testing.assert_allclose(
        shapes.pwl_value_np(pts, np.array([0.0, 1.5, 2.0, 2.5, 9.0])), [0.2, 0.1, 1.0, 0.75, 0.5]
    )


def test_tsukamoto_inverts_monotonic_terms() -> None:
    for kind, params in [
        ("ramp", (2, 8)),
        ("ramp", (8, 2)),
        ("sigmoid", (5, 2)),
        ("sshape", (2, 8)),
        ("arc", (2, 6)),
        ("arc", (6, 2)),
        ("zshape", (2, 8)),
        ("concave", (5, 8)),
        ("concave", (5, 2)),
    ]:
        for y in (0.1, 0.3, 0.5, 0.7, 0.9):
            x = shapes.tsukamoto(kind, params, 1.0, y)
            assert shapes.membership(kind, params, 1.0, x) == pytest.approx(y, abs=1e-12), (kind, y)
