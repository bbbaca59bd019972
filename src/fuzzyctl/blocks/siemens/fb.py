"""The Siemens S7 FUZZY function block (FB30) with its instance data block (manual 3.1).

:class:`FuzzyFB` is the instance data block of Tables 3-1..3-3: INPUT1..8 and OUTPUT1..4
(REAL), INFO (BYTE), START_STOP (WORD), plus the status bit BR as ``ENO``.  A controller
("fuzzy application") is downloaded into it like the configuration tool does: the tool
stops the block (START_STOP = 0), transfers, and restarts it (START_STOP = W#16#FFFF).
The controller's first 8 inputs and 4 outputs map to INPUT1..8 / OUTPUT1..4 in
declaration order.

Each :meth:`FuzzyFB.execute` is one call of the block:

* INFO 21 when the data block is shorter than a fuzzy data block (``db_length`` < 2126),
  INFO 11 when no valid application has been downloaded, INFO 01 when START_STOP = 0: the
  outputs are not touched (old values) and ENO is false;
* otherwise INFO 00, ENO true: the inputs are clamped to their [MIN, MAX] (1.5), the rules
  are evaluated, and each output takes its new value - or keeps its last one when no rule
  fired for it (0.0 before the first value, 1.5).

Inference (1.4): AND is the minimum, and the output is the centre of gravity of the
singletons weighted by the *sum* of the degrees of the rules concluding each of them,
``(mu_A x_A + mu_B x_B + ...) / (mu_A + mu_B + ...)`` with one mu per rule.  The block has
no other accumulation: whatever ACCU a program writes, the block adds (the ``siemens``
profile warns where that changes the result; ``ACCU : NSUM`` is the IEC way to say it).

The values are REALs: the block reads its inputs and writes its outputs in IEEE single
precision, as the PLC holds them.  A rule with an empty IF part acts with degree 1 (1.5);
that is the engine's reading of ``Rule.condition is None``.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any

from fuzzyctl.blocks.siemens.analog import DB_FUZZY_LENGTH
from fuzzyctl.blocks.siemens.info import Info
from fuzzyctl.blocks.siemens.profile import check_siemens, variable_limits
from fuzzyctl.diagnostics import Diagnostic, DiagnosticError, InputError, error
from fuzzyctl.model import (
    Default,
    Document,
    FunctionBlock,
)

__all__ = ["BLOCK_ACCU", "FuzzyFB", "block_semantics"]

N_INPUTS, N_OUTPUTS = 8, 4
BLOCK_ACCU = "SUM"
"""The block's accumulation: the plain sum of the rules' degrees per output term (1.4)."""


_REAL = struct.Struct("f")
_IN_ATTRS = tuple(f"INPUT{i}" for i in range(1, N_INPUTS + 1))
_OUT_ATTRS = tuple(f"OUTPUT{i}" for i in range(1, N_OUTPUTS + 1))


def real(value: float) -> float:
    """A value as an S7 REAL (IEEE 754 single precision) holds it: rounded to nearest,
    +-inf beyond the REAL range (as numpy's float32 conversion; struct is 4x faster, and
    this runs for every input and output of every cycle of the runtime)."""
    try:
        result: float = _REAL.unpack(_REAL.pack(value))[0]
    except OverflowError:  # rounds beyond FLT_MAX: IEEE gives the signed infinity
        return math.copysign(math.inf, value)
    return result


def block_semantics(fb: FunctionBlock) -> FunctionBlock:
    """``fb`` as the FUZZY block computes it, for the engine: no rule fired -> NaN (the
    block then keeps the last value, 1.5); the degrees of the rules concluding one output
    term are added (1.4: ``x_S' = (mu_A x_A + mu_B x_B + ...) / (mu_A + mu_B + ...)``, one
    mu per rule, and the glossary's "influences ... resulting from various rules are added
    together"), whatever ACCU the program writes: the block has no other accumulation."""
    return replace(
        fb,
        defuzzify=tuple(replace(d, default=Default(math.nan), accu=None) for d in fb.defuzzify),
        rule_blocks=tuple(replace(rb, accu=BLOCK_ACCU) for rb in fb.rule_blocks),
    )


class FuzzyFB:
    """One FUZZY instance data block.

    Set ``INPUT1``..``INPUT8`` (or :meth:`set_inputs` by variable name), call
    :meth:`execute`, read ``OUTPUT1``..``OUTPUT4``, ``INFO`` and ``ENO``.

    ``check_profile=False`` downloads a controller that breaks the ``siemens`` profile
    (operators, shapes, limits other than the I/O count); it then runs with the
    controller's own operators and shapes, which a real S7 block would not - but always
    with the block's accumulation (the sum, 1.4) and its "last value" rule (1.5)."""

    def __init__(
        self,
        application: FunctionBlock | Document | None = None,
        *,
        db_length: int = DB_FUZZY_LENGTH,
        check_profile: bool = True,
    ) -> None:
        self.INPUT1 = self.INPUT2 = self.INPUT3 = self.INPUT4 = 0.0
        self.INPUT5 = self.INPUT6 = self.INPUT7 = self.INPUT8 = 0.0
        self.OUTPUT1 = self.OUTPUT2 = self.OUTPUT3 = self.OUTPUT4 = 0.0
        self.INFO = 0
        self.START_STOP = 0
        self.ENO = False
        self.db_length = db_length
        self.application: FunctionBlock | None = None
        self.diagnostics: list[Diagnostic] = []
        self._controller: Any = None
        self._inputs: tuple[str, ...] = ()
        self._outputs: tuple[str, ...] = ()
        self._in_limits: list[tuple[float, float] | None] = [None] * N_INPUTS
        self._out_limits: list[tuple[float, float] | None] = [None] * N_OUTPUTS
        if application is not None:
            self.download(application, check_profile=check_profile)

    # ----------------------------------------------------------------- configuration

    def download(
        self, application: FunctionBlock | Document, *, check_profile: bool = True
    ) -> list[Diagnostic]:
        """Load a controller as the configuration tool does (stop, transfer, START_STOP =
        W#16#FFFF).  Returns the profile's warnings; raises DiagnosticError when the
        controller does not fit the block."""
        from fuzzyctl.engine import compile_block as compile_controller

        fb = application.main if isinstance(application, Document) else application
        self.START_STOP = 0
        diags = check_siemens(fb) if check_profile else []
        if len(fb.inputs) > N_INPUTS or len(fb.outputs) > N_OUTPUTS:
            diags.append(
                error(
                    f"{len(fb.inputs)} inputs and {len(fb.outputs)} outputs: the FUZZY block "
                    f"connects {N_INPUTS} and {N_OUTPUTS}",
                    fb.span,
                    code="siemens-io-count",
                )
            )
        if any(d.is_error for d in diags):
            raise DiagnosticError(diags)
        self._controller = compile_controller(block_semantics(fb))
        self.application = fb
        self._inputs = tuple(v.name for v in fb.inputs)
        self._outputs = tuple(v.name for v in fb.outputs)
        self._in_limits = [variable_limits(fb, n) for n in self._inputs] + [None] * (
            N_INPUTS - len(self._inputs)
        )
        self._out_limits = [variable_limits(fb, n) for n in self._outputs] + [None] * (
            N_OUTPUTS - len(self._outputs)
        )
        self.diagnostics = diags
        self.START_STOP = 0xFFFF
        return diags

    @property
    def has_application(self) -> bool:
        """True once a valid fuzzy application has been downloaded."""
        return self._controller is not None

    @property
    def input_names(self) -> tuple[str, ...]:
        return self._inputs

    @property
    def output_names(self) -> tuple[str, ...]:
        return self._outputs

    def input_limits(self, number: int) -> tuple[float, float]:
        """MIN/MAX of INPUT<number> (0.0, 0.0 for an input the application does not use)."""
        return self._in_limits[number - 1] or (0.0, 0.0)

    def output_limits(self, number: int) -> tuple[float, float]:
        return self._out_limits[number - 1] or (0.0, 0.0)

    # ----------------------------------------------------------------- values

    def write_input(self, number: int, value: float) -> None:
        setattr(self, _IN_ATTRS[number - 1], real(value))

    def read_output(self, number: int) -> float:
        return float(getattr(self, _OUT_ATTRS[number - 1]))

    @property
    def inputs(self) -> tuple[float, ...]:
        return tuple(float(getattr(self, f"INPUT{i}")) for i in range(1, N_INPUTS + 1))

    @property
    def outputs(self) -> tuple[float, ...]:
        return tuple(float(getattr(self, f"OUTPUT{i}")) for i in range(1, N_OUTPUTS + 1))

    def set_inputs(self, values: Mapping[str, float] | Sequence[float]) -> None:
        """Write inputs by variable name or INPUTn name, or a sequence for INPUT1.."""
        if isinstance(values, Mapping):
            for name, value in values.items():
                if name in self._inputs:
                    self.write_input(self._inputs.index(name) + 1, value)
                elif (
                    name.upper().startswith("INPUT") and name[5:].isdigit() and 1 <= int(name[5:]) <= N_INPUTS
                ):
                    self.write_input(int(name[5:]), value)
                else:
                    raise InputError(
                        f"{name!r} is not an input of the block (inputs: "
                        f"{', '.join(self._inputs) or 'none'}; or INPUT1..INPUT8)"
                    )
        else:
            if len(values) > N_INPUTS:
                raise InputError(f"{len(values)} values for {N_INPUTS} inputs")
            for i, value in enumerate(values, start=1):
                self.write_input(i, value)

    def output_values(self) -> dict[str, float]:
        """The outputs of the application by name."""
        return {name: self.read_output(i) for i, name in enumerate(self._outputs, start=1)}

    # ----------------------------------------------------------------- the call

    def execute(self) -> int:
        """One call of FB30; returns INFO (also in ``self.INFO``; ``self.ENO`` is BR)."""
        info = self._run()
        self.INFO = int(info)
        self.ENO = info is Info.OK
        return self.INFO

    __call__ = execute

    def _run(self) -> Info:
        if self.db_length < DB_FUZZY_LENGTH:
            return Info.DB_TOO_SHORT
        if self._controller is None:
            return Info.NO_APPLICATION
        if not self.START_STOP & 0xFFFF:
            return Info.DISABLED
        values: dict[str, float] = {}
        for i, name in enumerate(self._inputs, start=1):
            x = getattr(self, _IN_ATTRS[i - 1])
            if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
                raise InputError(f"INPUT{i} ({name}) = {x!r} is not a finite REAL")
            x = real(x)  # what a REAL parameter holds, however it was written
            limits = self._in_limits[i - 1]
            if limits is not None:
                x = min(max(x, limits[0]), limits[1])  # 1.5: clamped to MIN/MAX
            values[name] = x
        result = self._controller.evaluate(values, out_of_range="ignore")
        for j, name in enumerate(self._outputs, start=1):
            y = float(result[name])
            if not math.isnan(y):  # 1.5: no rule fired -> the last value stays
                setattr(self, _OUT_ATTRS[j - 1], real(y))
        return Info.OK
