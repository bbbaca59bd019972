"""Specialisation of the scalar path: the plan becomes one straight-line Python function.

Constants are inlined as exact float literals, every membership function becomes an if-chain
over its breakpoints, conditions become nested conditional expressions over local variables
(no calls for MIN/MAX), and Mamdani outputs on a constant grid use the closed-form area and
moment polynomials of :class:`~fuzzyctl.engine.plan.GridPlan` for the intervals a term has to
itself; shared intervals call :func:`fuzzyctl.engine.pwl.interval_pieces`.  Whatever is not
specialised (smooth output sets, outputs whose terms are given by variables, CoA/LM/RM/MoM)
goes through the interpreter's output code with the same rule degrees.

The generated source is kept on the function (``__source__``) for inspection.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from fuzzyctl.engine import pwl, selection, shapes
from fuzzyctl.engine.expr import eval_expr
from fuzzyctl.engine.interp import Interpreter
from fuzzyctl.engine.operators import SNORMS, SOURCE_HELPERS, TNORMS
from fuzzyctl.engine.plan import (
    CAnd,
    CChained,
    CDegree,
    CNot,
    CondPlan,
    COr,
    CTerm,
    CTrue,
    OutputPlan,
    Plan,
    PParam,
    Slot,
    TermPlan,
)
from fuzzyctl.escape import py_str

Fast = Callable[[list[float], list[float | None]], list[float]]


def _lit(x: float) -> str:
    if math.isnan(x):
        return "_NAN"
    if math.isinf(x):
        return "_INF" if x > 0 else "(-_INF)"
    return repr(float(x))


class _Gen:
    def __init__(self, plan: Plan) -> None:
        self.plan = plan
        self.lines: list[str] = []
        self.n = 0
        self.env: dict[str, Any] = {
            "_NAN": math.nan,
            "_INF": math.inf,
            "_exp": math.exp,
            "_cos": math.cos,
            "_sqrt": math.sqrt,
            "_m": shapes.membership,
            "_H": shapes.HEDGES,
            "_pieces": pwl.interval_pieces,
            "_am": pwl.area_moment,
            "_eval_expr": eval_expr,
            "_select": selection.select,
            **SOURCE_HELPERS,  # the Hamacher templates call _ham_t / _ham_s
        }
        self.consts: dict[int, str] = {}

    def tmp(self) -> str:
        self.n += 1
        return f"t{self.n}"

    def emit(self, line: str, indent: int = 1) -> None:
        self.lines.append("    " * indent + line)

    def obj(self, value: Any) -> str:
        """A name for an arbitrary constant object in the function's globals."""
        key = id(value)
        if key not in self.consts:
            name = f"_c{len(self.consts)}"
            self.consts[key] = name
            self.env[name] = value
        return self.consts[key]

    def param(self, p: PParam) -> str:
        return f"v{p.index}" if isinstance(p, Slot) else _lit(p)

    # ------------------------------------------------------------------ membership

    def term(self, t: TermPlan, x: str, out: str, ind: int = 1) -> None:
        if t.pwl is not None:
            self.pwl_chain(t.pwl, x, out, ind)
        elif t.kind == "gaussian" and t.constant:
            m, sd = (float(p) for p in t.params if not isinstance(p, Slot))
            h = float(t.height) if not isinstance(t.height, Slot) else 1.0
            d = self.tmp()
            self.emit(f"{d} = {x} - {_lit(m)}", ind)
            expr = f"_exp(-({d} * {d}) / {_lit(2.0 * sd * sd)})"
            self.emit(f"{out} = {expr}" if h == 1.0 else f"{out} = {_lit(h)} * {expr}", ind)
        elif t.kind == "function":
            self.emit(f"{out} = _eval_expr({self.obj(t.expr)}, v, (), {x})", ind)
        else:
            params = "[" + ", ".join(self.param(p) for p in t.params) + "]"
            self.emit(f"{out} = _m({py_str(t.kind)}, {params}, {self.param(t.height)}, {x})", ind)

    def pwl_chain(self, pts: tuple[tuple[float, float], ...], x: str, out: str, ind: int) -> None:
        xs = sorted({p[0] for p in pts})
        from fuzzyctl.engine.grid import left_limit, right_limit

        self.emit(f"if {x} < {_lit(xs[0])}: {out} = {_lit(pts[0][1])}", ind)
        for k, u in enumerate(xs):
            pv = shapes.pwl_value(pts, u)
            jump = left_limit(pts, u) != right_limit(pts, u) or pv != left_limit(pts, u)
            if jump or k == 0:
                self.emit(f"elif {x} == {_lit(u)}: {out} = {_lit(pv)}", ind)
            if k + 1 < len(xs):
                u1 = xs[k + 1]
                r0, l1 = right_limit(pts, u), left_limit(pts, u1)
                if r0 == l1:
                    expr = _lit(r0)
                else:
                    slope = (l1 - r0) / (u1 - u)
                    base = f"({x} - {_lit(u)}) * {_lit(slope)}"
                    expr = base if r0 == 0.0 else f"{_lit(r0)} + {base}"
                self.emit(f"elif {x} < {_lit(u1)}: {out} = {expr}", ind)
        last = xs[-1]
        pv_last = shapes.pwl_value(pts, last)
        self.emit(f"elif {x} == {_lit(last)}: {out} = {_lit(pv_last)}", ind)
        self.emit(f"else: {out} = {_lit(pts[-1][1])}", ind)

    # ------------------------------------------------------------------ conditions

    def cond(
        self,
        c: CondPlan,
        degrees: dict[tuple[int, int], str],
        chained: dict[tuple[int, int], str],
        bare: dict[int, str],
    ) -> str:
        if isinstance(c, CTerm | CChained):
            table = degrees if isinstance(c, CTerm) else chained
            d = "1.0" if "any" in c.hedges else table[(c.var, c.term)]
            return self.hedged(d, c.hedges, c.negated)
        if isinstance(c, CDegree):
            return f"v{c.slot}" if c.slot is not None else bare[c.chained or 0]
        if isinstance(c, CNot):
            inner = self.cond(c.operand, degrees, chained, bare)
            t = self.tmp()
            self.emit(f"{t} = 1.0 - {inner}")
            return t
        if isinstance(c, CAnd | COr):
            norm = (TNORMS if isinstance(c, CAnd) else SNORMS)[c.op]
            acc = self.cond(c.operands[0], degrees, chained, bare)
            for o in c.operands[1:]:
                b = self.cond(o, degrees, chained, bare)
                t = self.tmp()
                self.emit(f"{t} = {norm.source.format(a=acc, b=b)}")
                acc = t
            return acc
        assert isinstance(c, CTrue)
        return "1.0"

    def hedged(self, d: str, hedges: tuple[str, ...], negated: bool) -> str:
        for h in reversed(hedges):
            t = self.tmp()
            self.emit(f"{t} = {self.obj(shapes.hedge_function(h))}({d})")
            d = t
        if negated:
            t = self.tmp()
            self.emit(f"{t} = 1.0 - {d}")
            d = t
        return d


def _accu_src(accu: str, a: str, b: str) -> str:
    if accu == "MAX":
        return f"({a} if {a} > {b} else {b})"
    if accu in ("SUM", "NSUM"):
        return f"({a} + {b})"
    if accu == "BSUM":
        return f"min(1.0, {a} + {b})"
    if accu == "PROBOR":
        return f"({a} + {b} - {a} * {b})"
    return SNORMS[accu].source.format(a=a, b=b)


def specialise(plan: Plan) -> Fast:
    """Generate the straight-line evaluator of ``plan``."""
    g = _Gen(plan)
    interp = Interpreter(plan)
    g.env["_interp"] = interp
    g.env["_plan"] = plan
    opts = plan.options
    for i, inp in enumerate(plan.inputs):
        g.emit(f"v{i} = v[{i}]")
        if inp.clamp is not None:  # lock-range: the limited value is what everything reads
            lo, hi = inp.clamp
            g.emit(f"if v{i} < {_lit(lo)}: v{i} = {_lit(lo)}")
            g.emit(f"elif v{i} > {_lit(hi)}: v{i} = {_lit(hi)}")
    if any(inp.clamp is not None for inp in plan.inputs):
        g.emit(f"v = [{', '.join(f'v{i}' for i in range(len(plan.inputs)))}]")
    # ---- fuzzification: only the terms some condition reads
    degrees: dict[tuple[int, int], str] = {}
    for var, term in plan.terms_read():
        fi = plan.fuzzy_inputs[var]
        name = f"d{var}_{term}"
        g.term(fi.terms[term], f"v{fi.slot}", name)
        degrees[(var, term)] = name
    # ---- chained accumulators
    chained: dict[tuple[int, int], str] = {}
    bare: dict[int, str] = {}
    for ci, chp in enumerate(plan.chained):
        for ti in range(len(chp.terms)):
            chained[(ci, ti)] = f"c{ci}_{ti}"
            g.emit(f"c{ci}_{ti} = 0.0")
        bare[ci] = f"cb{ci}"
        g.emit(f"cb{ci} = 0.0")
    normalised: set[int] = set()
    threshold = _lit(opts.firing_threshold)

    def weighted(ri: int, r: str) -> None:
        """``r = weight * condition``, 0 at or below the firing threshold."""
        rule = plan.rules[ri]
        a = g.cond(rule.condition, degrees, chained, bare)
        g.emit(f"{r} = {a}" if rule.weight == 1.0 else f"{r} = {g.param(rule.weight)} * {a}")
        if opts.firing_threshold > 0.0:
            g.emit(f"if {r} <= {threshold}: {r} = 0.0")

    # ---- rule blocks with a rule activation method: their rules read no chained variable
    for k, sel in enumerate(plan.selections):
        for ri in sel.rules:
            weighted(ri, f"r{ri}")
        g.env[f"_sel{k}"] = sel
        g.emit(f"s{k} = _select(_sel{k}, [{', '.join(f'r{ri}' for ri in sel.rules)}])")
        for j, ri in enumerate(sel.rules):
            g.emit(f"r{ri} = s{k}[{j}]")
            if opts.firing_threshold > 0.0:
                g.emit(f"if r{ri} <= {threshold}: r{ri} = 0.0")
    # ---- rules
    concl_names: list[list[tuple[str, str]]] = [[] for _ in plan.rules]
    for ri in plan.order:
        rule = plan.rules[ri]
        reads = _chained_reads(rule.condition)
        for ci in sorted(reads - normalised):
            normalised.add(ci)
            if plan.chained[ci].accu == "NSUM" and plan.chained[ci].terms:
                names = [chained[(ci, t)] for t in range(len(plan.chained[ci].terms))]
                g.emit(f"top = max(1.0, {', '.join(names)})")
                for nme in names:
                    g.emit(f"{nme} = {nme} / top")
        r = f"r{ri}"
        if rule.selection is None:
            weighted(ri, r)
        carried = r
        for cp in rule.conclusions:
            base = carried if opts.hedges_carry_over else r
            h = g.hedged(base, cp.hedges, False) if cp.hedges else base
            if opts.hedges_carry_over:
                carried = h
            w = g.param(cp.weight)
            concl_names[ri].append((h, w))
            for ch in cp.chained:
                accu = plan.chained[ch].accu
                target = bare[ch] if cp.term is None else chained[(ch, cp.term)]
                val = h if w == "1.0" else f"{w} * {h}"
                g.emit(f"{target} = {_accu_src(accu, target, val)}")
    # ---- outputs
    need_cc = any(not _specialised(op, plan) for op in plan.outputs)
    if need_cc:
        cc = ", ".join(
            "[" + ", ".join(f"({h}, {w})" for h, w in concl_names[ri]) + "]" for ri in range(len(plan.rules))
        )
        g.emit(f"cc = [{cc}]")
    g.emit(f"outs = [_NAN] * {len(plan.outputs)}")
    for oi in plan.output_order:
        op = plan.outputs[oi]
        _gen_output(g, plan, oi, op, concl_names)
    g.emit("return outs")
    src = "def _fast(v, state):\n" + "\n".join(g.lines) + "\n"
    env = dict(g.env)
    # only generated names, float literals and py_str() text reach the source: no model text
    exec(compile(src, f"<fuzzyctl specialised {plan.name!r}>", "exec"), env)
    fn: Fast = env["_fast"]
    fn.__source__ = src  # type: ignore[attr-defined]
    return fn


def _chained_reads(c: CondPlan) -> set[int]:
    if isinstance(c, CChained):
        return {c.var}
    if isinstance(c, CNot):
        return _chained_reads(c.operand)
    if isinstance(c, CAnd | COr):
        out: set[int] = set()
        for o in c.operands:
            out |= _chained_reads(o)
        return out
    return set()


def _specialised(op: OutputPlan, plan: Plan) -> bool:
    if op.kind == "degree":
        return True
    if op.kind == "singleton":
        return op.method == "COGS" and all(t.kind == "singleton" for t in op.terms)
    if op.kind == "ts":
        return not any(t.kind in shapes.TSUKAMOTO_KINDS for t in op.terms)
    return op.kind == "mamdani" and op.exact and op.grid is not None and op.method == "COG"


def _contrib_src(
    plan: Plan, op: OutputPlan, concl: list[list[tuple[str, str]]]
) -> list[tuple[int | None, str, str, str]]:
    """(term, degree expr, weight expr, act) with the weight placement of the options."""
    out = []
    for c in op.contributions:
        h, w = concl[c.rule][c.conclusion]
        if plan.options.weight_before_activation and w != "1.0":
            out.append((c.term, f"({w} * {h})", "1.0", c.act))
        else:
            out.append((c.term, h, w, c.act))
    return out


def _gen_output(g: _Gen, plan: Plan, oi: int, op: OutputPlan, concl: list[list[tuple[str, str]]]) -> None:
    val, fired = f"y{oi}", f"f{oi}"
    if not _specialised(op, plan):
        g.emit(f"_rec = _interp._output(_plan.outputs[{oi}], cc, v, outs)")
        g.emit(f"{val} = _rec.value; {fired} = _rec.fired")
    else:
        contribs = _contrib_src(plan, op, concl)
        if op.kind == "degree":
            g.emit(f"{val} = 0.0; {fired} = True")
            for _t, h, w, _act in contribs:
                term = h if w == "1.0" else f"{w} * {h}"
                g.emit(f"{val} = {_accu_src(op.accu or 'MAX', val, term)}")
        elif op.kind == "singleton":
            _gen_singleton(g, op, contribs, val, fired)
        elif op.kind == "ts":
            _gen_ts(g, plan, op, contribs, val, fired)
        else:
            _gen_cog(g, op, contribs, val, fired)
    # DEFAULT / NC
    if op.kind == "degree":
        g.emit(f"outs[{oi}] = {val}; state[{oi}] = {val}")
        return
    init = _lit(op.default if op.default is not None else 0.0)
    g.emit(f"if not {fired}:")
    if op.no_change:
        g.emit(f"{val} = state[{oi}]", 2)
        g.emit(f"if {val} is None: {val} = {init}", 2)
    else:
        g.emit(f"{val} = {init}", 2)
    if op.clamp is not None:
        lo, hi = op.clamp
        g.emit(f"if {val} < {_lit(lo)}: {val} = {_lit(lo)}")
        g.emit(f"elif {val} > {_lit(hi)}: {val} = {_lit(hi)}")
    g.emit(f"outs[{oi}] = {val}; state[{oi}] = {val}")


def _gen_singleton(
    g: _Gen, op: OutputPlan, contribs: list[tuple[int | None, str, str, str]], val: str, fired: str
) -> None:
    accu = op.accu or "MAX"
    by_term: dict[int, list[str]] = {}
    for t, h, w, _act in contribs:
        assert t is not None
        by_term.setdefault(t, []).append(h if w == "1.0" else f"{w} * {h}")
    names = []
    for t, terms_ in by_term.items():
        m = f"m{t}_{g.tmp()}"
        g.emit(f"{m} = {terms_[0]}")
        for e in terms_[1:]:
            x = g.tmp()
            g.emit(f"{x} = {e}")
            g.emit(f"{m} = {_accu_src(accu, m, x)}")
        names.append((t, m))
    if not names:
        g.emit(f"{val} = _NAN; {fired} = False")
        return
    den = " + ".join(m for _t, m in names)
    num = " + ".join(f"{g.param(op.terms[t].params[0])} * {m}" for t, m in names)
    g.emit(f"den = {den}")
    g.emit(f"{fired} = den > 0.0")
    g.emit(f"{val} = ({num}) / den if {fired} else _NAN")


def _gen_ts(
    g: _Gen,
    plan: Plan,
    op: OutputPlan,
    contribs: list[tuple[int | None, str, str, str]],
    val: str,
    fired: str,
) -> None:
    zs: dict[int, str] = {}

    def z(t: int) -> str:
        if t not in zs:
            term = op.terms[t]
            name = f"z{t}_{g.tmp()}"
            if term.kind in ("singleton", "constant"):
                g.emit(f"{name} = {g.param(term.params[0])}")
            elif term.kind == "linear":
                n = len(plan.inputs)
                parts = [f"{g.param(c)} * v{i}" for i, c in enumerate(term.params[:n])]
                if len(term.params) > n:
                    parts.append(g.param(term.params[n]))
                g.emit(f"{name} = {' + '.join(parts) or '0.0'}")
            else:
                g.emit(f"{name} = _eval_expr({g.obj(term.expr)}, v, outs)")
            zs[t] = name
        return zs[t]

    g.emit("num = 0.0; den = 0.0")
    if op.accu is None:
        for t, h, w, _act in contribs:
            assert t is not None
            wt = h if w == "1.0" else f"{w} * {h}"
            x = g.tmp()
            g.emit(f"{x} = {wt}")
            zt = z(t)
            g.emit(f"if {x} > 0.0:")
            g.emit(f"num += {x} * {zt}; den += {x}", 2)
    else:
        by_term: dict[int, str] = {}
        for t, h, w, _act in contribs:
            assert t is not None
            wt = h if w == "1.0" else f"{w} * {h}"
            if t not in by_term:
                by_term[t] = f"m{t}_{g.tmp()}"
                g.emit(f"{by_term[t]} = {wt}")
            else:
                x = g.tmp()
                g.emit(f"{x} = {wt}")
                g.emit(f"{by_term[t]} = {_accu_src(op.accu, by_term[t], x)}")
        for t, m in by_term.items():
            zt = z(t)
            g.emit(f"if {m} > 0.0:")
            g.emit(f"num += {m} * {zt}; den += {m}", 2)
    g.emit(f"{fired} = den > 0.0")
    if op.method == "WTAVER":
        g.emit(f"{val} = num / den if {fired} else _NAN")
    else:
        g.emit(f"{val} = num if {fired} else _NAN")


def _gen_cog(
    g: _Gen, op: OutputPlan, contribs: list[tuple[int | None, str, str, str]], val: str, fired: str
) -> None:
    grid = op.grid
    assert grid is not None
    accu = op.accu or "MAX"
    # merge what MAX accumulation allows (see batch._merge)
    groups: list[tuple[int, str, str, bool]] = []
    keyed: dict[Any, list[str]] = {}
    order: list[Any] = []
    for t, h, w, act in contribs:
        assert t is not None
        is_min = act == "MIN"
        if accu == "MAX" and not is_min:
            key: Any = (t, False, "1.0")
            h = h if w == "1.0" else f"({w} * {h})"
        elif accu == "MAX" and not w.startswith("v"):
            key = (t, True, w)
        else:
            groups.append((t, h, w, is_min))
            continue
        if key not in keyed:
            keyed[key] = []
            order.append(key)
        keyed[key].append(h)
    for key in order:
        t, is_min, w = key
        hs = keyed[key]
        name = f"h{t}_{g.tmp()}"
        g.emit(f"{name} = {hs[0]}")
        for e in hs[1:]:
            x = g.tmp()
            g.emit(f"{x} = {e}")
            g.emit(f"if {x} > {name}: {name} = {x}")
        groups.append((t, name, w, is_min))
    per_term: dict[int, int] = {}
    for t, _h, _w, _mn in groups:
        per_term[t] = per_term.get(t, 0) + 1
    closed = {t for t, k in per_term.items() if k == 1 or accu in ("SUM", "NSUM")}
    g.emit("A = 0.0; M = 0.0")
    for t, h, w, is_min in groups:
        if t not in closed or not grid.solo[t]:
            continue
        scale = "" if w == "1.0" else f"{w} * "
        g.emit(f"if {h} > 0.0:")
        if is_min:
            bands = grid.min_bands[t]
            for bi, (lo_h, hi_h, ac, mc) in enumerate(bands):
                kw = "if" if bi == 0 else "elif"
                cond = f"{h} <= {_lit(hi_h)}" if bi + 1 < len(bands) else "True"
                if bi + 1 == len(bands):
                    g.emit("else:" if bi > 0 else "if True:", 2)
                else:
                    g.emit(f"{kw} {cond}:", 2)
                a_src = _poly_src(ac, h)
                m_src = _poly_src(mc, h)
                g.emit(f"A += {scale}({a_src}); M += {scale}({m_src})", 3)
                del lo_h
        else:
            fa, fm = grid.full[t]
            g.emit(f"A += {scale}{h} * {_lit(fa)}; M += {scale}{h} * {_lit(fm)}", 2)
    general = sorted(set(grid.shared) | {j for t in per_term if t not in closed for j in grid.solo[t]})
    for j in general:
        members = [(t, h, w, mn) for t, h, w, mn in groups if t in grid.active[j]]
        if not members:
            continue
        lines = ", ".join(
            f"({_lit(grid.left[t][j])}, {_lit(grid.right[t][j])}, {h}, {w}, {mn})" for t, h, w, mn in members
        )
        cond = " or ".join(f"{h} > 0.0" for _t, h, _w, _mn in members)
        g.emit(f"if {cond}:")
        g.emit(
            f"_ps = []; _pieces({_lit(grid.xs[j])}, {_lit(grid.xs[j + 1])}, "
            f"[l for l in ({lines},) if l[2] * l[3] > 0.0], {accu!r}, _ps)",
            2,
        )
        g.emit("_a, _mo = _am(_ps); A += _a; M += _mo", 2)
    g.emit(f"{fired} = A > 0.0")
    g.emit(f"{val} = M / A if {fired} else _NAN")


def _poly_src(c: tuple[float, ...], h: str) -> str:
    terms = [c0 for c0 in c]
    while len(terms) > 1 and terms[-1] == 0.0:
        terms.pop()
    src = _lit(terms[-1])
    for coef in reversed(terms[:-1]):
        src = f"{_lit(coef)} + {h} * ({src})" if coef != 0.0 else f"{h} * ({src})"
    return src
