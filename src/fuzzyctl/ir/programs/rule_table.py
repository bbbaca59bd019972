"""Large rule bases as tables and loops, evaluating only the rules that can fire.

Above :data:`fuzzyctl.ir.programs.evaluator.TABLE_THRESHOLD` rules the evaluator program does not
spell out one statement per rule (a 10,000-rule system would be a million lines of C that a
compiler needs minutes and gigabytes for): the rules become constant arrays and the program
loops over them.  It applies when every rule is *regular* - a conjunction (one AND norm) of
``variable IS term`` on distinct fuzzified inputs, no hedges, no NOT, constant weights,
conclusions ``output IS term`` - and every output can take its activated sets merged per
term (see :mod:`fuzzyctl.ir.programs.evaluator`: MAX accumulation with any activation, sums with
PROD; singleton, Takagi-Sugeno and degree outputs always).  Each merged set is a *slot*; a
rule adds ``multiplier * degree`` to its slots by the slot's accumulation.

Sparse evaluation.  A rule's degree is 0 as soon as one of its terms is 0 at the input (every
t-norm has T(0, x) = 0), and a rule of degree 0 changes no slot (0 is neutral for every
accumulation).  So per group of rules on the same input variables (and AND norm) the program
lists each variable's terms that are non-zero at its input, and when the product of those
list lengths is smaller than the group it enumerates the combinations and finds their rules in
a hash table (open addressing on the mixed-radix code of the term indices); otherwise it loops
over the group.  For triangular partitions at most 2 terms per input are non-zero: 2^n
combinations instead of 7^n rules.  Gaussian terms are never 0: the loop is taken.

The numpy renderer cannot loop a number of times that differs between samples, so its
program always loops over every rule (``sparse=False``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from fuzzyctl.engine.plan import CAnd, CTerm, Plan, RulePlan, Slot
from fuzzyctl.ir.builders import terms as T
from fuzzyctl.ir.nodes import Ex, Int, Num, Var
from fuzzyctl.kinds import norms

if TYPE_CHECKING:
    from fuzzyctl.ir.builders.rules import Contrib
    from fuzzyctl.ir.programs.evaluator import FastBuilder

#: accumulation codes of a slot
_KINDS = {"MAX": 1, "SUM": 2, "NSUM": 2, "BSUM": 3, "PROBOR": 4}
#: largest code of a term combination (INT in the generated code is 32-bit)
_MAX_CODE = 2**31 - 1


def _terms(r: RulePlan) -> list[CTerm] | None:
    """The terms of a regular condition, None for anything else."""
    c = r.condition
    items = [c] if isinstance(c, CTerm) else (list(c.operands) if isinstance(c, CAnd) else None)
    if not items or not all(isinstance(i, CTerm) and not i.hedges and not i.negated for i in items):
        return None
    terms = [i for i in items if isinstance(i, CTerm)]
    if len({t.var for t in terms}) != len(terms):
        return None
    return terms


def _output_ok(plan: Plan, oi: int) -> bool:
    op = plan.outputs[oi]
    accu = op.accu or "MAX"
    if op.kind == "mamdani":
        return norms.is_max(accu) or (
            norms.adds(accu) and all(norms.is_prod(c.act) for c in op.contributions)
        )
    if op.kind == "singleton":
        return norms.is_max(accu) or (
            norms.adds(accu) and all(norms.is_prod(c.act) for c in op.contributions)
        )
    if op.kind == "ts":
        return op.accu is None or op.accu in _KINDS
    return accu in _KINDS  # degree


def table_applies(plan: Plan) -> bool:
    """Whether the rules of ``plan`` can be tables (see the module docstring)."""
    if plan.chained or plan.selections:
        return False
    for r in plan.rules:
        if _terms(r) is None or isinstance(r.weight, Slot) or r.selection is not None:
            return False
        for cp in r.conclusions:
            if cp.term is None or cp.chained or cp.hedges or isinstance(cp.weight, Slot):
                return False
    return all(_output_ok(plan, oi) for oi in range(len(plan.outputs)))


@dataclass
class _Slot:
    output: int
    term: int
    weight: float  # the merged set's weight (1.0 when multiplied into the degree)
    act: str
    kind: int


@dataclass
class _Group:
    """Rules on the same input variables with the same AND norm."""

    vars: tuple[int, ...]
    op: str
    rules: list[int] = field(default_factory=list)


def _slots(plan: Plan) -> tuple[list[_Slot], list[list[tuple[int, float]]]]:
    """The merged sets, and per rule its (slot, multiplier) list."""
    before = plan.options.weight_before_activation
    slots: list[_Slot] = []
    index: dict[tuple[object, ...], int] = {}
    per_rule: list[list[tuple[int, float]]] = [[] for _ in plan.rules]
    for oi, op in enumerate(plan.outputs):
        accu = op.accu or "MAX"
        for c in op.contributions:
            cp = plan.rules[c.rule].conclusions[c.conclusion]
            w = float(cp.weight)  # type: ignore[arg-type]
            if op.kind in ("mamdani", "singleton") and norms.is_max(accu) and not before:
                key: tuple[object, ...] = (oi, c.term, w, c.act)
                slot, mult = _Slot(oi, c.term or 0, w, c.act, 1), 1.0
            elif op.kind in ("mamdani", "singleton"):
                key = (oi, c.term, c.act)
                slot, mult = _Slot(oi, c.term or 0, 1.0, c.act, _KINDS[accu]), w
            elif op.kind == "ts":
                kind = 2 if op.accu is None else _KINDS[op.accu]
                key = (oi, c.term)
                slot, mult = _Slot(oi, c.term or 0, 1.0, c.act, kind), w
            else:
                key = (oi,)
                slot, mult = _Slot(oi, 0, 1.0, c.act, _KINDS[accu]), w
            if key not in index:
                index[key] = len(slots)
                slots.append(slot)
            per_rule[c.rule].append((index[key], mult))
    return slots, per_rule


def _groups(plan: Plan) -> list[_Group]:
    groups: dict[tuple[tuple[int, ...], str], _Group] = {}
    for ri in plan.order:
        terms = _terms(plan.rules[ri])
        assert terms is not None
        c = plan.rules[ri].condition
        op = c.op if isinstance(c, CAnd) else "MIN"
        key = (tuple(sorted(t.var for t in terms)), op)
        groups.setdefault(key, _Group(key[0], op)).rules.append(ri)
    return list(groups.values())


class _Tables:
    """Constant arrays of the program, declared as they are filled."""

    def __init__(self, fb: FastBuilder) -> None:
        self.g = fb.g

    def ints(self, hint: str, values: list[int]) -> Var:
        init = tuple(float(v) for v in values) or (0.0,)
        return self.g.declare(self.g.fresh(hint, hint), "DINT", "const", len(init), init)

    def reals(self, hint: str, values: list[float]) -> Var:
        init = tuple(values) or (0.0,)
        return self.g.declare(self.g.fresh(hint, hint), "REAL", "const", len(init), init)


def table_rules(
    fb: FastBuilder, degrees: dict[tuple[int, int], Ex], sparse: bool
) -> dict[int, list[Contrib]]:
    """Emit the rule section as tables and loops; returns each output's (merged) activated
    sets as contributions ``(term, degree, weight, act)``."""
    plan, g = fb.plan, fb.g
    b = g.b
    slots, per_rule = _slots(plan)
    tab = _Tables(fb)
    # ---- term degrees in one array, and each variable's terms
    read = sorted(degrees)
    pos = {k: i for i, k in enumerate(read)}
    deg = g.array("DEG", "REAL", len(read))
    for k in read:
        b.set(deg[pos[k]], degrees[k])
    acc = g.array("ACC", "REAL", len(slots))
    for s in range(len(slots)):
        b.set(acc[s], 0.0)
    kind = tab.ints("SKIND", [s.kind for s in slots])
    with b.region("rules (tables)"):
        for grp in _groups(plan):
            _group(fb, grp, pos, deg, acc, kind, per_rule, tab, sparse)
    out: dict[int, list[Contrib]] = {oi: [] for oi in range(len(plan.outputs))}
    for s, slot in enumerate(slots):
        v = g.temp(hint="H")
        b.set(v, acc[s])
        if slot.kind == 3:  # BSUM: the sum limited to 1
            with b.if_(v.gt(1.0)):
                b.set(v, 1.0)
        out[slot.output].append((slot.term, v, Num(slot.weight), slot.act))
    return out


def _group(
    fb: FastBuilder,
    grp: _Group,
    pos: dict[tuple[int, int], int],
    deg: Var,
    acc: Var,
    kind: Var,
    per_rule: list[list[tuple[int, float]]],
    tab: _Tables,
    sparse: bool,
) -> None:
    plan, g = fb.plan, fb.g
    b = g.b
    nvars = len(grp.vars)
    # per rule: the DEG index of each of its terms (in the group's variable order), weight,
    # and slots
    rt: list[int] = []
    codes: list[int] = []
    fi_terms = [[t for (v, t) in sorted(pos) if v == var] for var in grp.vars]
    radix = [max(1, len(ts)) for ts in fi_terms]
    strides = [1] * nvars
    for k in range(nvars - 2, -1, -1):
        strides[k] = strides[k + 1] * radix[k + 1]
    for ri in grp.rules:
        terms = {t.var: t.term for t in (_terms(plan.rules[ri]) or [])}
        code = 0
        for k, var in enumerate(grp.vars):
            rt.append(pos[(var, terms[var])])
            code += fi_terms[k].index(terms[var]) * strides[k]
        codes.append(code)
    so: list[int] = []
    ss: list[int] = []
    sm: list[float] = []
    for ri in grp.rules:
        so.append(len(ss))
        for s, m in per_rule[ri]:
            ss.append(s)
            sm.append(m)
    so.append(len(ss))
    rt_v = tab.ints("RT", rt)
    rw_v = tab.reals("RW", [float(plan.rules[ri].weight) for ri in grp.rules])  # type: ignore[arg-type]
    so_v, ss_v, sm_v = tab.ints("RSO", so), tab.ints("RSS", ss), tab.reals("RSM", sm)
    n_rules = len(grp.rules)

    def fire(r: Ex) -> None:
        """Rule ``r`` of the group (its index in the group's tables): its degree, added to its
        slots (a degree at or below the firing threshold counts as 0, which changes no slot)."""
        base = g.let(r * nvars, "RB", "DINT")
        d: Ex = deg[rt_v[base]]
        for k in range(1, nvars):
            d = T.tnorm(g, grp.op, d, deg[rt_v[base + k]])
        a = g.let(d * rw_v[r], "RD")
        threshold = plan.options.firing_threshold
        if not sparse:  # one program for every sample (numpy): no branch on the degree
            if threshold > 0.0:
                with b.if_(a.le(threshold)):
                    b.set(a, 0.0)
            _add(r, a)
            return
        with b.if_(a.gt(threshold)):
            _add(r, a)

    def _add(r: Ex, a: Var) -> None:
        q = g.counter("Q", "DINT")
        with b.for_(q, so_v[r], so_v[r + 1] - 1) as qv:
            s = g.let(ss_v[qv], "S", "DINT")
            val = g.let(sm_v[qv] * a, "V")
            k_ = g.let(kind[s], "K", "DINT")
            with b.if_(k_.eq(1)), b.if_(val.gt(acc[s])):
                b.set(acc[s], val)
            with b.elif_(k_.eq(4)):
                b.set(acc[s], acc[s] + val - acc[s] * val)
            with b.else_():
                b.set(acc[s], acc[s] + val)

    if not sparse or nvars == 0 or _code_limit(radix):
        with b.for_(g.counter("R", "DINT"), 0, n_rules - 1) as rv:
            fire(rv)
        return
    _sparse(fb, grp, pos, deg, fi_terms, strides, codes, fire, tab, n_rules)


def _code_limit(radix: list[int]) -> bool:
    total = 1
    for r in radix:
        total *= r
    return total > _MAX_CODE


def _sparse(
    fb: FastBuilder,
    grp: _Group,
    pos: dict[tuple[int, int], int],
    deg: Var,
    fi_terms: list[list[int]],
    strides: list[int],
    codes: list[int],
    fire: Callable[[Ex], None],
    tab: _Tables,
    n_rules: int,
) -> None:
    """The non-zero terms of each variable, then either the combinations of them looked up in
    the group's hash table, or every rule when there are more combinations than rules."""
    g = fb.g
    b = g.b
    nvars = len(grp.vars)
    # hash table: code -> the group's rules with that code (duplicates allowed)
    by_code: dict[int, list[int]] = {}
    for r, code in enumerate(codes):
        by_code.setdefault(code, []).append(r)
    size = 1
    while size < 2 * len(by_code):
        size *= 2
    keys, first, count = [-1] * size, [0] * size, [0] * size
    order: list[int] = []
    for code, rs in by_code.items():
        h = code & (size - 1)
        while keys[h] != -1:
            h = (h + 1) & (size - 1)
        keys[h], first[h], count[h] = code, len(order), len(rs)
        order.extend(rs)
    hk, hf = tab.ints("HKEY", keys), tab.ints("HFIRST", first)
    hc, hr = tab.ints("HCNT", count), tab.ints("HRULE", order)
    # each variable's non-zero terms (index in the variable's list)
    nz = []
    for k in range(nvars):
        ts = fi_terms[k]
        arr = g.array(f"NZ{k}", "DINT", len(ts))
        n = g.let(0, f"NZN{k}", "DINT")
        for j, t in enumerate(ts):
            with b.if_(deg[pos[(grp.vars[k], t)]].gt(0.0)):
                b.set(arr[n], j)
                b.set(n, n + 1)
        nz.append((arr, n))
    combos = g.let(nz[0][1], "NCMB", "DINT")
    for _arr, n in nz[1:]:
        b.set(combos, combos * n)
    fire_fn = fire
    with b.if_(combos.lt(n_rules)):
        counters: list[Var] = []

        def nest(k: int, code: Ex) -> None:
            if k == nvars:
                h = g.let(_mod(code, size), "HH", "DINT")
                go = g.let(True, "GO", "BOOL")
                with b.while_(go):
                    with b.if_(hk[h].eq(code)):
                        with b.for_(g.counter("J", "DINT"), hf[h], hf[h] + hc[h] - 1) as jv:
                            fire_fn(hr[jv])
                        b.set(go, False)
                    with b.elif_(hk[h].eq(-1)):
                        b.set(go, False)
                    with b.else_():
                        b.set(h, _mod(h + 1, size))
                return
            arr, n = nz[k]
            with b.for_(g.counter(f"C{k}", "DINT"), 0, n - 1) as cv:
                counters.append(cv)
                c = g.let(code + arr[cv] * strides[k], f"CODE{k}", "DINT")
                nest(k + 1, c)

        nest(0, Int(0))
    with b.else_(), b.for_(g.counter("R"), 0, n_rules - 1) as rv:
        fire_fn(rv)


def _mod(e: Ex, size: int) -> Ex:
    """``e mod size`` for a power of two, with the IR's operators (no MOD in the IR)."""
    from fuzzyctl.ir.nodes import Call

    return Call("IMOD", (e, Int(size)))
