"""Names of the generated interface: the model's names where the target allows them, else a
legal replacement, listed in a rename table (header comment, ``--json``).

A model may name a variable ``time`` or ``len`` (reserved in IEC 61131-3, TwinCAT, CODESYS or
SCL), ``dV*``, ``Amplitude Slope`` or ``sugeno tipper`` (not identifiers), or use more
characters than a portable PLC name may have.  Such a name is replaced by the nearest legal
one: every character that cannot be in an identifier becomes ``_`` (runs collapse, no
leading or trailing ``_``), a name that is a reserved word or starts with a digit gets a
suffix or prefix telling what it is (``time_IN``, ``OUT_1x``), a long name is cut, and a
number keeps two replacements apart (names are compared case-insensitively: ST ignores case).
The rules are the target's (:attr:`fuzzyctl.kinds.targets.Target.identifiers`); the result
still goes through its check (:func:`fuzzyctl.escape.st_ident` / :func:`~fuzzyctl.escape.c_ident`)
when printed, so the table can never let an illegal name through.
"""

from __future__ import annotations

import dataclasses
import re
import unicodedata
from dataclasses import dataclass

from fuzzyctl.engine.plan import Plan
from fuzzyctl.escape import CodegenError
from fuzzyctl.ir.state import PREFIX, Target
from fuzzyctl.kinds import targets

#: Names the generated block declares itself.
_OWN = ("ENABLE", "INFO")
#: What each kind of name becomes when it is a reserved word (suffix) or starts with a digit
#: (prefix).
_TAG = {"function block": "FB", "input": "IN", "output": "OUT", "variable": "VAR"}


@dataclass(frozen=True)
class Rename:
    """One renamed name: ``kind`` is ``function block``, ``input``, ``output`` or ``variable``
    (a local variable with DEFUZZIFY)."""

    kind: str
    original: str
    name: str
    reason: str

    def to_dict(self) -> dict[str, str]:
        return dataclasses.asdict(self)

    def comment(self) -> str:
        return f"{self.kind} {self.original!r} is {self.name} ({self.reason})"


def _legal(name: str, target: Target) -> str | None:
    """Why ``name`` cannot be used as is, or None."""
    if name.upper().startswith(PREFIX) or name.upper() in _OWN:
        return "the generated code uses this name"
    ids = targets.get(target).identifiers
    try:
        ids.check(name, "name")
        if len(name) > ids.interface_length:  # C: NAME_step, NAME_real, ...
            raise CodegenError("too long")
    except CodegenError as exc:
        text = str(exc)
        if "reserved word" in text or "keyword" in text or "reserved to the C" in text:
            return "a reserved word of the target"
        if "longer" in text or "too long" in text:
            return "too long"
        return "not an identifier of the target"
    return None


def _candidate(name: str, kind: str, target: Target) -> str:
    ascii_ = unicodedata.normalize("NFKD", name).encode("ascii", "ignore").decode()
    s = re.sub(r"[^A-Za-z0-9]+", "_", ascii_).strip("_")
    tag = _TAG[kind]
    if not s:
        s = tag
    if s[0].isdigit() or s.upper().startswith(PREFIX):
        s = f"{tag}_{s}"
    limit = targets.get(target).identifiers.interface_length
    if len(s) > limit:
        s = s[:limit].rstrip("_")
    if _legal(s, target) is not None:
        s = f"{s[: limit - len(tag) - 1].rstrip('_')}_{tag}"
    return s


def rename_plan(plan: Plan, target: Target) -> tuple[Plan, list[Rename]]:
    """``plan`` with its function block, input and output names legal for ``target``
    (``st`` or ``c``), and the table of what changed (empty when every name is legal)."""
    taken: set[str] = set()
    table: list[Rename] = []

    def one(name: str, kind: str) -> str:
        reason = _legal(name, target)
        if reason is None and name.upper() not in taken:
            taken.add(name.upper())
            return name
        if reason is None:
            reason = "another name differs from it only in letter case"
        base = _candidate(name, kind, target)
        new, k = base, 1
        limit = targets.get(target).identifiers.interface_length
        while new.upper() in taken or _legal(new, target) is not None:
            k += 1
            new = f"{base[: limit - len(str(k)) - 1].rstrip('_')}_{k}"
            if k > 1000:  # cannot happen with the rules above; never loop forever
                new = f"{_TAG[kind]}_{len(taken) + 1}"
                break
        taken.add(new.upper())
        table.append(Rename(kind, name, new, reason))
        return new

    block = one(plan.name or "FUZZY", "function block")
    taken.clear()  # the block's name is in another namespace than its variables
    inputs = tuple(dataclasses.replace(i, name=one(i.name, "input")) for i in plan.inputs)
    outputs = tuple(
        dataclasses.replace(o, name=one(o.name, "output" if o.is_output else "variable"))
        for o in plan.outputs
    )
    if not table:
        return plan, []
    return dataclasses.replace(plan, name=block, inputs=inputs, outputs=outputs), table
