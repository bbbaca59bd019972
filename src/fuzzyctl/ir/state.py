"""The state of one program being built: declarations, temporaries, names and refusals."""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass, field

from fuzzyctl.escape import MAX_IDENT_ST as MAX_IDENT
from fuzzyctl.escape import CodegenError
from fuzzyctl.ir.nodes import Builder, Decl, Ex, ExLike, Storage, Type, Var, ex
from fuzzyctl.kinds import targets

#: A program builder's target, a key of :data:`fuzzyctl.kinds.targets.TARGETS` whose
#: ``language`` is itself: "c" and "st" the PLC function block; "py", "np" and "c" also the
#: evaluator of ``compile()``.  What the target can express is its capabilities record
#: (:attr:`Gen.caps`).
Target = str

#: Every generated identifier starts with this prefix (user names never do: checked).
PREFIX = "FZ_"


__all__ = ["MAX_IDENT", "PREFIX", "CodegenError", "Gen", "Target", "flat"]


@dataclass
class Gen:
    """Declarations and statements of one function block under construction."""

    target: Target
    b: Builder = field(default_factory=Builder)
    decls: list[Decl] = field(default_factory=list)
    names: set[str] = field(default_factory=set)  # upper-cased: ST is case-insensitive
    uses: set[str] = field(default_factory=set)
    _counter: int = 0
    _free: dict[Type, list[str]] = field(default_factory=dict)

    @property
    def caps(self) -> targets.Target:
        """The capabilities record of the target."""
        return targets.get(self.target)

    # ------------------------------------------------------------------ names

    def fresh(self, preferred: str, fallback: str) -> str:
        """An unused internal identifier: ``PREFIX + preferred`` when it is short enough and
        free, else ``PREFIX + fallback + n``."""
        cand = PREFIX + re.sub(r"[^A-Za-z0-9_]", "_", preferred)
        cand = re.sub(r"_+", "_", cand)
        if len(cand) <= MAX_IDENT and cand.upper() not in self.names:
            return cand
        while True:
            self._counter += 1
            cand = f"{PREFIX}{fallback}{self._counter}"
            if cand.upper() not in self.names:
                return cand

    def named(self, what: str) -> str:
        """An unused internal identifier that says what it holds (``FZ_DEG_distance_far``):
        the model's words made identifier-safe, cut to :data:`MAX_IDENT` characters, and on a
        clash (names are case-insensitive in ST) numbered within the same limit."""
        # no trailing or double underscore (IEC 61131-3 identifiers allow neither)
        base = re.sub(r"_+", "_", PREFIX + re.sub(r"[^A-Za-z0-9_]", "_", what))[:MAX_IDENT].rstrip("_")
        if base.upper() not in self.names:
            return base
        n = 1
        while True:
            n += 1
            cand = f"{base[: MAX_IDENT - len(str(n)) - 1].rstrip('_')}_{n}"
            if cand.upper() not in self.names:
                return cand

    def temp_named(self, what: str, type_: Type = "REAL") -> Var:
        """A new temporary named by :meth:`named`."""
        return self.declare(self.named(what), type_, "temp")

    def declare(
        self,
        name: str,
        type_: Type,
        storage: Storage,
        size: int | None = None,
        init: tuple[float, ...] | float | bool | None = None,
        comment: str = "",
    ) -> Var:
        if name.upper() in self.names:
            raise CodegenError(f"identifier {name!r} is declared twice (names are case-insensitive in ST)")
        self.names.add(name.upper())
        self.decls.append(Decl(name, type_, storage, size, init, comment))
        return Var(name)

    def temp(self, type_: Type = "REAL", hint: str = "T") -> Var:
        """A new temporary scalar (never reused: keeps generated code easy to read)."""
        return self.declare(self.fresh(hint, hint), type_, "temp")

    def array(self, hint: str, type_: Type, size: int, storage: Storage = "temp") -> Var:
        return self.declare(self.fresh(hint, hint), type_, storage, max(size, 1))

    def counter(self, hint: str = "K", type_: Type = "INT") -> str:
        """An INT (or DINT) loop counter."""
        return self.declare(self.fresh(hint, hint), type_, "temp").name

    # ------------------------------------------------------------------ helpers

    def let(self, value: ExLike, hint: str = "T", type_: Type = "REAL") -> Var:
        """Assign ``value`` to a new temporary and return it."""
        v = self.temp(type_, hint)
        self.b.set(v, value)
        return v

    def let_named(self, value: ExLike, what: str, type_: Type = "REAL") -> Var:
        """:meth:`let` into a temporary named by :meth:`named`."""
        v = self.temp_named(what, type_)
        self.b.set(v, value)
        return v

    def min_(self, a: ExLike, b: ExLike, hint: str = "T") -> Var:
        """``a if a < b else b`` as an IF (the engine's MIN, no MIN() call in ST)."""
        t = self.let(b, hint)
        with self.b.if_(ex(a).lt(t)):
            self.b.set(t, a)
        return t

    def max_(self, a: ExLike, b: ExLike, hint: str = "T") -> Var:
        """``a if a > b else b`` as an IF."""
        t = self.let(b, hint)
        with self.b.if_(ex(a).gt(t)):
            self.b.set(t, a)
        return t

    def call(self, fn: str, *args: ExLike) -> Ex:
        from fuzzyctl.ir.nodes import call

        self.uses.add(fn)
        return call(fn, *args)

    def refuse(self, what: str, why: str) -> CodegenError:
        return CodegenError(f"{what}: {why} (cannot be expressed in generated {self.caps.label})")


def flat(values: Sequence[float]) -> tuple[float, ...]:
    return tuple(float(v) for v in values)
