"""Code-generation targets: one capabilities record per target and per Structured Text dialect.

Everything that differs between the languages the IR is printed in - whether ``POW`` exists
(else ``x**y`` is built as ``EXP(y * LN(x))``), how NaN and infinities are written (or that
they must be avoided), which intrinsic functions exist and how they are spelled, identifier
rules, comment syntax, number format, string escaping, file extensions, the CLI choice - is a
field of a :class:`Target` here.  The program builders and renderers read the record; nothing
else compares target or dialect names.

A new target is a record in :data:`TARGETS` (its ``cli`` field makes it a ``codegen --lang``
choice, ``generator`` names the function the CLI calls) and a renderer (a subclass of
:class:`fuzzyctl.ir.render.printer.Printer`).  A new Structured Text dialect is a record in
:data:`DIALECTS` (``dataclasses.replace`` of :data:`ST`).

This module imports nothing of fuzzyctl but :mod:`fuzzyctl.escape` (the escaping functions
the records name), so every layer may read it.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from fuzzyctl.escape import (
    C_KEYWORDS,
    PY_KEYWORDS,
    RESERVED,
    CodegenError,
    c_comment,
    c_ident,
    c_string,
    py_ident,
    py_str,
    st_comment,
    st_ident,
    st_ident_iec,
    st_string,
)

__all__ = [
    "ALIASES",
    "DIALECTS",
    "FMU",
    "NP",
    "PLCOPEN",
    "PY",
    "ST",
    "TARGETS",
    "C",
    "Comments",
    "Identifiers",
    "Numbers",
    "Target",
    "cli_choices",
    "cli_target",
    "dialect",
    "dialect_names",
    "get",
    "incomplete",
    "st_real",
]


# --------------------------------------------------------------------------- parts of a record


@dataclass(frozen=True)
class Numbers:
    """How literals are written.  ``real`` writes a finite REAL without the parentheses a
    negative one gets where ``negative_parens`` (C, ST: ``x - (-1.0)``); ``nan`` / ``inf``
    are the spellings of NaN and +infinity, None where the target has none (the builder then
    refuses what would need them)."""

    real: Callable[[float], str]
    nan: str | None
    inf: str | None
    negative_parens: bool
    single_suffix: str = ""  # appended to a REAL literal of the single-precision build
    true: str = "TRUE"
    false: str = "FALSE"

    @property
    def nonfinite(self) -> bool:
        """NaN and infinities can be written."""
        return self.nan is not None and self.inf is not None


@dataclass(frozen=True)
class Identifiers:
    """Identifier rules: ``check(name, what)`` returns ``name`` or raises
    :class:`~fuzzyctl.escape.CodegenError` naming ``what`` (syntax, length, reserved words);
    ``interface_room`` characters of ``max_length`` are kept free for the suffixes the
    renderer appends to an interface name (C: ``NAME_step``, ``NAME_real``)."""

    check: Callable[[str, str], str]
    reserved: frozenset[str]
    max_length: int
    case_sensitive: bool = True
    interface_room: int = 0

    @property
    def interface_length(self) -> int:
        """The longest name of the generated interface (block, inputs, outputs)."""
        return self.max_length - self.interface_room


@dataclass(frozen=True)
class Comments:
    """``open + escape(text) + close``; ``escape`` makes model text inert (one line that
    cannot close the comment: :mod:`fuzzyctl.escape`)."""

    open: str
    close: str
    escape: Callable[[str], str]

    def __call__(self, text: str, lead: str = "") -> str:
        """One comment; ``lead`` is generated text put before the escaped ``text``."""
        return f"{self.open}{lead}{self.escape(text)}{self.close}"


# --------------------------------------------------------------------------- the record


@dataclass(frozen=True)
class Target:
    """The capabilities of one code-generation target (or Structured Text dialect)."""

    name: str  # registry key (a dialect's own name for a dialect)
    label: str  # the language in messages: "... in generated {label}"
    language: str  # the program builder's target: st, c, py or np (a dialect: st)
    numbers: Numbers
    #: intrinsic (ir.Call name) -> spelling, in the order messages list them; an intrinsic
    #: missing here does not exist on the target (POW missing: powers are EXP(y * LN(x)))
    functions: Mapping[str, str]
    function_noun: str  # what an intrinsic is called in messages ("no {function_noun}")
    to_real: str  # INT -> REAL, a template: {0} the operand, {real} the REAL type
    real_types: tuple[str, str]  # (single precision, double precision)
    operators: Mapping[str, str]  # IR operator -> spelling; a template with {0} {1} is a call
    neg: str  # template of unary minus ({0}: the operand)
    not_: str  # template of NOT
    identifiers: Identifiers
    comments: Comments
    string: Callable[[str], str]  # a string literal, quotes included
    extensions: tuple[str, ...]  # of the files written, main file first
    int_mod: str | None = None  # template of an INT modulo, None: none
    library: frozenset[str] = frozenset()  # functions taken from the system library (C: libm)
    parenthesise_all: bool = False  # every binary operation in parentheses (no precedence)
    #: kernels (ir.Kernel routines) the renderer provides; the builder refuses or expands
    #: the others in the IR
    kernels: frozenset[str] = frozenset()
    function_terms: bool = True  # function terms inline as IR (else the EXPR kernel)
    data_dependent_loops: bool = True  # loops may run a number of times the input decides
    type2: bool = False  # generates interval type-2 systems (codegen/type2.py; else refused, docs/type2.md)
    # --- the CLI (``fuzzyctl codegen --lang``); None: not a CLI choice
    cli: str | None = None
    cli_help: str = ""
    generator: str = ""  # "module:function" the CLI calls
    cli_options: frozenset[str] = frozenset()  # of CLI_OPTIONS
    report: bool = False  # the generator fills a rename/--default report (--json)
    # --- Structured Text block conventions (dialects)
    cli_dialect_help: str = ""  # the dialect as --dialect's help lists it
    var_prefix: str = ""  # before every block variable (SCL: #)
    regions: bool = False  # Region as REGION ... END_REGION (else a comment)
    for_as_while: bool = False  # FOR as WHILE (matiec runs FOR i := a TO a zero times)
    block_name_quote: str = ""
    block_head: tuple[str, ...] = ()  # lines after the FUNCTION_BLOCK line
    body_keyword: str | None = None  # the line before the statements (SCL: BEGIN)
    body_indent: int = 0
    temp_arrays: bool = False  # VAR_TEMP may hold arrays without initial value
    testbench: bool = True
    #: targets that cannot hold the dialect's text: target name -> why (a sentence)
    refused_by: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}))
    plcopen_p_form: bool = False  # its tools read formatted text from <xhtml:p> only

    # ------------------------------------------------------------------ literals

    def real(self, v: float, single: bool = False, parens: bool = True) -> str:
        """A REAL literal; a non-finite value the target cannot write is refused."""
        n = self.numbers
        if not math.isfinite(v):
            spelled = n.nan if math.isnan(v) else n.inf
            if spelled is None:
                raise CodegenError(f"the value {v} cannot be written in portable {self.label}")
            return spelled if math.isnan(v) or v > 0 else f"(-{spelled})"
        s = n.real(v) + n.single_suffix if single else n.real(v)
        return f"({s})" if parens and n.negative_parens and v < 0 else s

    def integer(self, v: int) -> str:
        return f"({v})" if self.numbers.negative_parens and v < 0 else str(v)

    def boolean(self, v: bool) -> str:
        return self.numbers.true if v else self.numbers.false

    def comment(self, text: str, lead: str = "") -> str:
        return self.comments(text, lead)

    def has(self, function: str) -> bool:
        """The intrinsic ``function`` exists on the target."""
        return function in self.functions

    def function_list(self) -> str:
        """The intrinsics as a message lists them: ``EXP, LN or SQRT``."""
        names = list(self.functions)
        return ", ".join(names[:-1]) + (" or " if len(names) > 1 else "") + names[-1]

    def real_type(self, single: bool) -> str:
        return self.real_types[0 if single else 1]


# --------------------------------------------------------------------------- number formats


def st_real(v: float) -> str:
    """A REAL literal with the decimal point IEC requires (``1.0E-5``, never ``1e-05``)."""
    if not math.isfinite(v):
        raise CodegenError(f"the value {v} cannot be written in portable Structured Text")
    s = repr(float(v)).upper()
    mant, _, exp = s.partition("E")
    if "." not in mant:
        mant += ".0"
    return mant + ("E" + exp if exp else "")


def _c_real(v: float) -> str:
    s = repr(float(v))
    return s if "e" in s or "." in s else s + ".0"


def _py_real(v: float) -> str:
    """``repr`` round-trips exactly."""
    return repr(float(v))


# --------------------------------------------------------------------------- the records

_IEC_FUNCTIONS = ("EXP", "LN", "LOG", "SQRT", "ABS", "SIN", "COS", "TAN", "ASIN", "ACOS", "ATAN")
_PRECEDENCE_OPS = MappingProxyType({"=": "=", "<>": "<>", "AND": "AND", "OR": "OR"})

#: IEC 61131-3 Structured Text (the portable subset CODESYS and TwinCAT accept).
ST = Target(
    name="st",
    label="Structured Text",
    type2=True,
    language="st",
    numbers=Numbers(real=st_real, nan=None, inf=None, negative_parens=True),
    functions=MappingProxyType({f: f for f in _IEC_FUNCTIONS}),
    function_noun="IEC 61131-3 standard function",
    to_real="INT_TO_{real}({0})",
    real_types=("REAL", "LREAL"),
    operators=_PRECEDENCE_OPS,
    neg="-{0}",
    not_="NOT {0}",
    identifiers=Identifiers(st_ident, RESERVED, 24, case_sensitive=False),
    comments=Comments("(* ", " *)", st_comment),
    string=st_string,
    extensions=(".st",),
    cli="st",
    cli_help="Structured Text",
    generator="fuzzyctl.codegen.api:generate_st",
    cli_options=frozenset({"dialect", "lreal", "testbench", "arith", "lookup"}),
    report=True,
    cli_dialect_help="codesys (default)",
)

#: Structured Text dialects (``--dialect``); the first is the default.
DIALECTS: Mapping[str, Target] = MappingProxyType(
    {
        "codesys": dataclasses.replace(ST, name="codesys"),
        "twincat": dataclasses.replace(ST, name="twincat", cli_dialect_help="twincat"),
        "scl": dataclasses.replace(
            ST,
            name="scl",
            extensions=(".scl",),
            var_prefix="#",
            regions=True,
            block_name_quote='"',
            block_head=("{ S7_Optimized_Access := 'TRUE' }", "VERSION : 0.1"),
            body_keyword="BEGIN",
            body_indent=1,
            temp_arrays=True,
            testbench=False,
            refused_by=MappingProxyType({"plcopen": "TIA Portal does not import PLCopen XML"}),
            cli_dialect_help="scl (TIA Portal, st only)",
        ),
        "iec": dataclasses.replace(
            ST,
            name="iec",
            identifiers=Identifiers(st_ident_iec, RESERVED, 24, case_sensitive=False),
            for_as_while=True,
            plcopen_p_form=True,
            cli_dialect_help=(
                "iec (strict IEC 61131-3 as OpenPLC's compiler matiec accepts it; alias openplc)"
            ),
        ),
    }
)
#: Other names of a dialect: OpenPLC (and Beremiz) compile strict IEC 61131-3 with matiec.
ALIASES: Mapping[str, str] = MappingProxyType({"openplc": "iec"})

#: The same blocks as PLCopen TC6 XML 2.01 (Structured Text inside).
PLCOPEN = dataclasses.replace(
    ST,
    name="plcopen",
    extensions=(".xml",),
    cli="plcopen",
    cli_help="the same as PLCopen TC6 XML",
    generator="fuzzyctl.codegen.plcopen:generate_plcopen",
    cli_options=frozenset({"dialect", "lreal", "arith", "lookup"}),
    report=False,
)

_C_HELPERS = {
    "LN": "fz_log",
    "LOG": "fz_log10",
    "SQRT": "fz_sqrt",
    "ABS": "fz_fabs",
    "SIN": "fz_sin",
    "COS": "fz_cos",
    "TAN": "fz_tan",
    "ASIN": "fz_asin",
    "ACOS": "fz_acos",
    "ATAN": "fz_atan",
    "SINH": "fz_sinh",
    "COSH": "fz_cosh",
    "TANH": "fz_tanh",
    "FLOOR": "fz_floor",
    "CEIL": "fz_ceil",
    "RINT": "fz_rint",
    "POW": "fz_pow",
    "ATAN2": "fz_atan2",
    "FMOD": "fz_fmod",
}

#: C99: the PLC block as ``NAME.h`` / ``NAME.c``, and the native evaluator of ``compile()``.
#: libm only for ``exp``; the other intrinsics are static helpers (ir/render/c_helpers.py).
C = Target(
    name="c",
    label="C",
    type2=True,
    language="c",
    numbers=Numbers(
        real=_c_real, nan="NAN", inf="INFINITY", negative_parens=True, single_suffix="f", true="1", false="0"
    ),
    functions=MappingProxyType({"EXP": "exp", **_C_HELPERS}),
    function_noun="function of the generated C",
    library=frozenset({"EXP"}),
    to_real="(({real}){0})",
    int_mod="({0} % {1})",
    real_types=("float", "double"),
    operators=MappingProxyType({"OR": "||", "AND": "&&", "=": "==", "<>": "!="}),
    neg="-{0}",
    not_="!{0}",
    identifiers=Identifiers(c_ident, C_KEYWORDS, 63, interface_room=8),
    comments=Comments("/* ", " */", c_comment),
    string=c_string,
    extensions=(".h", ".c"),
    kernels=frozenset({"HOLD"}),  # the native builder writes every other kernel in the IR
    cli="c",
    cli_help="C99",
    generator="fuzzyctl.codegen.api:generate_c",
    cli_options=frozenset({"float", "testbench", "arith", "lookup"}),
    report=True,
)

#: The native evaluator of ``compile()`` (ir/render/c.py ``render_native``): the C above,
#: compiled on the host with its libm, whose ``sqrt`` is the correctly rounded square root
#: (the reference's ``math.sqrt``, one instruction): the CoA's root costs no Newton
#: iterations.  Not a CLI choice.
NATIVE_C = dataclasses.replace(
    C,
    name="native",
    label="native C",
    functions=MappingProxyType({**C.functions, "SQRT": "sqrt"}),
    library=C.library | {"SQRT"},
    cli=None,
    cli_help="",
    generator="",
    cli_options=frozenset(),
    report=False,
)

_PY_KERNELS = frozenset({"HOLD", "AM_LINES", "SELECT", "EXPR", "MEMBER", "TS", "MAMDANI"})

#: The evaluator of ``compile()`` as one Python function (ir/render/pysrc.py).
PY = Target(
    name="py",
    label="Python",
    language="py",
    numbers=Numbers(real=_py_real, nan="_NAN", inf="_INF", negative_parens=False, true="True", false="False"),
    functions=MappingProxyType(
        {
            "EXP": "_m.exp",
            "SQRT": "_m.sqrt",
            "LN": "_m.log",
            "LOG": "_m.log10",
            "ABS": "abs",
            "SIN": "_m.sin",
            "COS": "_m.cos",
            "TAN": "_m.tan",
            "ASIN": "_m.asin",
            "ACOS": "_m.acos",
            "ATAN": "_m.atan",
            "POW": "_m.pow",
        }
    ),
    function_noun="Python intrinsic",
    to_real="float({0})",
    int_mod="({0} % {1})",
    real_types=("float", "float"),
    operators=MappingProxyType({"=": "==", "<>": "!=", "AND": "and", "OR": "or"}),
    neg="(-{0})",
    not_="(not {0})",
    parenthesise_all=True,
    identifiers=Identifiers(py_ident, PY_KEYWORDS, 1000),
    comments=Comments("# ", "", c_comment),
    string=py_str,
    extensions=(".py",),
    kernels=_PY_KERNELS,
    function_terms=False,
)

#: The batch evaluator of ``compile()`` as numpy, if-converted (ir/render/npsrc.py);
#: transcendental functions as libm computes them (engine/semantics/libm_np.py says why).
NP = dataclasses.replace(
    PY,
    name="np",
    label="numpy",
    language="np",
    functions=MappingProxyType(
        {
            "EXP": "_libm.exp",
            "SQRT": "_np.sqrt",
            "LN": "_libm.log",
            "LOG": "_libm.log10",
            "ABS": "_np.abs",
            "SIN": "_libm.sin",
            "COS": "_libm.cos",
            "TAN": "_libm.tan",
            "ASIN": "_libm.asin",
            "ACOS": "_libm.acos",
            "ATAN": "_libm.atan",
            "POW": "_libm.pow_",
        }
    ),
    to_real="_real({0})",
    int_mod=None,
    operators=MappingProxyType({"=": "==", "<>": "!=", "AND": "_and({0}, {1})", "OR": "_or({0}, {1})"}),
    not_="_not({0})",
    data_dependent_loops=False,  # one program for every sample: no branch on a degree
)

#: An FMI 2/3 co-simulation FMU: the PLC block's C inside the Reference FMUs' framework
#: (fuzzyctl.codegen.fmu), one block, in double.
FMU = dataclasses.replace(
    C,
    name="fmu",
    label="FMU",
    type2=False,  # (the FMU wraps the type-1 block)
    extensions=(".fmu",),
    cli="fmu",
    cli_help="an FMI co-simulation FMU (sources and this platform's binary)",
    generator="fuzzyctl.codegen.fmu:generate_fmu",
    cli_options=frozenset({"fmi"}),
    report=False,
)

#: Every target, by name: the program builders' (st, c, py, np) and the CLI's (plcopen, fmu).
TARGETS: Mapping[str, Target] = MappingProxyType(
    {"st": ST, "plcopen": PLCOPEN, "c": C, "fmu": FMU, "py": PY, "np": NP}
)


# --------------------------------------------------------------------------- lookups


def get(name: str) -> Target:
    """The record of target ``name``."""
    try:
        return TARGETS[name]
    except KeyError:
        raise CodegenError(f"unknown code generation target {name!r} (known: {', '.join(TARGETS)})") from None


def dialect(name: str) -> Target:
    """The record of Structured Text dialect ``name`` (an alias gives its dialect's record)."""
    record = DIALECTS.get(ALIASES.get(name, name))
    if record is None:
        raise CodegenError(f"unknown dialect {name!r} (known: {', '.join(dialect_names())})")
    return record


def dialect_names() -> tuple[str, ...]:
    """Every ``--dialect`` value, aliases after the dialects."""
    return (*DIALECTS, *ALIASES)


def cli_choices() -> tuple[str, ...]:
    """The ``codegen --lang`` choices, in registry order."""
    return tuple(t.cli for t in TARGETS.values() if t.cli is not None)


def cli_target(choice: str) -> Target:
    """The record behind a ``--lang`` choice."""
    for t in TARGETS.values():
        if t.cli == choice:
            return t
    raise CodegenError(f"unknown --lang {choice!r} (known: {', '.join(cli_choices())})")


# --------------------------------------------------------------------------- completeness

#: Intrinsics every builder needs (smooth shapes, CoA, the POW fallback EXP(y * LN(x))).
CORE_FUNCTIONS = frozenset({"EXP", "LN", "SQRT", "ABS"})
#: CLI options a target may accept.
#: ``lookup`` also admits ``--tolerance`` and ``--max-bytes`` (they go with it).
CLI_OPTIONS = frozenset({"dialect", "lreal", "float", "testbench", "fmi", "arith", "lookup"})


def incomplete(t: Target) -> list[str]:
    """What record ``t`` lacks or gets wrong (empty when complete): a test walks every
    record of :data:`TARGETS` and :data:`DIALECTS`."""
    out: list[str] = []
    for f in dataclasses.fields(t):
        value = getattr(t, f.name)
        if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING and not value:
            out.append(f"{f.name} is empty")
    missing = sorted(CORE_FUNCTIONS - set(t.functions))
    if missing:
        out.append(f"functions lack {', '.join(missing)}")
    if not t.to_real or "{0}" not in t.to_real:
        out.append("to_real is no template with {0}")
    for op in ("=", "<>", "AND", "OR"):
        if op not in t.operators:
            out.append(f"operators lack {op}")
    if "{0}" not in t.neg or "{0}" not in t.not_:
        out.append("neg / not_ are no templates with {0}")
    try:
        if t.numbers.real(0.5) in ("", None):
            out.append("numbers.real writes nothing")
    except Exception as exc:
        out.append(f"numbers.real fails: {exc}")
    close = t.comments.close.strip()
    if close and close in t.comments.escape(f"a {close} b"):
        out.append("comments.escape lets the closing delimiter through")
    if not t.comments.open.strip():
        out.append("comments.open is empty")
    ids = t.identifiers
    if ids.max_length <= ids.interface_room or ids.max_length < 8:
        out.append("identifiers.max_length too small")
    try:
        ids.check("FZ_T1", "probe")
    except CodegenError:
        out.append("identifiers.check refuses the generated name FZ_T1")
    for word in sorted(ids.reserved)[:50]:
        try:
            ids.check(word, "probe")
        except CodegenError:
            continue
        out.append(f"identifiers.check accepts the reserved word {word}")
        break
    if not all(e.startswith(".") for e in t.extensions):
        out.append("extensions must start with '.'")
    if t.cli is not None:
        if not t.generator or ":" not in t.generator or not t.cli_help:
            out.append("a CLI choice needs generator ('module:function') and cli_help")
        if not t.cli_options <= CLI_OPTIONS:
            out.append(f"cli_options beyond {sorted(CLI_OPTIONS)}")
    if t.language not in TARGETS:
        out.append(f"language {t.language!r} is no builder target")
    return out
