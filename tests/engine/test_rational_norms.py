"""HAMACHER and EINSTEIN (rational norms) as activation and accumulation on piecewise-linear
terms: every path against an independent integration of the set computed in exact rational
arithmetic (fractions.Fraction, the textbook formulas) and integrated by scipy's quad with a
point at every breakpoint.  Overlapping plateaus at rule degree 1 and just below are where
the floating-point (a+b-2ab)/(1-ab) cancelled catastrophically (values up to 2.27)."""

from __future__ import annotations

import dataclasses
import warnings
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl import model as m

TOL = 1e-9  # of the output range
LO, HI = 0.0, 10.0
IN_TERMS = {"a": (0.0, 1.0, 4.0, 6.0), "b": (2.0, 3.5, 5.0, 8.0), "c": (5.0, 8.0, 9.0, 10.0)}
OUT_TERMS = {"o0": (0.5, 2.0, 5.5, 7.0), "o1": (1.0, 3.0, 6.0, 9.0), "o2": (4.0, 7.0, 7.0, 9.5)}
# a partial set first, then two sets at exactly 1 on [3, 5.5]: the order that broke
RULES = [("a", "o2", 0.4), ("a", "o0", None), ("b", "o1", None), ("c", "o1", 0.7), ("b", "o0", 0.9)]
PAIRS = [
    ("HAMACHER", "HAMACHER"),
    ("EINSTEIN", "EINSTEIN"),
    ("HAMACHER", "EINSTEIN"),
    ("EINSTEIN", "HAMACHER"),
]
# both plateaus (degrees exactly 1), just below 1, partial, and one term alone
XS = [3.7, 4.5, 4.0 - 1e-12, 3.5 + 1e-13, 2.7, 5.5, 7.3, 0.3, 9.5]


def _trap(p: tuple[float, ...]) -> m.MembershipFunction:
    return m.ShapeMF("trapezoid", p)


def system() -> m.FunctionBlock:
    outs = [f"y_{act}_{accu}".lower() for act, accu in PAIRS]
    variables = (m.Variable("x", m.VarKind.INPUT), *(m.Variable(o, m.VarKind.OUTPUT) for o in outs))
    fuzzify = (m.FuzzifyBlock("x", tuple(m.Term(n, _trap(p)) for n, p in IN_TERMS.items()), m.Range(LO, HI)),)
    terms = tuple(m.Term(n, _trap(p)) for n, p in OUT_TERMS.items())
    defuzz = tuple(
        m.DefuzzifyBlock(o, terms, m.Range(LO, HI), "COG", m.Default(-1.0), accu=accu)
        for o, (_act, accu) in zip(outs, PAIRS, strict=True)
    )
    blocks = tuple(
        m.RuleBlock(
            f"b{k}",
            tuple(
                m.Rule(f"{i + 1}", m.Is("x", t), (m.Conclusion(o, ot, w),))
                for i, (t, ot, w) in enumerate(RULES)
            ),
            "MIN",
            "MAX",
            act,
        )
        for k, (o, (act, _accu)) in enumerate(zip(outs, PAIRS, strict=True))
    )
    return m.FunctionBlock(
        "rational", variables=variables, fuzzify=fuzzify, defuzzify=defuzz, rule_blocks=blocks
    )


def _mu(p: tuple[float, ...], x: Fraction) -> Fraction:
    a, b, c, d = (Fraction(v) for v in p)
    if x <= a or x >= d:
        return Fraction(0)
    if x < b:
        return (x - a) / (b - a)
    return Fraction(1) if x <= c else (d - x) / (d - c)


def _t(name: str, a: Fraction, b: Fraction) -> Fraction:
    if name == "HAMACHER":
        s = a + b - a * b
        return a * b / s if s else Fraction(0)
    return a * b / (2 - (a + b - a * b))


def _s(name: str, a: Fraction, b: Fraction) -> Fraction:
    if name == "HAMACHER":
        return (a + b - 2 * a * b) / (1 - a * b) if a * b != 1 else Fraction(1)
    return (a + b) / (1 + a * b)


def exact_cog(x: float, act: str, accu: str) -> float:
    quad = pytest.importorskip("scipy.integrate").quad
    fx = Fraction(x)
    sets = [(OUT_TERMS[ot], _mu(IN_TERMS[t], fx), Fraction(1 if w is None else w)) for t, ot, w in RULES]

    def f(u: float) -> float:
        acc, fu = Fraction(0), Fraction(u)
        for p, alpha, w in sets:
            acc = _s(accu, acc, w * _t(act, alpha, _mu(p, fu)))
        return float(acc)

    points = sorted({v for p in OUT_TERMS.values() for v in p})
    opts = {"points": points, "limit": 500, "epsabs": 1e-14, "epsrel": 1e-13}
    area = quad(f, LO, HI, **opts)[0]
    moment = quad(lambda u: u * f(u), LO, HI, **opts)[0]
    return float(moment / area)


def test_rational_norms_agree_on_every_path_with_an_exact_integration(tmp_path: Path) -> None:
    fb = system()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref = fuzzyctl.compile(fb, backend="interpreted")
        py = fuzzyctl.compile(fb, backend="python")
        nat = fuzzyctl.compile(fb, backend="native")
    cols = {"x": np.array(XS)}
    paths = {"native batch": nat.evaluate_batch(cols), "numpy batch": py.evaluate_batch(cols)}
    try:
        from tests.codegen.test_c import build_library, run

        plan = dataclasses.replace(ref.plan, name="rational")
        lib = build_library([plan], tmp_path)
        c_out = run(lib, plan, np.array([[x] for x in XS]))
        names = [o.name for o in plan.outputs if o.is_output]
        paths["generated C"] = {o: c_out[:, j] for j, o in enumerate(names)}
    except pytest.skip.Exception:  # no C compiler: the other paths are still compared
        pass
    bad = []
    for i, x in enumerate(XS):
        got = {
            "interpreted": ref.evaluate({"x": x}),
            "python": py.evaluate({"x": x}),
            "native": nat.evaluate({"x": x}),
        }
        got.update({k: {o: float(v[o][i]) for o in v} for k, v in paths.items()})
        for act, accu in PAIRS:
            out = f"y_{act}_{accu}".lower()
            want = exact_cog(x, act, accu)
            for path, vals in got.items():
                if not abs(vals[out] - want) <= TOL * (HI - LO):
                    bad.append(f"{out} x={x!r}: {path} {vals[out]!r} != exact {want!r}")
    assert not bad, "\n".join(bad)
