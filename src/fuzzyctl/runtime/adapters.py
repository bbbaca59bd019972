"""One interface over the two block styles, so that the instance's cycle, the safety logic
and the API do not care which PLC family a block comes from.

Parameters keep their manual names (``INPUT1``, ``START_STOP``, ``INP3``, ``O2_MAN``...);
controller variables are accepted wherever an input or output is meant.  The adapters
convert between the field's floats and the block's types (S7 REAL; XFUZ 16-bit words:
rounded half away from zero and saturated, manual 2.3) and add the runtime's I/O fault
indication to INFO / STATUS (docs/runtime.md, "Safety"):

* Siemens: INFO = 16#40 while an instance holds its last good inputs, 16#41 while its
  outputs are at their safe values, 16#42 while they are because the block cannot compute
  (an error, a result that is not a finite REAL); the block's own codes are 00, 01, 11,
  21, 31;
* XFUZ: STATUS bit 15 (unused by the manual) and ERROR while the outputs are at their safe
  values, for either reason.

A value the API forces or sets is refused when the block's type cannot hold it: a Siemens
input is a REAL (finite, at most 3.4028235e38 in magnitude), an XFUZ input or manual
value a 16-bit integer.
"""

from __future__ import annotations

import math
import re
from typing import Any, ClassVar

from fuzzyctl.blocks.siemens.fb import real
from fuzzyctl.diagnostics import InputError
from fuzzyctl.runtime.kb import PreparedKB

__all__ = [
    "INFO_BLOCK_FAULT",
    "INFO_HOLD",
    "INFO_SAFE",
    "STATUS_IO_FAULT_BIT",
    "Adapter",
    "NotSupported",
    "SiemensAdapter",
    "XfuzAdapter",
    "make_adapter",
]

INFO_HOLD = 0x40
INFO_SAFE = 0x41
INFO_BLOCK_FAULT = 0x42
STATUS_IO_FAULT_BIT = 15
REAL_LIMIT = 2.0**128 - 2.0**103
"""The smallest magnitude that an S7 REAL (IEEE single) cannot hold: it rounds to infinity."""


class NotSupported(InputError):
    """The block style has no such operation (MAN_AUTO on a Siemens block, ...)."""


def exact_word(what: str, value: float) -> int:
    """A value an operator gives for an XFUZ word: an integer -32768..32767, else refused
    (the field's values are rounded and saturated instead, see :func:`to_word`)."""
    if not (math.isfinite(value) and float(value).is_integer() and -32768 <= value <= 32767):
        raise InputError(f"{what}: {value!r} is not a 16-bit integer (-32768..32767)")
    return int(value)


def to_word(value: float) -> int:
    """A field value as an XFUZ word: rounded half away from zero, saturated to INT16."""
    if math.isnan(value):
        raise InputError("NaN is not a 16-bit word")
    if math.isinf(value):
        return 32767 if value > 0 else -32768
    n = math.floor(abs(value) + 0.5) * (1 if value >= 0 else -1)
    return int(min(max(n, -32768), 32767))


class Adapter:
    """What the runtime needs from a block.  ``fault`` is set by the instance: None,
    ``"hold"``, ``"safe"`` or ``"block"`` (the block cannot compute)."""

    style: ClassVar[str]
    PARAMS: ClassVar[dict[str, tuple[int, int]]] = {}
    INPUT_LIMIT: ClassVar[float] = math.inf
    """Field values of this magnitude or more (and NaN) are not inputs the block can read."""
    fault: str | None = None
    block: Any

    def __init__(self, kb: PreparedKB) -> None:
        self.kb = kb

    # --- names (against the current knowledge base, or ``kb`` for a download to come)
    def input_key(self, name: str, kb: PreparedKB | None = None) -> str:
        raise NotImplementedError

    def output_key(self, name: str, kb: PreparedKB | None = None) -> str:
        raise NotImplementedError

    def param_key(self, name: str) -> str:
        raise NotImplementedError

    def describe_inputs(self) -> str:
        raise NotImplementedError

    # --- values
    def write_input(self, key: str, value: float) -> None:
        raise NotImplementedError

    def read_output(self, key: str) -> float:
        raise NotImplementedError

    def get_param(self, key: str) -> int:
        raise NotImplementedError

    def set_param(self, key: str, value: float) -> None:
        self.check_param(key, value)
        self._set_param(key, int(value))

    def check_param(self, key: str, value: float) -> None:
        """Raise InputError when ``value`` is not valid for parameter ``key``."""
        low, high = self.PARAMS[key]
        if not (math.isfinite(value) and float(value).is_integer() and low <= value <= high):
            raise InputError(f"{key} = {value!r}: must be an integer {low}..{high}")

    def _set_param(self, key: str, value: int) -> None:
        raise NotImplementedError

    def execute(self, period: float) -> None:
        raise NotImplementedError

    def install(self, kb: PreparedKB) -> None:
        """Switch to a prepared knowledge base (called between two cycles)."""
        raise NotImplementedError

    def before_cycle(self) -> bool:
        """Called before each execute; True when a download takes effect in this call."""
        return False

    def after_cycle(self) -> None:
        """Called after each execute (XFUZ lowers the REFRESH it raised)."""

    def bad_output(self) -> str | None:
        """``"OUTPUTn = inf"`` when the last call left an output the block cannot put out
        (not a finite value of its type); None when all are fine."""
        return None

    @property
    def status(self) -> dict[str, int]:
        """INFO (siemens) or STATUS/ERROR (xfuz), with the runtime's fault indication."""
        raise NotImplementedError

    @property
    def ok(self) -> bool:
        """Whether the block computed normally in its last call."""
        raise NotImplementedError

    def values(self) -> dict[str, float]:
        """Every parameter worth showing, by manual name."""
        raise NotImplementedError

    def force(self, key: str, value: float | None) -> None:
        """Force an input (None releases it)."""
        raise NotImplementedError

    def forced(self) -> dict[str, float]:
        raise NotImplementedError

    def set_manual(self, key: str, value: float) -> None:
        raise NotSupported(f"{self.style} blocks have no manual outputs (XFUZ Oi_MAN)")

    def set_mode(self, auto: bool) -> None:
        raise NotSupported(f"{self.style} blocks have no MAN_AUTO (an XFUZ parameter); use START_STOP")


def _lookup(name: str, labels: dict[str, str], pattern: str, what: str, valid: str) -> str:
    if name in labels and re.fullmatch(pattern, labels[name]):
        return labels[name]
    if re.fullmatch(pattern, name.upper()):
        return name.upper()
    raise InputError(f"{name!r} is not {what} of this block ({valid})")


class SiemensAdapter(Adapter):
    """Siemens FUZZY (FB30): INPUT1..8, OUTPUT1..4, INFO, ENO; START_STOP is a parameter.
    The block has no forcing; the runtime forces an input by replacing the field value
    before the block reads it, as a CPU's force table does."""

    style = "siemens"
    PARAMS: ClassVar[dict[str, tuple[int, int]]] = {"START_STOP": (0, 0xFFFF)}
    INPUT_LIMIT = REAL_LIMIT

    def __init__(self, kb: PreparedKB) -> None:
        super().__init__(kb)
        self.block = kb.block
        self._forced: dict[str, float] = {}

    def _valid_inputs(self, kb: PreparedKB | None = None) -> str:
        return ", ".join((kb or self.kb).inputs) + " or INPUT1..INPUT8"

    def input_key(self, name: str, kb: PreparedKB | None = None) -> str:
        labels = (kb or self.kb).labels
        return _lookup(name, labels, r"INPUT[1-8]", "an input", self._valid_inputs(kb))

    def output_key(self, name: str, kb: PreparedKB | None = None) -> str:
        if name.upper() in ("INFO", "ENO"):
            return name.upper()
        k = kb or self.kb
        return _lookup(
            name,
            k.labels,
            r"OUTPUT[1-4]",
            "an output",
            ", ".join(k.outputs) + ", OUTPUT1..OUTPUT4, INFO or ENO",
        )

    def param_key(self, name: str) -> str:
        if name.upper() in self.PARAMS:
            return name.upper()
        raise InputError(f"{name!r} is not a parameter of a Siemens FUZZY block (START_STOP)")

    def describe_inputs(self) -> str:
        return self._valid_inputs()

    def write_input(self, key: str, value: float) -> None:
        # The key is the data block's variable (INPUTn); the block reads it as a REAL.
        if self._forced:
            value = self._forced.get(key, value)
        setattr(self.block, key, real(value))

    def read_output(self, key: str) -> float:
        if key == "INFO":
            return float(self.status["INFO"])
        if key == "ENO":
            return float(self.block.ENO)
        return float(getattr(self.block, key))

    def bad_output(self) -> str | None:
        block = self.block
        for i in range(1, len(self.kb.outputs) + 1):
            y = block.read_output(i)
            if not math.isfinite(y):
                return f"OUTPUT{i} = {y!r}"
        return None

    def get_param(self, key: str) -> int:
        return int(getattr(self.block, key))

    def _set_param(self, key: str, value: int) -> None:
        setattr(self.block, key, value)

    def execute(self, period: float) -> None:
        for key, value in self._forced.items():  # bound or not, a forced input holds its value
            setattr(self.block, key, value)
        self.block.execute()

    def install(self, kb: PreparedKB) -> None:
        # The configuration tool's procedure (manual 3.1): stop the block, transfer, restart.
        old, new = self.block, kb.block
        old.START_STOP = 0
        for i in range(1, 9):
            new.write_input(i, old.inputs[i - 1])
        for i in range(1, 5):
            setattr(new, f"OUTPUT{i}", old.outputs[i - 1])  # the DB keeps its output values
        new.START_STOP = 0xFFFF
        self.block, self.kb = new, kb
        self._forced = {}

    @property
    def status(self) -> dict[str, int]:
        info = int(self.block.INFO)
        if self.fault == "block":
            info = INFO_BLOCK_FAULT
        elif self.fault == "safe":
            info = INFO_SAFE
        elif self.fault == "hold" and info == 0:
            info = INFO_HOLD
        return {"INFO": info}

    @property
    def ok(self) -> bool:
        return bool(self.block.ENO)

    def values(self) -> dict[str, float]:
        b = self.block
        out: dict[str, float] = {f"INPUT{i}": b.inputs[i - 1] for i in range(1, len(self.kb.inputs) + 1)}
        out |= {f"OUTPUT{i}": b.outputs[i - 1] for i in range(1, len(self.kb.outputs) + 1)}
        out |= {"INFO": self.status["INFO"], "START_STOP": b.START_STOP, "ENO": int(b.ENO)}
        return out

    def force(self, key: str, value: float | None) -> None:
        if value is None:
            self._forced.pop(key, None)
        elif not abs(value) < REAL_LIMIT:  # also NaN
            raise InputError(f"force {key}: {value!r} is not a REAL (finite, |x| <= 3.4028235e38)")
        else:
            self._forced[key] = real(value)

    def forced(self) -> dict[str, float]:
        return dict(self._forced)


_XFUZ_PARAMS: dict[str, tuple[int, int]] = {
    "MAN_AUTO": (0, 1), "CONT_ASK": (0, 1), "START": (0, 1), "INHIB": (0, 1), "INIT": (0, 1),
    "T_OFB": (0, 32767), "MONITOR": (-32768, 32767), "COMMAND": (-32768, 32767),
    **{f"O{i}_MAN": (-32768, 32767) for i in range(1, 7)},
    **{f"O{i}_DEF": (-32768, 32767) for i in range(1, 7)},
    **{f"I{i}_SIM": (-32768, 32767) for i in range(1, 9)},
}  # fmt: skip


class XfuzAdapter(Adapter):
    """Schneider XFUZ: INP1..8, OUT1..6, Oi_CALC, STATUS, ERROR; the rw parameters of
    manual 2.3 (MAN_AUTO, START, COMMAND, Oi_MAN, Ii_SIM, ...).  REFRESH is the runtime's:
    a download raises it for one cycle (manual 2.6-4)."""

    style = "xfuz"
    PARAMS: ClassVar[dict[str, tuple[int, int]]] = _XFUZ_PARAMS

    def __init__(self, kb: PreparedKB, period: float, span_rule: bool) -> None:
        from fuzzyctl.blocks.schneider import XfuzFB

        super().__init__(kb)
        self.block = XfuzFB(kb.block, task_period=period, span_rule=span_rule)
        self._pending: PreparedKB | None = None
        self._raised = False  # REFRESH raised by us in this call
        self._low_seen = True  # a call has seen REFRESH = 0 since we last raised it

    def _valid_inputs(self, kb: PreparedKB | None = None) -> str:
        names = [n for n, lab in (kb or self.kb).labels.items() if lab.startswith("INP")]
        return ", ".join(names) + " or INP1..INP8"

    def input_key(self, name: str, kb: PreparedKB | None = None) -> str:
        labels = (kb or self.kb).labels
        return _lookup(name, labels, r"INP[1-8]", "an input", self._valid_inputs(kb))

    def output_key(self, name: str, kb: PreparedKB | None = None) -> str:
        if name.upper() in ("STATUS", "ERROR"):
            return name.upper()
        if re.fullmatch(r"O[1-6]_CALC", name.upper()):
            return name.upper()
        k = kb or self.kb
        outs = [n for n, lab in k.labels.items() if lab.startswith("OUT")]
        return _lookup(
            name,
            k.labels,
            r"OUT[1-6]",
            "an output",
            ", ".join(outs) + ", OUT1..OUT6, O1_CALC..O6_CALC, STATUS or ERROR",
        )

    def param_key(self, name: str) -> str:
        if name.upper() in self.PARAMS:
            return name.upper()
        raise InputError(
            f"{name!r} is not a writable XFUZ parameter (MAN_AUTO, CONT_ASK, START, INHIB, INIT, "
            "T_OFB, MONITOR, COMMAND, Oi_MAN, Oi_DEF, Ii_SIM; REFRESH is raised by a download)"
        )

    def describe_inputs(self) -> str:
        return self._valid_inputs()

    def write_input(self, key: str, value: float) -> None:
        self.block[key] = to_word(value)

    def read_output(self, key: str) -> float:
        if key in ("STATUS", "ERROR"):
            return float(self.status[key])
        return float(self.block[key])

    def get_param(self, key: str) -> int:
        return int(self.block[key])

    def _set_param(self, key: str, value: int) -> None:
        self.block[key] = value

    def execute(self, period: float) -> None:
        self.block.execute(period)

    def install(self, kb: PreparedKB) -> None:
        # PL7-3's way (manual 2.6-4): new constants, then a rising edge of REFRESH; the
        # block copies the whole knowledge base in that call.  A later download replaces
        # a pending one.
        self._pending = kb

    def before_cycle(self) -> bool:
        # An edge needs a call that saw REFRESH = 0 since the last one we raised.
        if self._pending is None or not self._low_seen:
            return False
        kb, self._pending = self._pending, None
        self.block.constants = kb.block
        self.block.REFRESH = 1
        self.kb = kb
        self._raised, self._low_seen = True, False
        return True

    def after_cycle(self) -> None:
        if self._raised:
            self.block.REFRESH = 0
            self._raised = False
        elif not self.block.REFRESH:
            self._low_seen = True

    @property
    def refresh_pending(self) -> bool:
        return self._pending is not None

    @property
    def status(self) -> dict[str, int]:
        status, error = int(self.block.STATUS), bool(self.block.ERROR)
        if self.fault in ("safe", "block"):
            status |= 1 << STATUS_IO_FAULT_BIT
            error = True
        return {"STATUS": status - 0x10000 if status >= 0x8000 else status, "ERROR": int(error)}

    @property
    def ok(self) -> bool:
        return not self.block.ERROR

    def values(self) -> dict[str, float]:
        b = self.block
        used_in = sorted({lab for lab in self.kb.labels.values() if lab.startswith("INP")})
        used_out = sorted({lab for lab in self.kb.labels.values() if lab.startswith("OUT")})
        out: dict[str, float] = {k: b[k] for k in used_in}
        out |= {k: b[k] for k in used_out}
        out |= {f"O{k[3:]}_CALC": b[f"O{k[3:]}_CALC"] for k in used_out}
        out |= {f"O{k[3:]}_MAN": b[f"O{k[3:]}_MAN"] for k in used_out}
        out |= self.status
        out |= {k: b[k] for k in ("MAN_AUTO", "CONT_ASK", "START", "INHIB", "T_OFB", "COMMAND")}
        return out

    def force(self, key: str, value: float | None) -> None:
        # Manual 2.3: COMMAND bit i-1 makes the block read Ii_SIM instead of INPi.
        i = int(key[3:])
        bit = 1 << (i - 1)
        command = self.block.COMMAND & 0xFFFF
        if value is None:
            command &= ~bit
        else:
            self.block[f"I{i}_SIM"] = exact_word(f"force {key}", value)
            command |= bit
        self.block.COMMAND = command - 0x10000 if command >= 0x8000 else command

    def forced(self) -> dict[str, float]:
        b = self.block
        return {f"INP{i}": float(b[f"I{i}_SIM"]) for i in range(1, 9) if b.COMMAND >> (i - 1) & 1}

    def set_manual(self, key: str, value: float) -> None:
        self.block[f"O{key[3:]}_MAN"] = exact_word(f"O{key[3:]}_MAN", value)

    def set_mode(self, auto: bool) -> None:
        self.block.MAN_AUTO = int(auto)


def make_adapter(kb: PreparedKB, style: str, period: float, span_rule: bool = True) -> Adapter:
    if style == "siemens":
        return SiemensAdapter(kb)
    return XfuzAdapter(kb, period, span_rule)
