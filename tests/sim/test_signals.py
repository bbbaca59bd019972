"""Signal expressions: arithmetic, the first-order elements against closed forms, refusals."""

from __future__ import annotations

import math

import pytest

from fuzzyctl.diagnostics import InputError
from fuzzyctl.sim import Expression, profiles


def test_arithmetic_and_functions():
    env = {"a": 3.0, "b": -4.0}
    assert Expression("a - b * 2 + a ** 2 / 3")(env, 0.1) == pytest.approx(3 + 8 + 3)
    assert Expression("clip(b, -1, 1) + abs(b) + max(a, b, 10) + sign(b)")(env, 0.1) == -1 + 4 + 10 - 1
    assert Expression("deg(rad(a)) + sqrt(9)")(env, 0.1) == pytest.approx(6.0)
    assert Expression("-a")(env, 0.1) == -3.0


def test_ddt_of_a_ramp_is_its_slope_and_the_filter_is_first_order():
    d = Expression("ddt(x)")
    values = [d({"x": 2.0 * k * 0.1}, 0.1) for k in range(5)]
    assert values[0] == 0.0 and values[1:] == pytest.approx([2.0] * 4)
    # Backward-Euler filter of a unit slope: v_k = 1 - (tf / (tf + h))^k  after the first call.
    tf, h = 0.5, 0.01
    f = Expression(f"ddt(x, {tf})")
    f({"x": 0.0}, h)
    for k in range(1, 200):
        v = f({"x": k * h}, h)
        assert v == pytest.approx(1 - (tf / (tf + h)) ** k, rel=1e-9)
    assert v == pytest.approx(1 - math.exp(-199 * h / tf), abs=0.02)


def test_integral_delay_and_reset():
    i = Expression("integral(x)")
    for _ in range(10):
        i({"x": 3.0}, 0.5)
    assert i({"x": 3.0}, 0.5) == pytest.approx(16.5)
    i.reset()
    assert i({"x": 1.0}, 1.0) == 1.0
    dl = Expression("delay(x, 2)")
    assert [dl({"x": float(k)}, 1.0) for k in range(5)] == [0.0, 0.0, 0.0, 1.0, 2.0]


@pytest.mark.parametrize(
    ("source", "message"),
    [
        ("__import__('os')", "unknown function|not allowed"),
        ("a.b", "Attribute is not allowed"),
        ("a if b else c", "IfExp is not allowed"),
        ("a +", "cannot read"),
        ("ddt(a, -1)", ">= 0"),
        ("ddt(a, b)", "expected a number"),
        ("foo(a)", "unknown function foo"),
        ("a // 2", "only"),
        ("clip(a)", "takes 3"),
    ],
)
def test_refusals_name_the_problem(source, message):
    with pytest.raises(InputError, match=message):
        Expression(source, where="controller.inputs.x")


def test_unknown_signal_names_the_expression_and_the_signals():
    with pytest.raises(InputError, match=r"controller.inputs.d: unknown signal 'target'.*signals: position"):
        Expression("target - position", where="controller.inputs.d")({"position": 1.0}, 0.1)


def test_profiles():
    s = profiles.steps([(0, 1), (5, 2)])
    assert [s(t) for t in (0, 4.99, 5, 100)] == [1, 1, 2, 2]
    p = profiles.points([(0, 0), (10, 20)])
    assert [p(t) for t in (-1, 5, 10, 11)] == [0, 10, 20, 20]
    pulse = profiles.from_config({"pulse": 5, "start": 2, "width": 0.5}, where="x")
    assert [pulse(t) for t in (1.9, 2.0, 2.4, 2.5)] == [0, 5, 5, 0]
    sine = profiles.from_config({"sine": 2, "period": 4}, where="x")
    assert sine(1.0) == pytest.approx(2.0)
    with pytest.raises(InputError, match=r"\[setpoints\] w: .*times must not decrease"):
        profiles.from_config({"steps": [[5, 1], [1, 2]]}, where="[setpoints] w")
    with pytest.raises(InputError, match="expected a number or a table"):
        profiles.from_config("hot", where="w")
