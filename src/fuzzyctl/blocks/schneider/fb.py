"""The Schneider/Telemecanique XFUZ function block (OFB-FUZZY manual, chapter 2).

An :class:`XfuzFB` holds the parameters and internal data of section 2.3 under their
manual names, all 16-bit integers or bits, and behaves as section 2.6 describes at each
call of :meth:`XfuzFB.execute`:

* cold restart (construction or :meth:`cold_restart`) and a rising edge of INIT: the ``$``
  constants are copied into their internal data, OUTi, Oi_MAN and Oi_CALC take Oi_DEF$,
  every other internal datum is 0 (MANUAL mode, START = 0) and the knowledge base is
  copied and checked;
* warm restart: nothing;
* rising edge of REFRESH: as a cold restart but the other internal data keep their values
  (MAN_AUTO, START, DEGRE, STATUS bits 0-6 of the last inference);
* otherwise the nominal cycle of the Grafcet: read INPi or, for each bit 0-7 of COMMAND,
  Ii_SIM; run the inferences on a rising edge of START (CONT_ASK = 1, on demand) or every
  T_OFB while START = 1 (CONT_ASK = 0, continuous, T_OFB rounded to a multiple of the task
  period); put Oi_MAN (MAN_AUTO = 0) or Oi_CALC (MAN_AUTO = 1) on the outputs.

STATUS and ERROR follow 2.4: bits 0-5 default value on OUT1-6, bit 6 no active rule
(masked by COMMAND bit 8), bits 7-14 errors, which raise ERROR unless INHIB = 1 and block
the inferences.  OP_ET, OP_IMPL, OP_DEFUZ and OUT_PT are read at every inference; the
knowledge base only on cold restart, INIT and REFRESH (2.8).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from fuzzyctl.blocks.schneider.inference import InferenceResult, XfuzInference, to_word
from fuzzyctl.diagnostics import InputError
from fuzzyctl.formats.xfuz.tables import (
    ERROR_BITS,
    INT16_MAX,
    INT16_MIN,
    KbIssue,
    KnowledgeBase,
    StatusBit,
    XfuzConstants,
    decode_kb,
)

__all__ = ["XfuzFB", "XfuzSnapshot"]

N_IN, N_OUT, N_RULES = 8, 6, 64
DEGRE_FULL = 255
"""DEGRE holds a rule's degree 0..1 as 0..255, rounded (2.3)."""
_ARRAYS = {"INP": N_IN, "OUT": N_OUT, "I_SIM": N_IN, "O_CALC": N_OUT, "O_MAN": N_OUT, "O_DEF": N_OUT}
_BITS = ("INIT", "MAN_AUTO", "CONT_ASK", "START", "REFRESH", "INHIB")
_WORDS = ("T_OFB", "MONITOR", "COMMAND")
ERROR_MASK = sum(1 << b for b in ERROR_BITS)


def _array_key(name: str) -> tuple[str, int] | None:
    """``"INP3"`` -> ("INP", 2), ``"O2_CALC"`` -> ("O_CALC", 1), ``"I5_SIM"`` -> ("I_SIM", 4)."""
    upper = name.upper()
    for prefix in ("INP", "OUT"):
        if upper.startswith(prefix) and upper[len(prefix) :].isdigit():
            return prefix, int(upper[len(prefix) :]) - 1
    if len(upper) >= 3 and upper[0] in "IO" and upper[1].isdigit() and upper[2] == "_":
        return f"{upper[0]}_{upper[3:]}", int(upper[1]) - 1
    return None


@dataclass(frozen=True)
class XfuzSnapshot:
    """The visible state after one call, for logs and the CLI."""

    out: tuple[int, ...]
    o_calc: tuple[int, ...]
    status: int
    error: bool
    inferred: bool
    degre: tuple[int, ...]


class XfuzFB:
    """One XFUZ instance.

    Read and write parameters by their manual names: ``fb["INP1"] = 120``,
    ``fb["O3_MAN"]``, ``fb.MAN_AUTO = 1``, ``fb.START = 1``, ``fb.COMMAND = 0x101``.
    ``fb.constants`` holds the internal constants (:class:`XfuzConstants`); assign a new
    value and raise REFRESH (or INIT) to load a new knowledge base, as in PL7-3.

    ``task_period`` is the period of the task that calls the block, in seconds; the task
    runner passes it to :meth:`execute` each cycle.

    ``span_rule=False`` stops enforcing "BorneSup - BorneInf >= 2 (Discr - 1)" (STATUS bit
    9), which the manual's own example breaks; Discr must still be 3..20."""

    def __init__(
        self, constants: XfuzConstants | None = None, *, task_period: float = 0.01, span_rule: bool = True
    ) -> None:
        if task_period <= 0:
            raise ValueError("task_period must be positive")
        self.constants = constants or XfuzConstants()
        self.task_period = task_period
        self.span_rule = span_rule
        # Parameters and internal data (2.3).
        self.arrays: dict[str, list[int]] = {k: [0] * n for k, n in _ARRAYS.items()}
        self.INIT = self.MAN_AUTO = self.CONT_ASK = self.START = self.REFRESH = self.INHIB = 0
        self.T_OFB = self.MONITOR = self.COMMAND = 0
        self.ERROR = False
        self.STATUS = 0
        self.DEGRE = [0] * N_RULES
        # Private data: the knowledge base copy and the edge/period memories.
        self._kb = KnowledgeBase()
        self._inference = XfuzInference(self._kb)
        self._kb_status = 0
        self._info_status = 0
        self._prev = {"INIT": 0, "REFRESH": 0, "START": 0}
        self._count = 0
        self.last_result: InferenceResult | None = None
        self.inferred = False
        self.cold_restart()

    # ----------------------------------------------------------------- named access

    def __getitem__(self, name: str) -> int:
        key = _array_key(name)
        if key and key[0] in self.arrays and 0 <= key[1] < len(self.arrays[key[0]]):
            return self.arrays[key[0]][key[1]]
        if name.upper() in _BITS + _WORDS:
            return int(getattr(self, name.upper()))
        if name.upper() in ("STATUS", "ERROR"):
            return int(getattr(self, name.upper()))
        if name.upper().startswith("DEGRE"):
            return self.DEGRE[int(name[5:].strip("[]"))]
        raise KeyError(f"XFUZ has no parameter {name!r}")

    def __setitem__(self, name: str, value: int) -> None:
        key = _array_key(name)
        if key and key[0] in self.arrays and 0 <= key[1] < len(self.arrays[key[0]]):
            if key[0] in ("OUT", "O_CALC"):
                raise KeyError(f"{name} is computed by the block (access 1: read only)")
            self.arrays[key[0]][key[1]] = _word(name, value)
            return
        upper = name.upper()
        if upper in _BITS:
            setattr(self, upper, _bit(upper, value))
        elif upper in _WORDS:
            setattr(self, upper, _word(upper, value))
        else:
            raise KeyError(f"XFUZ has no writable parameter {name!r}")

    def set(self, values: Mapping[str, Any]) -> None:
        """Write several parameters by name (``{"INP1": 12, "START": 1}``)."""
        for name, value in values.items():
            self[name] = value

    @property
    def kb(self) -> KnowledgeBase:
        """The private copy of the knowledge base (loaded on cold restart, INIT, REFRESH)."""
        return self._kb

    @property
    def kb_issues(self) -> tuple[KbIssue, ...]:
        """The findings of the 2.8 checks at the last load."""
        return self._kb.issues

    # ----------------------------------------------------------------- modes (2.6)

    def _load_constants(self) -> None:
        c = self.constants
        self.CONT_ASK = int(c.contask)
        self.T_OFB = c.t_ofb
        for i in range(N_OUT):
            self.arrays["O_DEF"][i] = c.o_def[i]
            self.arrays["OUT"][i] = self.arrays["O_MAN"][i] = self.arrays["O_CALC"][i] = c.o_def[i]
        self._kb = decode_kb(c, span_rule=self.span_rule)
        self._inference = XfuzInference(self._kb)
        self._kb_status = sum(1 << b for b in self._kb.error_bits)
        self._count = 0  # the T_OFB period starts again with the new knowledge base
        self._update_status()

    def cold_restart(self) -> None:
        """2.6-1: ``$`` constants into internal data, outputs to Oi_DEF$, other data to 0,
        knowledge base copied and checked."""
        self.INIT = self.MAN_AUTO = self.START = self.REFRESH = self.INHIB = 0
        self.MONITOR = self.COMMAND = 0
        self.arrays["I_SIM"] = [0] * N_IN
        self._prev = {"INIT": 0, "REFRESH": 0, "START": 0}
        # "All the other internal data are set to 0": the inference's information (STATUS
        # bits 0-6, DEGRE) too.
        self._info_status = 0
        self.DEGRE = [0] * N_RULES
        self._load_constants()

    def warm_restart(self) -> None:
        """2.6-2: no special processing; the block continues in its previous state."""

    def refresh(self) -> None:
        """2.6-4 (what a rising edge of REFRESH does): ``$`` constants and the knowledge
        base reloaded, "all the other internal data keep their values": MAN_AUTO, START,
        and the last inference's DEGRE and STATUS bits 0-6 (default
        value on OUTi, no active rule), until the next inference recomputes them.  STATUS
        bits 7-14 are the new knowledge base's checks (2.8)."""
        self._load_constants()

    # ----------------------------------------------------------------- the cycle (2.6-5)

    def execute(self, task_period: float | None = None) -> XfuzSnapshot:
        """One call of the block by its task (``exec``); returns what it shows afterwards."""
        period = task_period if task_period is not None else self.task_period
        if period <= 0:
            raise ValueError("task_period must be positive")
        self.task_period = period
        self._validate()
        self.inferred = False
        init, refresh = self.INIT, self.REFRESH
        if init and not self._prev["INIT"]:
            self.cold_restart()  # clears INIT, so the next 0 -> 1 is an edge again
            self._assign_outputs()
        elif refresh and not self._prev["REFRESH"]:
            self.refresh()
            self._prev["REFRESH"] = 1
        else:
            self._prev["REFRESH"] = refresh
            self._nominal(period)
        self._prev["INIT"] = self.INIT
        self._update_status()
        return self.snapshot()

    def _nominal(self, period: float) -> None:
        inputs = [
            self.arrays["I_SIM"][i] if self.COMMAND >> i & 1 else self.arrays["INP"][i] for i in range(N_IN)
        ]
        cycles = self._round_period(period)
        start_edge = bool(self.START) and not self._prev["START"]
        self._prev["START"] = self.START
        run = False
        if self.CONT_ASK:
            run = start_edge
            self._count = 0
        elif self.START:
            self._count += 1
            if self._count >= cycles:
                run, self._count = True, 0
        else:
            self._count = 0
        if run and not self._kb_status:
            self._infer(inputs)
        self._assign_outputs()

    def _round_period(self, period: float) -> int:
        """T_OFB (hundredths of a second) as a whole number of task cycles, at least one;
        T_OFB is rewritten to that multiple of the period (2.3, 3.1)."""
        cycles = max(1, math.floor(self.T_OFB / 100.0 / period + 0.5))
        self.T_OFB = min(INT16_MAX, math.floor(cycles * period * 100.0 + 0.5))
        return cycles

    def _infer(self, inputs: list[int]) -> None:
        c = self.constants
        result = self._inference.run(
            inputs, op_et=c.op_et, op_impl=c.op_impl, op_defuz=c.op_defuz, out_pt=c.out_pt
        )
        self.last_result = result
        self.inferred = True
        info = 0
        for number, value in result.outputs.items():
            if value is None:
                self.arrays["O_CALC"][number - 1] = self.arrays["O_DEF"][number - 1]
                info |= 1 << (number - 1)
            else:
                self.arrays["O_CALC"][number - 1] = to_word(value)
        if not result.any_active and not self.COMMAND >> 8 & 1:
            info |= 1 << StatusBit.NO_ACTIVE_RULE
        self._info_status = info
        self.DEGRE = [min(DEGRE_FULL, math.floor(DEGRE_FULL * d + 0.5)) for d in result.degrees]
        self.DEGRE += [0] * (N_RULES - len(self.DEGRE))

    def _assign_outputs(self) -> None:
        source = "O_CALC" if self.MAN_AUTO else "O_MAN"
        self.arrays["OUT"] = list(self.arrays[source])

    def _update_status(self) -> None:
        info = self._info_status
        if self.COMMAND >> 8 & 1:
            info &= ~(1 << StatusBit.NO_ACTIVE_RULE)
        self.STATUS = self._kb_status | info
        self.ERROR = bool(self.STATUS & ERROR_MASK) and not self.INHIB

    def _validate(self) -> None:
        for name, values in self.arrays.items():
            for i, v in enumerate(values):
                _word(name.replace("_", f"{i + 1}_", 1) if "_" in name else f"{name}{i + 1}", v)
        for name in _BITS:
            _bit(name, getattr(self, name))
        for name in _WORDS:
            _word(name, getattr(self, name))

    def snapshot(self) -> XfuzSnapshot:
        return XfuzSnapshot(
            tuple(self.arrays["OUT"]),
            tuple(self.arrays["O_CALC"]),
            self.STATUS,
            self.ERROR,
            self.inferred,
            tuple(self.DEGRE),
        )

    @property
    def status_bits(self) -> tuple[int, ...]:
        """The numbers of the STATUS bits that are set."""
        return tuple(b for b in range(16) if self.STATUS >> b & 1)


def _word(name: str, value: object) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not INT16_MIN <= value <= INT16_MAX:
        if isinstance(value, float) and value.is_integer() and INT16_MIN <= value <= INT16_MAX:
            return int(value)
        raise InputError(f"{name} = {value!r}: XFUZ words are 16-bit integers (-32768..32767)")
    return value


def _bit(name: str, value: object) -> int:
    if isinstance(value, int) and value in (0, 1):
        return int(value)
    raise InputError(f"{name} = {value!r}: a bit is 0 or 1")
