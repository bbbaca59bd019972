"""The model compares by content: positions and comments never decide equality."""

import math

from fuzzyctl.model import (
    Conclusion,
    Default,
    FunctionBlock,
    Is,
    Rule,
    RuleBlock,
    Span,
    Variable,
    VarKind,
)


def test_spans_and_comments_do_not_take_part_in_equality() -> None:
    a = Rule("1", Is("temp", "cold", span=Span(3, 4)), (Conclusion("valve", "inlet"),), comments=("x",))
    b = Rule("1", Is("temp", "cold", span=Span(9, 1)), (Conclusion("valve", "inlet"),))
    assert a == b
    assert a != Rule("1", Is("temp", "hot"), (Conclusion("valve", "inlet"),))


def test_nan_defaults_compare_equal() -> None:
    assert Default(float("nan"), True) == Default(float("nan"), True)
    assert math.isnan(Default(float("nan")).value or 0.0)


def test_function_block_views() -> None:
    fb = FunctionBlock(
        "fb",
        variables=(
            Variable("t", VarKind.INPUT),
            Variable("v", VarKind.OUTPUT),
            Variable("w", VarKind.LOCAL),
        ),
        rule_blocks=(RuleBlock("r", (Rule("1", None, ()),)),),
    )
    assert [v.name for v in fb.inputs] == ["t"]
    assert [v.name for v in fb.outputs] == ["v"]
    assert [v.name for v in fb.locals] == ["w"]
    assert fb.variable("w") is fb.locals[0]
    assert [r.label for _, r in fb.rules()] == ["1"]
