"""``--default``: what the generated block outputs when no rule fired for an output whose
``DEFAULT`` is NaN (fuzzylite's and MATLAB's default, ``DEFAULT := nan`` in 33 FIS and 50 FLL
files of the corpus).

Portable Structured Text has no NaN literal (and a NaN output breaks most PLC programs that
read it), so generation needs a choice:

* ``--default VALUE``: output ``VALUE``;
* ``--default hold``: keep the output's last value (``DEFAULT := NC``; 0.0 before the first
  cycle in which a rule fired).

Either way INFO is 16#02 ("no rule fired for an output") in that cycle, and the header
comment of the generated code says which choice was made.  C can hold a NaN: without the
option the generated C outputs NaN as the engine does.
"""

from __future__ import annotations

import dataclasses
import math

from fuzzyctl.engine.plan import Plan
from fuzzyctl.escape import CodegenError

HOLD = "hold"


def parse_default(text: str | float | None) -> float | str | None:
    """``--default`` as given: a finite number, ``hold`` or None; else a message naming the
    option."""
    if text is None or (isinstance(text, float | int) and not isinstance(text, bool)):
        value = None if text is None else float(text)
        if value is not None and not math.isfinite(value):
            raise CodegenError(f"--default {text}: give a finite number or 'hold'")
        return value
    s = str(text).strip()
    if s.lower() == HOLD:
        return HOLD
    try:
        value = float(s)
    except ValueError:
        raise CodegenError(f"--default {s}: give a number or 'hold'") from None
    if not math.isfinite(value):
        raise CodegenError(f"--default {s}: give a finite number or 'hold'")
    return value


def nan_outputs(plan: Plan) -> list[str]:
    """The outputs whose DEFAULT is NaN (and that do not keep their value)."""
    return [
        op.name
        for op in plan.outputs
        if op.kind != "degree" and op.default is not None and math.isnan(op.default)
    ]


def apply_default(plan: Plan, default: float | str | None) -> tuple[Plan, list[str]]:
    """``plan`` with every ``DEFAULT := nan`` replaced as ``default`` says, and the header
    lines that say so (none when no output has a NaN DEFAULT or ``default`` is None)."""
    names = nan_outputs(plan)
    if default is None or not names:
        return plan, []
    outputs = []
    for op in plan.outputs:
        if op.name not in names:
            outputs.append(op)
        elif default == HOLD:
            outputs.append(dataclasses.replace(op, default=None, no_change=True))
        else:  # with DEFAULT := NC as well, VALUE is the value before a rule first fired
            assert isinstance(default, float)
            outputs.append(dataclasses.replace(op, default=default))
    if default == HOLD:
        what = "keep their last value (0.0 before a rule first fired)"
    else:
        what = f"output {default!r}"
    notes = [
        f"--default {default}: when no rule fires, outputs with DEFAULT := nan ({', '.join(names)}) "
        f"{what}; INFO is 16#02 then"
    ]
    return dataclasses.replace(plan, outputs=tuple(outputs)), notes
