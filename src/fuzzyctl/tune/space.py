"""The parameters a user frees, and how a vector in the unit box becomes a valid system.

Every optimiser works on ``u`` in ``[0, 1]^n``; :meth:`Space.decode` turns any such ``u``
into a function block that is valid by construction:

* **Abscissae** (points of IEC terms, the parameters the shape registry calls positions:
  triangle/trapezoid/... vertices, Gaussian means,
  singleton positions) are *breakpoints of their variable*.  Equal abscissae of one
  variable are one breakpoint (a point shared by two neighbouring terms moves in both, so a
  partition stays a partition).  Breakpoints at the ends of the universe (the RANGE, or
  without one the outermost abscissae) stay; a run of free breakpoints between two fixed
  ones is decoded as ``lo + span * (delta * (i + 1) + sort(u)_i * (1 - delta * (k + 1)))``:
  strictly increasing with a gap of at least ``delta * span``, strictly inside its
  neighbours.  Every abscissa therefore keeps its order relative to every other abscissa of
  the variable, which keeps each term's points ascending, keeps it inside the RANGE and
  keeps the union of the supports covering what it covered (coverage is a statement about
  the order of breakpoints only).
* **Scales** (Gaussian sigma, bell width and slope, sigmoid slope: the parameters whose
  role in the shape registry is not a position) move on a log scale in
  ``[v/4, 4 v]`` and keep their sign.
* **Takagi-Sugeno coefficients** move in a box around their value (see :func:`_coef_box`).
* **Weights** (WITH, rule weights) move in ``[0, 1]``.
* **Lower functions** of interval type-2 terms (:mod:`fuzzyctl.tune.type2`): scale in
  ``[0.01, 1]`` and lags in ``[0, 0.95]``, or an explicit function's parameters as above,
  projected below the upper function.

The degrees (``y``) of points stay as written.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.model import (
    SHAPES,
    DefuzzifyBlock,
    FunctionBlock,
    FuzzifyBlock,
    PointsMF,
    Range,
    Ref,
    Rule,
    RuleBlock,
    ShapeMF,
    SingletonMF,
    SingletonsMF,
    Term,
)
from fuzzyctl.tune import type2

Vector = npt.NDArray[np.float64]

#: Minimum gap between two breakpoints, as a fraction of the run they move in.
DELTA = 1e-4
#: Scales move within [v / SCALE_FACTOR, v * SCALE_FACTOR].
SCALE_FACTOR = 4.0


class SpaceError(FuzzyctlError):
    """A --free specification that names nothing tunable, or something unknown."""


# A number in the model: ("term", variable, term index, parameter index) - for points and
# SINGLETONS the parameter index is 2k for x_k -, ("with", rule block, rule, conclusion) or
# ("rule", rule block, rule).
SlotKey = tuple[str | int, ...]


@dataclass(frozen=True)
class Slot:
    """One tunable number of the model."""

    key: SlotKey
    value: float
    role: str  # "x" (abscissa), "scale", "coef", "weight"
    variable: str | None
    term: str | None
    label: str


@dataclass(frozen=True)
class Group:
    """Parameters decoded together.

    ``kind`` ``"run"``: ordered breakpoints strictly between ``lo`` and ``hi``; entry ``i`` of
    ``slots`` lists the slots at breakpoint ``i``.  ``"box"``: one number in ``[lo, hi]``.
    ``"log"``: ``value * SCALE_FACTOR ** (2 u - 1)``."""

    kind: str
    lo: float
    hi: float
    slots: tuple[tuple[SlotKey, ...], ...]
    start: int  # index of the group's first entry in u
    value: float = 0.0  # "log": the initial value

    @property
    def size(self) -> int:
        return len(self.slots)


@dataclass
class Space:
    """The free parameters of one function block (build it with :func:`build_space`)."""

    block: FunctionBlock
    slots: dict[SlotKey, Slot]
    groups: list[Group]
    free_keys: tuple[SlotKey, ...]
    notes: list[str] = field(default_factory=list)

    @property
    def size(self) -> int:
        return sum(g.size for g in self.groups)

    # ------------------------------------------------------------------ encode / decode

    def initial(self) -> Vector:
        """The ``u`` that decodes to (within ``DELTA``) the block as written."""
        u = np.empty(self.size)
        for g in self.groups:
            if g.kind == "run":
                k = g.size
                span = g.hi - g.lo
                for i, keys in enumerate(g.slots):
                    x = self.slots[keys[0]].value
                    s = ((x - g.lo) / span - DELTA * (i + 1)) / (1.0 - DELTA * (k + 1))
                    u[g.start + i] = min(1.0, max(0.0, s))
                # Clipping keeps sort order; a run never needs more.
            elif g.kind == "box":
                v = self.slots[g.slots[0][0]].value
                u[g.start] = 0.5 if g.hi == g.lo else min(1.0, max(0.0, (v - g.lo) / (g.hi - g.lo)))
            else:
                u[g.start] = 0.5
        return u

    def values(self, u: Sequence[float] | Vector) -> dict[SlotKey, float]:
        """The number each free slot takes for ``u`` (clipped to the unit box)."""
        uu = np.clip(np.asarray(u, dtype=np.float64), 0.0, 1.0)
        out: dict[SlotKey, float] = {}
        for g in self.groups:
            part = uu[g.start : g.start + g.size]
            if g.kind == "run":
                k = g.size
                span = g.hi - g.lo
                s = np.sort(part)
                for i, keys in enumerate(g.slots):
                    x = g.lo + span * (DELTA * (i + 1) + float(s[i]) * (1.0 - DELTA * (k + 1)))
                    for key in keys:
                        out[key] = x
            elif g.kind == "box":
                out[g.slots[0][0]] = g.lo + (g.hi - g.lo) * float(part[0])
            else:
                out[g.slots[0][0]] = g.value * SCALE_FACTOR ** (2.0 * float(part[0]) - 1.0)
        return out

    def derivative(self, u: Sequence[float] | Vector) -> dict[SlotKey, tuple[int, float]]:
        """For each free slot: the one entry of ``u`` it depends on and ``d slot / d u``
        (the decoding is separable: each slot moves with exactly one entry, a.e.)."""
        uu = np.clip(np.asarray(u, dtype=np.float64), 0.0, 1.0)
        out: dict[SlotKey, tuple[int, float]] = {}
        for g in self.groups:
            part = uu[g.start : g.start + g.size]
            if g.kind == "run":
                k = g.size
                scale = (g.hi - g.lo) * (1.0 - DELTA * (k + 1))
                order = np.argsort(part, kind="stable")
                for i, keys in enumerate(g.slots):
                    for key in keys:
                        out[key] = (g.start + int(order[i]), scale)
            elif g.kind == "box":
                out[g.slots[0][0]] = (g.start, g.hi - g.lo)
            else:
                v = g.value * SCALE_FACTOR ** (2.0 * float(part[0]) - 1.0)
                out[g.slots[0][0]] = (g.start, v * 2.0 * math.log(SCALE_FACTOR))
        return out

    def decode(self, u: Sequence[float] | Vector, *, digits: int | None = None) -> FunctionBlock:
        """The function block for ``u``; ``digits`` rounds each number to that many
        significant digits of its own scale (what is written to FCL)."""
        vals = self.values(u)
        if digits is not None:
            vals = {k: self._round(k, v, digits) for k, v in vals.items()}
        return apply_values(self.block, vals)

    def _round(self, key: SlotKey, v: float, digits: int) -> float:
        """``v`` to ``digits`` significant digits of its group's span (of itself for scales);
        a step of at most 1e-5 of a run cannot reorder breakpoints ``DELTA`` apart."""
        g = self._group_of(key)
        span = abs(g.hi - g.lo) if g.kind != "log" else abs(v)
        if span == 0.0 or not math.isfinite(span):
            return v
        step = 10.0 ** (math.floor(math.log10(span)) - digits + 1)
        r = float(f"{round(v / step) * step:.12g}")
        if g.kind in ("box", "run"):
            r = min(max(r, g.lo), g.hi)
        return r

    def _group_of(self, key: SlotKey) -> Group:
        for g in self.groups:
            for keys in g.slots:
                if key in keys:
                    return g
        raise KeyError(key)

    def changes(
        self, u: Sequence[float] | Vector, *, digits: int | None = None
    ) -> list[tuple[str, float, float]]:
        """``(label, before, after)`` for every parameter that changed; a breakpoint shared
        by several terms is one row naming all of them."""
        vals = self.values(u)
        rows = []
        for g in self.groups:
            for keys in g.slots:
                key = keys[0]
                after = vals[key] if digits is None else self._round(key, vals[key], digits)
                before = self.slots[key].value
                if after == before:
                    continue
                labels = [self.slots[k].label for k in keys]
                var = self.slots[key].variable
                if len(labels) > 1 and var is not None:
                    label = f"{var}: " + " = ".join(lb.removeprefix(f"{var}.") for lb in labels)
                else:
                    label = labels[0]
                rows.append((label, before, after))
        return rows


# --------------------------------------------------------------------------- building


def catalogue(fb: FunctionBlock) -> dict[SlotKey, Slot]:
    """Every number of the block that a tuner could move (constants only)."""
    slots: dict[SlotKey, Slot] = {}
    inputs = [v.name for v in fb.inputs]
    blocks: list[FuzzifyBlock | DefuzzifyBlock] = [*fb.fuzzify, *fb.defuzzify]
    for blk in blocks:
        var = blk.variable
        for ti, t in enumerate(blk.terms):
            for tkey, value, role, label in _term_slots(var, ti, t, inputs):
                slots[tkey] = Slot(tkey, value, role, var, t.name, label)
            for tkey, value, role, label in _lower_slots(var, ti, t, inputs):
                slots[tkey] = Slot(tkey, value, role, var, t.name, label)
    key: SlotKey
    for bi, rb in enumerate(fb.rule_blocks):
        for ri, rule in enumerate(rb.rules):
            if isinstance(rule.weight, float | int):
                key = ("rule", bi, ri)
                slots[key] = Slot(key, float(rule.weight), "weight", None, None, f"rule {rule.label} weight")
            for ci, c in enumerate(rule.conclusions):
                w = 1.0 if c.weight is None else c.weight
                if isinstance(w, float | int):
                    what = f"{c.variable} IS {c.term}" if c.term else c.variable
                    key = ("with", bi, ri, ci)
                    slots[key] = Slot(key, float(w), "weight", None, None, f"rule {rule.label} ({what}) WITH")
    return slots


def _num(p: object) -> float:
    assert isinstance(p, float | int)
    return float(p)


def _const(p: object) -> bool:
    return isinstance(p, float | int) and not isinstance(p, bool) and math.isfinite(float(p))


def _lower_slots(
    var: str, ti: int, t: Term, inputs: Sequence[str]
) -> Iterable[tuple[SlotKey, float, str, str]]:
    """An interval type-2 term's lower function: scale and lags, or the parameters of an
    explicit function (keyed ``("lower", var, ti, ...)``; see :mod:`fuzzyctl.tune.type2`)."""
    if t.lower is None:
        return
    if t.lower.mf is None:
        yield from type2.scale_lag_slots(var, ti, t)
        return
    for key, value, role, label in _term_slots(var, ti, Term(f"{t.name} lower", t.lower.mf), inputs):
        yield ("lower", *key[1:]), value, role, label


def _term_slots(
    var: str, ti: int, t: Term, inputs: Sequence[str]
) -> Iterable[tuple[SlotKey, float, str, str]]:
    mf = t.mf
    base = f"{var}.{t.name}"
    if isinstance(mf, PointsMF | SingletonsMF):
        if all(_const(p.x) for p in mf.points):
            for k, p in enumerate(mf.points):
                yield ("term", var, ti, 2 * k), _num(p.x), "x", f"{base} point {k + 1}"
    elif isinstance(mf, SingletonMF):
        if _const(mf.value):
            yield ("term", var, ti, 0), _num(mf.value), "x", base
    elif isinstance(mf, ShapeMF):
        shape = SHAPES.get(mf.kind)
        if shape is None or not all(_const(p) or isinstance(p, Ref) for p in mf.params):
            return  # an infinite parameter (a shoulder): kept as written
        roles = [shape.tuning[min(k, len(shape.tuning) - 1)] for k in range(len(mf.params))]  # variadic: last
        variable = [isinstance(p, Ref) for p in mf.params]
        # a parameter given by a variable stays; the term's other abscissae too when one of
        # them is a variable (their order against it is unknown), its scales move
        fixed_x = any(v and r == "abscissa" for v, r in zip(variable, roles, strict=True))
        for k, c in enumerate(mf.params):
            if variable[k]:
                continue
            v = _num(c)
            if roles[k] == "coef":
                what = f"coefficient of {inputs[k]}" if shape.variadic and k < len(inputs) else "constant"
                yield ("term", var, ti, k), v, "coef", f"{base} {what}"
            elif roles[k] == "abscissa" and math.isfinite(v) and not fixed_x:
                yield ("term", var, ti, k), v, "x", f"{base} {shape.params[k]}"
        for k, c in enumerate(mf.params):
            if not variable[k] and roles[k] in ("scale", "slope") and _num(c) != 0.0:
                yield ("term", var, ti, k), _num(c), "scale", f"{base} {shape.params[k]}"


def _universe(fb: FunctionBlock, var: str, xs: Sequence[float]) -> tuple[float, float]:
    blk = fb.fuzzify_block(var) or fb.defuzzify_block(var)
    rng: Range | None = getattr(blk, "range", None)
    decl = fb.variable(var)
    if rng is None and decl is not None:
        rng = decl.range
    if rng is not None:
        return float(rng.low), float(rng.high)
    return (min(xs), max(xs)) if xs else (0.0, 0.0)


def parse_free(
    spec: str | Sequence[str] | None, fb: FunctionBlock
) -> tuple[set[tuple[str, str]], bool, list[str]]:
    """``(variable, term)`` pairs and whether weights are free, from a specification like
    ``"all"``, ``"inputs,-angle"``, ``"distance.close,power"`` or ``"weights"``."""
    items: list[str] = []
    for part in [spec] if isinstance(spec, str) or spec is None else list(spec):
        items.extend(s.strip() for s in (part or "all").split(",") if s.strip())
    fuzz = {b.variable: [t.name for t in b.terms] for b in fb.fuzzify}
    defz = {b.variable: [t.name for t in b.terms] for b in fb.defuzzify}
    every = {**fuzz, **defz}
    terms: set[tuple[str, str]] = set()
    weights = False
    used: list[str] = []
    for raw in items:
        neg = raw.startswith("-")
        item = raw[1:].strip() if neg else raw
        if item in ("all", "*"):
            chosen = {(v, t) for v, ts in every.items() for t in ts}
            chosen_w = None
        elif item == "inputs":
            chosen, chosen_w = {(v, t) for v, ts in fuzz.items() for t in ts}, None
        elif item == "outputs":
            chosen, chosen_w = {(v, t) for v, ts in defz.items() for t in ts}, None
        elif item == "weights":
            chosen, chosen_w = set(), True
        elif item in every:
            chosen, chosen_w = {(item, t) for t in every[item]}, None
        elif "." in item and item.split(".", 1)[0] in every:
            v, t = item.split(".", 1)
            if t not in every[v]:
                raise SpaceError(f"--free {raw!r}: {v} has no term {t!r} (terms: {', '.join(every[v])})")
            chosen, chosen_w = {(v, t)}, None
        else:
            known = ", ".join(["all", "inputs", "outputs", "weights", *every])
            raise SpaceError(
                f"--free {raw!r}: not a variable or VARIABLE.TERM of this block (known: {known})"
            )
        used.append(raw)
        if neg:
            terms -= chosen
            if chosen_w:
                weights = False
        else:
            terms |= chosen
            if chosen_w:
                weights = True
    return terms, weights, used


def build_space(
    fb: FunctionBlock,
    free: str | Sequence[str] | None = "all",
    *,
    keep_zero: bool = False,
    lower_only: bool = False,
) -> Space:
    """The free parameters of ``fb`` for a ``--free`` specification (see :func:`parse_free`).

    ``keep_zero``: abscissae and singletons at exactly 0 stay there.  In a closed loop the
    terms at zero error and the zero output make the equilibrium (no error, no action):
    moving them moves where the loop settles.  ``lower_only``: only the lower functions of
    interval type-2 terms move (what widening a type-1 system tunes)."""
    slots = catalogue(fb)
    if lower_only:
        slots = {k: v for k, v in slots.items() if k[0] in ("lower", "with", "rule")}
    free_terms, free_weights, _ = parse_free(free, fb)
    notes: list[str] = []
    groups: list[Group] = []
    start = 0
    free_keys: list[SlotKey] = []
    variables = [b.variable for b in fb.fuzzify] + [b.variable for b in fb.defuzzify]
    # Terms whose parameters are variables (Refs) or whose kind has no tunable parameter.
    blocks: list[FuzzifyBlock | DefuzzifyBlock] = [*fb.fuzzify, *fb.defuzzify]
    for blk in blocks:
        for ti, t in enumerate(blk.terms):
            if (blk.variable, t.name) in free_terms and not any(
                k[0] == "term" and k[1] == blk.variable and k[2] == ti for k in slots
            ):
                notes.append(f"{blk.variable}.{t.name}: nothing to tune in this term (kept as written)")
    for var in variables:
        xs_slots = [s for s in slots.values() if s.variable == var and s.role == "x"]
        values = sorted({s.value for s in xs_slots})
        lo, hi = _universe(fb, var, values)
        by_value: dict[float, list[Slot]] = {}
        for s in xs_slots:
            by_value.setdefault(s.value, []).append(s)
        is_free = [
            lo < v < hi
            and not (keep_zero and v == 0.0)
            and any((var, s.term) in free_terms for s in by_value[v])
            for v in values
        ]
        # Runs of free breakpoints between fixed neighbours (or the universe's ends).
        i = 0
        while i < len(values):
            if not is_free[i]:
                i += 1
                continue
            j = i
            while j < len(values) and is_free[j]:
                j += 1
            left = values[i - 1] if i > 0 and values[i - 1] > lo else lo
            right = values[j] if j < len(values) and values[j] < hi else hi
            entries = tuple(tuple(s.key for s in by_value[v]) for v in values[i:j])
            groups.append(Group("run", left, right, entries, start))
            start += len(entries)
            for keys in entries:
                free_keys.extend(keys)
            i = j
        for s in slots.values():
            if s.variable != var or (var, s.term) not in free_terms:
                continue
            if s.role == "scale":
                groups.append(Group("log", 0.0, 0.0, ((s.key,),), start, value=s.value))
            elif s.role == "coef":
                lo_c, hi_c = _coef_box(fb, s)
                groups.append(Group("box", lo_c, hi_c, ((s.key,),), start))
            elif s.role in ("lower_scale", "lag"):
                lo_b, hi_b = type2.box(s.role)
                groups.append(Group("box", lo_b, hi_b, ((s.key,),), start))
            else:
                continue
            start += 1
            free_keys.append(s.key)
    if free_weights:
        for s in slots.values():
            if s.role == "weight":
                groups.append(Group("box", 0.0, 1.0, ((s.key,),), start))
                start += 1
                free_keys.append(s.key)
    if start == 0:
        raise SpaceError(
            "nothing to tune: the --free specification frees no parameter that can move "
            "(abscissae at the ends of the universe stay; give the variable a RANGE to free them)"
        )
    return Space(fb, slots, groups, tuple(free_keys), notes)


def _coef_box(fb: FunctionBlock, s: Slot) -> tuple[float, float]:
    """Takagi-Sugeno coefficient box: the output's span S (its RANGE, else the largest
    constant of its terms, at least 1), the constant within ``c +- 4 S``, the coefficient of
    input i within ``c +- 4 S / span_i`` (a local model may be steep where rules overlap)."""
    assert s.variable is not None
    out = fb.defuzzify_block(s.variable)
    rng = out.range if out is not None else None
    decl = fb.variable(s.variable)
    if rng is None and decl is not None:
        rng = decl.range
    if rng is not None and rng.high > rng.low:
        big = rng.high - rng.low
    else:
        consts = [
            abs(_num(p))
            for t in (out.terms if out else ())
            if isinstance(t.mf, ShapeMF)
            for p in t.mf.params[-1:]
            if _const(p)
        ]
        big = max([1.0, *consts])
    assert s.key[0] == "term"
    k = int(s.key[-1])
    inputs = [v.name for v in fb.inputs]
    width = 4.0 * big
    if "coefficient of" in s.label and k < len(inputs):
        name = inputs[k]
        xs = [sl.value for sl in catalogue_x(fb, name)]
        lo, hi = _universe(fb, name, xs)
        width = 4.0 * big / (hi - lo) if hi > lo else 4.0 * big
    return s.value - width, s.value + width


def catalogue_x(fb: FunctionBlock, var: str) -> list[Slot]:
    return [s for s in catalogue(fb).values() if s.variable == var and s.role == "x"]


# --------------------------------------------------------------------------- applying values


def apply_values(fb: FunctionBlock, values: dict[SlotKey, float]) -> FunctionBlock:
    """A copy of ``fb`` with the numbers at ``values`` replaced (comments and positions kept)."""
    by_term: dict[tuple[str, int], dict[int, float]] = {}
    withs: dict[tuple[int, int, int], float] = {}
    rule_w: dict[tuple[int, int], float] = {}
    lowers: dict[tuple[str, int], dict[SlotKey, float]] = {}
    for key, v in values.items():
        if key[0] == "term":
            by_term.setdefault((str(key[1]), int(key[2])), {})[int(key[3])] = v
        elif key[0] == "lower":
            lowers.setdefault((str(key[1]), int(key[2])), {})[key[3:]] = v
        elif key[0] == "with":
            withs[(int(key[1]), int(key[2]), int(key[3]))] = v
        else:
            rule_w[(int(key[1]), int(key[2]))] = v

    def terms(var: str, ts: tuple[Term, ...]) -> tuple[Term, ...]:
        out = []
        for ti, t in enumerate(ts):
            new = by_term.get((var, ti))
            t = t if not new else dataclasses.replace(t, mf=_replace_mf(t.mf, new))
            low = lowers.get((var, ti))
            out.append(t if not low else type2.with_values(t, low, _replace_mf))
        return tuple(out)

    fuzz = tuple(dataclasses.replace(b, terms=terms(b.variable, b.terms)) for b in fb.fuzzify)
    defz = tuple(dataclasses.replace(b, terms=terms(b.variable, b.terms)) for b in fb.defuzzify)
    rbs: list[RuleBlock] = []
    for bi, rb in enumerate(fb.rule_blocks):
        rules: list[Rule] = []
        for ri, rule in enumerate(rb.rules):
            concl = []
            for ci, c in enumerate(rule.conclusions):
                w = withs.get((bi, ri, ci))
                if w is not None and not (c.weight is None and w == 1.0):
                    c = dataclasses.replace(c, weight=w)
                concl.append(c)
            new_rule: Rule = dataclasses.replace(rule, conclusions=tuple(concl))
            if (bi, ri) in rule_w:
                new_rule = dataclasses.replace(new_rule, weight=rule_w[(bi, ri)])
            rules.append(new_rule)
        rbs.append(dataclasses.replace(rb, rules=tuple(rules)))
    out = dataclasses.replace(fb, fuzzify=fuzz, defuzzify=defz, rule_blocks=tuple(rbs))
    return type2.project(out) if out.is_type2 else out


def _replace_mf(mf: object, new: dict[int, float]) -> PointsMF | SingletonsMF | SingletonMF | ShapeMF:
    if isinstance(mf, PointsMF | SingletonsMF):
        pts = tuple(
            dataclasses.replace(p, x=new[2 * k]) if 2 * k in new else p for k, p in enumerate(mf.points)
        )
        return dataclasses.replace(mf, points=pts)
    if isinstance(mf, SingletonMF):
        return dataclasses.replace(mf, value=new.get(0, mf.value))
    assert isinstance(mf, ShapeMF)
    return dataclasses.replace(mf, params=tuple(new.get(k, p) for k, p in enumerate(mf.params)))
