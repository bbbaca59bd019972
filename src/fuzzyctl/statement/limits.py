"""Table 11 (6.2), the data check list, for the system as a whole.

fuzzyctl's own limits are probes: a generated program of a stated size (32 inputs, 1000 rules,
nesting depth 32, identifiers of 255 characters, ...) loads and evaluates, so the answer is
"no fixed limit (tested: ...)".  The Siemens S7 FUZZY block's and the Schneider XFUZ block's
limits are the constants their modules enforce (the ``siemens`` profile, the XFUZ tables),
read here, so a change there changes the statement.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from fuzzyctl.fcl import conformance, load_text
from fuzzyctl.model import Document
from fuzzyctl.statement.probes import BASE, SLOTS

__all__ = ["LimitRow", "limit_rows"]


def _tent(points: int, left: float) -> str:
    """A term of ``points`` points from ``left`` to ``left + 2``, peaking at 1 in the middle."""
    out = []
    for i in range(points):
        u = i / (points - 1) if points > 1 else 0.5
        out.append(f"({left + 2 * u:.6g}, {1 - abs(2 * u - 1):.6g})")
    return " ".join(out)


def _program(
    *,
    inputs: int = 1,
    terms: int = 2,
    points: int = 3,
    outputs: int = 1,
    out_terms: int = 2,
    out_points: int = 1,
    blocks: int = 1,
    rules: int = 2,
    sub: int = 1,
    concl: int = 1,
    depth: int = 0,
    name: int = 2,
) -> str:
    """A generated program of the given size; ``name`` is the length of every identifier."""
    pad = "x" * max(0, name - 2)
    iv = [f"i{k}{pad}" for k in range(inputs)]
    tv = [f"t{k}{pad}" for k in range(max(terms, out_terms))]
    ov = [f"o{k}{pad}" for k in range(outputs)]
    lines = ["FUNCTION_BLOCK limits", "VAR_INPUT", *[f"    {v} : REAL;" for v in iv], "END_VAR"]
    lines += ["VAR_OUTPUT", *[f"    {v} : REAL;" for v in ov], "END_VAR"]
    for v in iv:
        lines += [
            f"FUZZIFY {v}",
            *[f"    TERM {tv[j]} := {_tent(points, 2 * j)};" for j in range(terms)],
            "END_FUZZIFY",
        ]
    for v in ov:
        lines.append(f"DEFUZZIFY {v}")
        if out_points == 1:
            lines += [f"    TERM {tv[j]} := {j};" for j in range(out_terms)]
            lines += ["    METHOD : CoGS;", "    DEFAULT := 0;"]
        else:
            lines += [f"    TERM {tv[j]} := {_tent(out_points, 2 * j)};" for j in range(out_terms)]
            lines += [f"    RANGE(0..{2 * out_terms + 2});", "    METHOD : CoG;", "    DEFAULT := 0;"]
        lines.append("END_DEFUZZIFY")
    for b in range(blocks):
        lines += [f"RULEBLOCK b{b}", "    AND : MIN;", "    ACCU : MAX;"]
        for r in range(rules):
            conds = [f"{iv[(r + k) % inputs]} IS {tv[(r + k) % terms]}" for k in range(sub)]
            cond = " AND ".join(conds)
            for _ in range(depth):
                cond = f"({cond} OR {iv[0]} IS {tv[1 % terms]}) AND {iv[0]} IS {tv[0]}"
            then = ", ".join(f"{ov[(r + k) % outputs]} IS {tv[(r + k) % out_terms]}" for k in range(concl))
            lines.append(f"    RULE {r + 1} : IF {cond} THEN {then};")
        lines.append("END_RULEBLOCK")
    lines.append("END_FUNCTION_BLOCK")
    return "\n".join(lines) + "\n"


@dataclass(frozen=True)
class LimitRow:
    """One line of Table 11: the item, fuzzyctl's answer (a probe), the Siemens FUZZY block's
    and the XFUZ block's (the constants their modules enforce)."""

    item: str
    fuzzyctl: str
    siemens: str
    xfuz: str


def _probe_size(text: str, what: str, check: Callable[[Document], bool] | None = None) -> str:
    """``no fixed limit; tested: <what>`` when the program loads, passes ``check`` and
    evaluates, else why not."""
    import fuzzyctl

    result = load_text(text)
    if not result.ok or result.document is None:
        first = next((d.message for d in result.diagnostics if d.is_error), "does not load")
        return f"{what}: refused ({first})"
    doc = result.document
    if check is not None and not check(doc):
        raise RuntimeError(f"statement: the Table 11 probe for {what} is not what it says")
    try:
        out = fuzzyctl.compile(doc, out_of_range="ignore").evaluate(
            dict.fromkeys((v.name for v in doc.main.inputs), 1.0)
        )
    except Exception as exc:  # an engine refusal is the answer
        return f"{what}: refused ({str(exc).splitlines()[0]})"
    if not all(math.isfinite(v) or math.isnan(v) for v in out.values()):
        return f"{what}: no number"
    return f"no fixed limit (tested: {what})"


_TYPES = (
    "REAL",
    "LREAL",
    "SINT",
    "INT",
    "DINT",
    "LINT",
    "USINT",
    "UINT",
    "UDINT",
    "ULINT",
    "BYTE",
    "WORD",
    "DWORD",
    "BOOL",
)


def _types() -> str:
    """The IEC 61131-3 elementary types a program's inputs and outputs may have."""
    ok = []
    for t in _TYPES:
        text = (
            BASE.substitute(SLOTS)
            .replace("    x : REAL;", f"    x : {t};")
            .replace("    z : REAL;", f"    z : {t};")
        )
        if _probe_size(text, t).startswith("no fixed limit"):
            ok.append(t)
    return ", ".join(ok) + " (computed as IEEE double; generated code REAL or LREAL)"


def _comments() -> str:
    styles = {"(* *)": "(* c *)", "//": "// c", "/* */": "/* c */"}
    base = BASE.substitute(SLOTS)
    ok = [k for k, c in styles.items() if load_text(f"{c}\n{base}").ok]
    return "YES: " + ", ".join(ok)


def limit_rows() -> list[LimitRow]:
    """Table 11 for the system as a whole: fuzzyctl, the Siemens FUZZY block, XFUZ."""
    from fuzzyctl.blocks.schneider.fb import DEGRE_FULL
    from fuzzyctl.blocks.siemens.profile import LIMITS
    from fuzzyctl.formats.xfuz import tables as xt
    from fuzzyctl.io.s7 import FUZZY_DB

    s_in, s_terms, s_out, s_oterms = (
        LIMITS["inputs"],
        LIMITS["input_terms"],
        LIMITS["outputs"],
        LIMITS["output_terms"],
    )
    s_types = sorted(
        {kind.upper() for name, (_o, kind) in FUZZY_DB.items() if name.startswith(("INPUT", "OUTPUT"))}
    )
    names = (
        f"project {LIMITS['project_name']}, variables {LIMITS['variable_name']}, terms {LIMITS['term_name']} "
        "(significant characters)"
    )
    inputs = _probe_size(
        _program(inputs=32, terms=8, rules=32, sub=32),
        "32 inputs of 8 terms (256 terms), 32 subconditions a rule",
    )
    outputs = _probe_size(_program(outputs=32, out_terms=2, concl=32), "32 outputs, 32 subconclusions a rule")
    terms = _probe_size(_program(terms=128, out_terms=128), "128 terms on an input and on an output")
    in_pts = _probe_size(_program(points=500), "500 points an input term")
    out_pts = _probe_size(_program(out_points=32), "32 points an output term")
    rules = _probe_size(_program(inputs=4, terms=8, rules=1000, sub=3), "1000 rules in a block")
    blocks = _probe_size(_program(blocks=32), "32 rule blocks")
    nest = _probe_size(
        _program(depth=32),
        "depth 32",
        lambda d: max(conformance.depth(r.condition) for _b, r in d.main.rules()) == 32,
    )
    name = _probe_size(_program(name=255), "255 characters", lambda d: len(d.main.inputs[0].name) == 255)
    R = LimitRow
    return [
        R(
            "data types of function block inputs and outputs",
            _types(),
            f"{', '.join(s_types)} (Tables 3-1, 3-2)",
            "INT (16-bit words)",
        ),
        R("line comments in the FCL program", _comments(), "FPL: /* */ (1.3)", "-"),
        R("execution time (ms)", "measured below", "measured below", "measured below"),
        R(
            "memory requirements (kb)",
            "measured below",
            "instance DB 2126 bytes (3.4)",
            "ESV/FA/RG constants",
        ),
        R(
            "mapping of weighting factors and degrees onto integers",
            "none: IEEE 754 double",
            "none: REAL",
            f"DEGRE 0..{DEGRE_FULL}, one byte a rule",
        ),
        R("length of identifiers", name, names, f"{2 * xt.NAME_WORDS} (terms, intermediate variables)"),
        R("max. number of input variables for fuzzification", inputs, str(s_in), str(xt.N_INPUTS)),
        R(
            "max. number of membership function terms per input variable",
            terms,
            str(s_terms),
            f"{xt.MAX_MF} functions in all",
        ),
        R(
            "max. total number of membership function terms for all input variables",
            inputs,
            str(s_in * s_terms),
            str(xt.MAX_MF),
        ),
        R(
            "max. number of points for the membership function of an input term",
            in_pts,
            "4 (rectangle, triangle, trapezoid)",
            "4",
        ),
        R(
            "max. total number of points for all input terms",
            in_pts,
            str(4 * s_in * s_terms),
            str(4 * xt.MAX_MF),
        ),
        R(
            "max. number of output variables for defuzzification",
            outputs,
            str(s_out),
            f"{xt.N_OUTPUTS} (+ {xt.N_VARS} intermediate)",
        ),
        R(
            "max. number of membership function terms per output variable",
            terms,
            str(s_oterms),
            f"{xt.MAX_MF} functions in all",
        ),
        R(
            "max. total number of membership function terms for all output variables",
            outputs,
            str(s_out * s_oterms),
            str(xt.MAX_MF),
        ),
        R(
            "max. number of points for the membership function of an output term",
            out_pts,
            "1 (singletons)",
            "4 (1 with OUT_PT = 1)",
        ),
        R(
            "max. total number of points for all output terms",
            out_pts,
            str(s_out * s_oterms),
            str(4 * xt.MAX_MF),
        ),
        R("max. number of rule blocks", blocks, "1", "1 (two inference levels through VAR1..4)"),
        R("max. number of rules per block", rules, str(LIMITS["rules"]), str(xt.MAX_RULES)),
        R(
            "max. number of subconditions per rule",
            inputs,
            f"{s_in} (one per input, AND)",
            str(xt.RULE_PREDICATES),
        ),
        R("max. number of all rules", rules, str(LIMITS["rules"]), str(xt.MAX_RULES)),
        R(
            "max. number of subconclusions per rule",
            outputs,
            f"{s_out} (one per output)",
            str(xt.RULE_CONCLUSIONS),
        ),
        R("nesting depth of ( )", nest, "0 (AND only)", "0 (AND only)"),
    ]
