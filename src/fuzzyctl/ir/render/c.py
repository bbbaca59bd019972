"""Print a :class:`~fuzzyctl.ir.nodes.Program` as C99: a header with the instance struct and
``NAME_init`` / ``NAME_step`` / ``NAME_batch``, and a source file.

No allocation, no globals besides constant tables; libm only for ``exp`` (smooth shapes):
``sqrt`` (exact CoA, some shapes and hedges), ``pow``, ``cos`` and the functions of function
terms are static helpers of :mod:`fuzzyctl.ir.render.c_helpers`, emitted only when used.
The native evaluator (:func:`render_native`, compiled on the host) takes ``sqrt`` from libm
too (:data:`fuzzyctl.kinds.targets.NATIVE_C`).
"""

from __future__ import annotations

import array
from collections.abc import Sequence

from fuzzyctl.escape import CodegenError, c_ident
from fuzzyctl.ir.nodes import (
    Assign,
    Bool,
    Call,
    Decl,
    Ex,
    For,
    If,
    Index,
    Kernel,
    Program,
    Pwl,
    Region,
    Stmt,
    Var,
    While,
    identifiers,
    subexprs,
)
from fuzzyctl.ir.programs.evaluator import FastProgram
from fuzzyctl.ir.render import c_helpers
from fuzzyctl.ir.render.printer import Printer
from fuzzyctl.kinds import targets

C = targets.C
# libm itself is used for ``exp`` only; every other intrinsic is one of the static helpers
# of :mod:`fuzzyctl.ir.render.c_helpers` (written with + - * / and exp), emitted on demand.
_LIBM = {f: C.functions[f] for f in C.library}


def _helper_of(target: targets.Target) -> dict[str, str]:
    """Intrinsic -> the static helper spelling it (those not taken from libm)."""
    return {f: spelled for f, spelled in target.functions.items() if f not in target.library}


_HELPER_OF = _helper_of(C)


def helper_functions(prog: Program) -> list[str]:
    """The static helpers the generated C defines (callees included, callees first)."""
    return c_helpers.closure({_HELPER_OF[f] for f in prog.uses if f in _HELPER_OF})


def libm_functions(prog: Program) -> list[str]:
    """The libm functions the generated C calls (documented in its header): ``exp`` or none."""
    direct = any(f in _LIBM for f in prog.uses)
    via_helpers = any(c_helpers.HELPERS[h].uses_exp for h in helper_functions(prog))
    return ["exp"] if direct or via_helpers else []


class _C(Printer):
    """C99 statements; block fields as ``fb->x``, constant tables as ``NAME_x``."""

    GROUP_AND_IN_OR = True

    def __init__(self, prog: Program, single: bool, target: targets.Target = C) -> None:
        super().__init__(target, real=f"{prog.name}_real", single=single)
        self.prog = prog
        self.fields = {d.name for d in prog.decls if d.storage in ("input", "output", "param", "state")}
        self.consts = {d.name for d in prog.decls if d.storage == "const"}

    def name(self, n: str) -> str:
        if n in self.consts:  # file-scope tables: unique per block (several blocks may share a unit)
            return f"{self.prog.name}_{n}"
        return f"fb->{n}" if n in self.fields else n

    def call(self, e: Call) -> str:
        if e.function in self.caps.library:  # libm: expf in the float build
            args = ", ".join(self.args(e))
            return f"{self.caps.functions[e.function]}{'f' if self.single else ''}({args})"
        text = super().call(e)
        # the helpers compute in double; the float build rounds their result once
        return f"(({self.real}){text})" if self.single and e.function in self.caps.functions else text

    def kernel(self, k: Kernel, ind: int) -> None:
        """The PLC block has no kernels (the native evaluator's are in :class:`_Native`)."""


_CTYPES = {"INT": "int", "DINT": "long", "BOOL": "unsigned char", "BYTE": "unsigned char"}


def _ctype(d: Decl, real: str) -> str:
    return {"REAL": real, **_CTYPES}[d.type]


def _read_names(body: Sequence[Stmt]) -> set[str]:
    """Names whose value is read somewhere (an assignment target itself is not a read)."""
    out: set[str] = set()

    def visit(e: Ex, top_target: bool) -> None:
        for sub in subexprs(e):
            if sub is e and top_target:
                if isinstance(e, Index):
                    visit(e.index, False)
                continue
            if isinstance(sub, Var | Index):
                out.add(sub.name)

    def rec(stmts: Sequence[Stmt]) -> None:
        for s in stmts:
            if isinstance(s, Assign):
                visit(s.target, True)
                visit(s.value, False)
            elif isinstance(s, If):
                for c, b in s.branches:
                    visit(c, False)
                    rec(b)
                rec(s.orelse)
            elif isinstance(s, For):
                out.add(s.var)
                visit(s.start, False)
                visit(s.stop, False)
                rec(s.body)
            elif isinstance(s, While):
                visit(s.cond, False)
                rec(s.body)
            elif isinstance(s, Region):
                rec(s.body)

    rec(body)
    return out


def _render_header(prog: Program, name: str, r: _C, single: bool) -> list[str]:
    """The header: the instance struct and the prototypes."""
    real = r.real
    guard = f"FUZZYCTL_{name.upper()}_H"
    h: list[str] = []
    h.append(r.comment(f"{name}.h - generated by fuzzyctl; do not edit (regenerate from the FCL)."))
    for line in prog.header:
        h.append(r.comment(line))
    h += [f"#ifndef {guard}", f"#define {guard}", "", "#include <stddef.h>", ""]
    h.append(f"typedef {'float' if single else 'double'} {real};")
    h.append("")
    h.append(
        r.comment(
            f"One instance of the function block: set the inputs, call {name}_step(), read the outputs."
        )
    )
    h.append("typedef struct {")
    for storage, title in (
        ("input", "inputs"),
        ("output", "outputs"),
        ("param", "tunable parameters (initialised by init; may be changed between steps)"),
        ("state", "internal state"),
    ):
        ds = prog.of(storage)  # type: ignore[arg-type]
        if not ds:
            continue
        h.append(f"    {r.comment(title)}")
        for d in ds:
            dim = f"[{d.size}]" if d.size is not None else ""
            note = d.comment.split("\n")[0]
            h.append(f"    {_ctype(d, real)} {d.name}{dim};" + (f" {r.comment(note)}" if note else ""))
    h.append(f"}} {name};")
    h.append("")
    n_in = len(prog.of("input")) - 1  # without ENABLE
    outs = [d for d in prog.of("output") if d.name != "INFO"]
    h.append(f"#define {name.upper()}_N_INPUTS {n_in}")
    h.append(f"#define {name.upper()}_N_OUTPUTS {len(outs)}")
    h.append("")
    h.append(r.comment("Set the parameters to the FCL's values, clear the state, ENABLE = 1."))
    h.append(f"void {name}_init({name} *fb);")
    h.append(r.comment(f"One evaluation (a PLC cycle); returns INFO: {prog.decl('INFO').comment}."))
    h.append(f"unsigned char {name}_step({name} *fb);")
    in_names = ", ".join(d.name for d in prog.of("input") if d.name != "ENABLE")
    out_names = ", ".join(d.name for d in outs)
    h.append(r.comment(f"n evaluations in a row: in[i*{n_in} + k] is input k ({in_names}) of row i,"))
    h.append(r.comment(f"out[i*{len(outs)} + k] output k ({out_names}); returns INFO of the last row."))
    h.append(f"unsigned char {name}_batch({name} *fb, size_t n, const double *in, double *out);")
    h.append("")
    h.append(f"#endif {r.comment(guard)}")
    return h


def render_c(prog: Program, *, single: bool = False, target: targets.Target = C) -> tuple[str, str]:
    """``(header, source)`` for ``prog``; ``single`` selects float instead of double;
    ``target`` is the C record (literals, comments, functions)."""
    name = c_ident(prog.name, "function block name")
    for d in prog.decls:  # model names become struct members: each one must be inert
        c_ident(d.name, "variable" if d.storage in ("input", "output") else "identifier")
    r = _C(prog, single, target)
    real = r.real
    h = _render_header(prog, name, r, single)
    outs = [d for d in prog.of("output") if d.name != "INFO"]

    c: list[str] = []
    c.append(r.comment(f"{name}.c - generated by fuzzyctl; do not edit (regenerate from the FCL)."))
    libs = libm_functions(prog)
    c.append(r.comment(f"libm functions used: {', '.join(libs) if libs else 'none'}"))
    helpers = helper_functions(prog)
    if helpers:
        c.append(r.comment(f"static helpers instead of libm (only + - * / and exp): {', '.join(helpers)}"))
    c += [f'#include "{name}.h"', "#include <math.h>", ""]
    for d in prog.of("const"):
        assert isinstance(d.init, tuple)
        vals = ", ".join(str(int(v)) if d.type != "REAL" else r.num(v) for v in d.init)
        c.append(f"static const {_ctype(d, real)} {r.name(d.name)}[{d.size}] = {{{vals}}};")
    c.append("")
    c += c_helpers.render(set(helpers))
    c.append(f"void {name}_init({name} *fb)")
    c.append("{")
    for d in prog.decls:
        if d.storage not in ("input", "output", "param", "state"):
            continue
        if d.size is None:
            one = d.init if isinstance(d.init, float | int | bool) else 0.0
            if isinstance(one, bool) or d.type != "REAL":
                c.append(f"    fb->{d.name} = {int(one)};")
            else:
                c.append(f"    fb->{d.name} = {r.num(float(one))};")
        else:
            values = d.init if isinstance(d.init, tuple) else (0.0,) * d.size
            for i, val in enumerate(values):
                c.append(f"    fb->{d.name}[{i}] = {r.num(val)};")
    c.append("}")
    c.append("")
    c.append(f"unsigned char {name}_step({name} *fb)")
    c.append("{")
    read = _read_names(prog.body)
    temps = prog.of("temp")
    for d in temps:  # zero-initialised: keeps -Wmaybe-uninitialized quiet at any -O
        if d.size is not None:
            c.append(f"    {_ctype(d, real)} {d.name}[{d.size}] = {{0}};")
        else:
            c.append(f"    {_ctype(d, real)} {d.name} = 0;")
    r.stmts(prog.body, 1)
    c += r.lines
    unread = [d.name for d in temps if d.name not in read]
    for n in unread:  # assigned but never read: keeps -Wall -Wextra -Werror quiet
        c.append(f"    (void){n};")
    c.append("    return fb->INFO;")
    c.append("}")
    c.append("")
    ins = [d.name for d in prog.of("input") if d.name != "ENABLE"]
    c.append(f"unsigned char {name}_batch({name} *fb, size_t n, const double *in, double *out)")
    c.append("{")
    c.append("    size_t i;")
    c.append("    (void)in;")
    c.append("    (void)out;")
    c.append("    for (i = 0; i < n; i++) {")
    for k, nm in enumerate(ins):
        c.append(f"        fb->{nm} = ({real})in[i * {len(ins)} + {k}];")
    c.append(f"        {name}_step(fb);")
    for k, d in enumerate(outs):
        c.append(f"        out[i * {len(outs)} + {k}] = (double)fb->{d.name};")
    c.append("    }")
    c.append("    return fb->INFO;")
    c.append("}")
    return "\n".join(h) + "\n", "\n".join(c) + "\n"


# --------------------------------------------------------------------------- the native evaluator


class _Native(_C):
    """The evaluator program of ``compile()`` (:mod:`fuzzyctl.ir.programs.evaluator`) as C: one
    ``fz_row`` per evaluation, called by a loop over columns.  No name of the model appears
    (every variable is an ``FZ_`` identifier; comments are not printed)."""

    def __init__(self, fp: FastProgram) -> None:
        super().__init__(fp.program, False, targets.NATIVE_C)
        self.comments = False  # no model text in the native evaluator
        self.fp = fp
        self.real = "double"
        self.fields = set()
        self.state = fp.state
        self.pwl_funcs: dict[tuple[tuple[float, float], ...], str] = {}
        self.uses: set[str] = set()  # intrinsics the kernels call

    def name(self, n: str) -> str:
        if n in self.consts:
            return f"fz_c_{n}"
        if n == self.state:
            return "prev"
        return n

    def pwl(self, e: Pwl) -> str:
        return f"{self.pwl_func(e.points)}({self.ex(e.x)})"

    def pwl_func(self, points: tuple[tuple[float, float], ...]) -> str:
        if points not in self.pwl_funcs:
            self.pwl_funcs[points] = f"fz_pwl{len(self.pwl_funcs)}"
        return self.pwl_funcs[points]

    def kernel(self, k: Kernel, ind: int) -> None:
        if k.name == "HOLD":
            self.hold(k, ind)
        else:
            raise CodegenError(f"the native evaluator has no kernel {k.name}")

    def hold(self, k: Kernel, ind: int) -> None:
        oi, default, no_change, clamp = k.data
        out = self.ex(k.outs[0])
        value, fired = k.args
        if isinstance(fired, Bool) and fired.value:
            if self.ex(value) != out:
                self.emit(f"{out} = {self.ex(value)};", ind)
        else:
            alt = f"prev[{oi}]" if no_change else self.num(default)
            self.emit(f"{out} = ({self.ex(fired)}) ? {self.ex(value)} : {alt};", ind)
        if clamp is not None:
            lo, hi = clamp
            self.emit(f"if ({out} < {self.num(lo)}) {out} = {self.num(lo)};", ind)
            self.emit(f"else if ({out} > {self.num(hi)}) {out} = {self.num(hi)};", ind)
        self.emit(f"prev[{oi}] = {out};", ind)

    def pwl_code(self) -> list[str]:
        """One static function per breakpoint list (``shapes.pwl_value`` as an if-chain)."""
        from fuzzyctl.engine.lowering.grid import left_limit, right_limit
        from fuzzyctl.engine.semantics.shapes import pwl_value

        out: list[str] = []
        for pts, fname in self.pwl_funcs.items():
            n = self.num
            xs = sorted({q[0] for q in pts})
            out.append(f"static inline double {fname}(double x)\n{{")
            out.append(f"    if (x < {n(xs[0])}) return {n(pts[0][1])};")
            for k, u in enumerate(xs):
                pv = pwl_value(pts, u)
                jump = left_limit(pts, u) != right_limit(pts, u) or pv != left_limit(pts, u)
                if jump or k == 0:
                    out.append(f"    if (x == {n(u)}) return {n(pv)};")
                if k + 1 < len(xs):
                    u1 = xs[k + 1]
                    r0, l1 = right_limit(pts, u), left_limit(pts, u1)
                    if r0 == l1:
                        expr = n(r0)
                    else:
                        base = f"(x - {n(u)}) * {n((l1 - r0) / (u1 - u))}"
                        expr = base if r0 == 0.0 else f"{n(r0)} + {base}"
                    out.append(f"    if (x < {n(u1)}) return {expr};")
            out.append(f"    if (x == {n(xs[-1])}) return {n(pwl_value(pts, xs[-1]))};")
            out.append(f"    return {n(pts[-1][1])};\n}}\n")
        return out


#: Tables at least this long go to the native library as binary data (see render_native).
BINARY_TABLE_MIN = 64
_ARRAY_CODES = {"double": "d", "long": "l", "int": "i", "unsigned char": "B"}


def _binary_table(
    name: str, ctype: str, size: int, values: tuple[float, ...], tables: dict[str, bytes]
) -> str:
    """The declaration of a constant table whose bytes the assembler includes (``.incbin``)
    instead of the C compiler parsing a long initialiser: a 10,000-rule system's tables are
    960 KB of C text, 0.5 s of gcc at -O0 and 1.5 s at -O3, against nothing as data.  The
    file name is the table's (generated) name, in the build directory the compiler runs in."""
    code = _ARRAY_CODES[ctype]
    data = array.array(code, [int(v) for v in values] if code != "d" else [float(v) for v in values])
    fname = f"{name}.bin"
    tables[fname] = data.tobytes()
    return (
        f'extern const {ctype} {name}[{size}] __attribute__((visibility("hidden")));\n'
        f'__asm__(".pushsection .rodata\\n.balign 8\\n.globl {name}\\n.hidden {name}\\n'
        f'{name}:\\n.incbin \\"{fname}\\"\\n.popsection");'
    )


def render_native(fp: FastProgram, tables: dict[str, bytes] | None = None) -> str:
    """One C file: ``fz_row`` (one evaluation), ``fz_eval``, ``fz_batch`` (a loop over
    columns of rows) and ``fz_init`` (the NC state), exported for the native backend.

    With ``tables`` (a dict to fill; ELF targets with the GNU assembler), constant tables of
    :data:`BINARY_TABLE_MIN` entries or more are written there as ``{name}.bin`` files of the
    native byte order, which the C includes as data: the compiler must run in the directory
    holding them."""
    prog = fp.program
    # every name printed passes c_ident (they are the program's FZ_ names: a model name
    # reaching here is refused, never printed)
    for n in sorted(identifiers(prog) | {*fp.inputs, *fp.outputs, fp.state}):
        c_ident(n, "generated name")
    r = _Native(fp)
    r.stmts(prog.body, 1)
    body = r.lines
    c: list[str] = ["/* generated by fuzzyctl: the native evaluator; do not edit */"]
    c += ["#include <math.h>", "#include <stddef.h>"]
    c += ['#define FZ_API __attribute__((visibility("default")))', ""]
    for d in prog.of("const"):
        assert isinstance(d.init, tuple)
        ctype = {"REAL": "double", **_CTYPES}[d.type]
        if tables is not None and d.size is not None and d.size >= BINARY_TABLE_MIN:
            c.append(_binary_table(f"fz_c_{d.name}", ctype, d.size, d.init, tables))
            continue
        vals = ", ".join(str(int(v)) if d.type != "REAL" else r.num(v) for v in d.init)
        c.append(f"static const {ctype} fz_c_{d.name}[{d.size}] = {{{vals}}};")
    helper_of = _helper_of(r.caps)
    helpers = c_helpers.closure({helper_of[f] for f in prog.uses | r.uses if f in helper_of})
    c += c_helpers.render(set(helpers))
    c += r.pwl_code()
    n_out = len(fp.outputs)
    c.append(
        "static inline void fz_row(double *restrict prev, const double *restrict in, double *restrict out)"
    )
    c.append("{")
    for k, name in enumerate(fp.inputs):
        c.append(f"    double {name} = in[{k}];")
    for d in prog.of("output"):
        c.append(f"    double {d.name} = 0;")
    for d in prog.of("temp"):
        ctype = _ctype(d, "double")
        if d.size is not None:
            c.append(f"    {ctype} {d.name}[{d.size}] = {{0}};")
        else:
            c.append(f"    {ctype} {d.name} = 0;")
    c += body
    for k, name in enumerate(fp.outputs):
        c.append(f"    out[{k}] = {name};")
    c.append("    (void)prev;")
    c.append("}")
    c.append("")
    init = prog.decl(fp.state).init
    assert isinstance(init, tuple)
    c.append(f"FZ_API size_t fz_n_state(void) {{ return {len(init)}; }}")
    c.append("FZ_API void fz_init(double *prev)\n{")
    for i, v in enumerate(init):
        c.append(f"    prev[{i}] = {r.num(v)};")
    c.append("}")
    c.append("FZ_API void fz_eval(double *prev, const double *in, double *out)")
    c.append("{ fz_row(prev, in, out); }")
    n_in = max(1, len(fp.inputs))
    c.append("/* n rows: input k of row i is cols[k][i], output k of row i goes to outs[k][i] */")
    c.append("FZ_API void fz_batch(double *prev, size_t n, const double *const *cols, double *const *outs)")
    c.append("{")
    c.append(f"    double in[{n_in}] = {{0}}, out[{max(1, n_out)}];")
    c.append("    size_t i;")
    c.append("    for (i = 0; i < n; i++) {")
    for k in range(len(fp.inputs)):
        c.append(f"        in[{k}] = cols[{k}][i];")
    c.append("        fz_row(prev, in, out);")
    for k in range(n_out):
        c.append(f"        outs[{k}][i] = out[{k}];")
    c.append("    }")
    c.append("    (void)cols;")
    c.append("    (void)outs;")
    c.append("}")
    return "\n".join(c) + "\n"
