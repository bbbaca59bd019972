"""The language elements of Tables 8, 9 and 10, each with a probe program.

A probe is the Basic-level program :data:`BASE` with some of its slots replaced.  Running it
(:func:`run_probe`) loads it, checks that :func:`fuzzyctl.fcl.conformance.features` finds the
element at the level the statement gives (else RuntimeError: the statement and ``fuzzyctl
check`` never disagree), evaluates it with the engine and asks the code generators for ST and
C.  The catalogue lists the standard's elements one by one and generates the Open level rows
of what the model knows (every shape of :data:`fuzzyctl.model.SHAPES`, every operator of its
keyword sets), so that a shape or an operator added to fuzzyctl appears here by itself.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from string import Template

from fuzzyctl.fcl import conformance, load_text
from fuzzyctl.fcl.conformance import Level
from fuzzyctl.kinds.shapes import ENTRIES
from fuzzyctl.model import ACCU_METHODS, ACT_METHODS, AND_OPERATORS, OR_OPERATORS, SHAPES, Document, ShapeMF

__all__ = ["BASE", "SHAPE_PARAMS", "SLOTS", "Probe", "ProbeResult", "element_rows", "probes", "run_probe"]

BASE = Template(
    """FUNCTION_BLOCK probe
VAR_INPUT
    x : REAL;
    y : REAL;$inputs
END_VAR
VAR_OUTPUT
    z : REAL;$outputs
END_VAR
$locals
FUZZIFY x
$xrange    TERM lo := $xlo;
    TERM hi := (0, 0) (10, 1);
END_FUZZIFY
FUZZIFY y
    TERM lo := (0, 1) (10, 0);
    TERM hi := (0, 0) (10, 1);
END_FUZZIFY
DEFUZZIFY z
$zterms
$zitems
END_DEFUZZIFY
$blocks
RULEBLOCK r
$ops
$rules
END_RULEBLOCK
$more
END_FUNCTION_BLOCK
$after"""
)
"""A Basic-level program (Table 8) with slots for what a probe changes."""
SLOTS = {
    "inputs": "",
    "outputs": "",
    "locals": "",
    "xrange": "",
    "xlo": "(0, 1) (10, 0)",
    "zterms": "    TERM a := 0;\n    TERM b := 10;",
    "zitems": "    METHOD : CoGS;\n    DEFAULT := 0;",
    "blocks": "",
    "ops": "    AND : MIN;\n    ACCU : MAX;",
    "rules": "    RULE 1 : IF x IS lo AND y IS lo THEN z IS a;\n    RULE 2 : IF x IS hi THEN z IS b;",
    "more": "",
    "after": "",
}
_AREA = "    TERM a := (0, 0) (2, 1) (4, 0);\n    TERM b := (6, 0) (8, 1) (10, 0);"
_AREA_ITEMS = "    RANGE(0..10);\n    METHOD : {m};\n    DEFAULT := 0;"
_OR_RULES = "    RULE 1 : IF x IS lo OR y IS lo THEN z IS a;\n    RULE 2 : IF x IS hi THEN z IS b;"
_W_BLOCK = (
    "DEFUZZIFY w\n    TERM c := 5;\n    TERM d := 8;\n    METHOD : CoGS;\n    DEFAULT := 0;\nEND_DEFUZZIFY"
)
_CHAINED = (
    "DEFUZZIFY m\n    TERM p := (0, 1) (1, 0);\n    TERM q := (0, 0) (1, 1);\n    RANGE(0..1);\n"
    "    METHOD : CoG;\n    DEFAULT := 0;\nEND_DEFUZZIFY\nRULEBLOCK first\n    AND : MIN;\n    ACCU : MAX;\n"
    "    RULE 1 : IF x IS lo THEN m IS p;\n    RULE 2 : IF x IS hi THEN m IS q;\nEND_RULEBLOCK"
)


def _rules(first: str, second: str = "IF x IS hi THEN z IS b") -> str:
    return f"    RULE 1 : {first};\n    RULE 2 : {second};"


@dataclass(frozen=True)
class Probe:
    """One language element, and the slots of :data:`BASE` a program using it changes."""

    table: str  # "Table 8", "Table 9", "Table 10"
    element: str  # the language element, as the standard's tables name it
    detail: str
    feature: tuple[str, str] | None  # what conformance.features must report (None: Basic)
    slots: dict[str, str] = field(default_factory=dict)

    @property
    def level(self) -> Level:
        return {"Table 8": Level.BASIC, "Table 9": Level.EXTENSION}.get(self.table, Level.OPEN)

    def text(self) -> str:
        return BASE.substitute({**SLOTS, **self.slots})


def _p(table: str, element: str, detail: str, feature: tuple[str, str] | None = None, **slots: str) -> Probe:
    return Probe(table, element, detail, feature, slots)


def _basic() -> list[Probe]:
    t = "Table 8"
    return [
        _p(t, "function block declaration", "VAR_INPUT, VAR_OUTPUT: input and output variables"),
        _p(
            t,
            "membership function",
            "input TERM: at most three constant points, degrees 0 or 1",
            xlo="(0, 1) (4, 1) (10, 0)",
        ),
        _p(t, "membership function", "output TERM: constant singletons"),
        _p(t, "conditional aggregation", "AND: MIN"),
        _p(t, "activation", "not relevant: singletons only"),
        _p(t, "accumulation", "ACCU: MAX"),
        _p(t, "defuzzification", "METHOD: CoGS"),
        _p(t, "default value", "DEFAULT := value"),
        _p(t, "default value", "DEFAULT := NC", zitems="    METHOD : CoGS;\n    DEFAULT := NC;"),
        _p(t, "ruleblock", "RULEBLOCK: one rule block"),
        _p(t, "condition", "IF ... IS ...: n subconditions"),
        _p(t, "conclusion", "THEN: one subconclusion"),
    ]


def _extension() -> list[Probe]:
    t, ca, mf = "Table 9", "conditional aggregation", "membership function"
    out = [
        _p(
            t,
            "function block declaration",
            "VAR: local variables",
            ("function block declaration", "VAR: local variables"),
            locals="VAR\n    m : REAL;\nEND_VAR",
            blocks=_CHAINED,
            rules=_rules("IF m IS p THEN z IS a", "IF m IS q THEN z IS b"),
        ),
        _p(
            t,
            mf,
            "input TERM: four constant points, degrees 0 or 1",
            (mf, "input: four points"),
            xlo="(0, 0) (2, 1) (6, 1) (10, 0)",
        ),
        _p(
            t,
            mf,
            "input TERM: variable points",
            (mf, "input: variable points"),
            inputs="\n    p : REAL := 6;",
            xlo="(0, 1) (p, 0)",
        ),
        _p(
            t,
            mf,
            "output TERM: up to four constant points",
            (mf, "output terms given by points"),
            zterms=_AREA,
            zitems=_AREA_ITEMS.format(m="CoG"),
        ),
        _p(
            t,
            mf,
            "output TERM: variable points",
            (mf, "output: variable points"),
            inputs="\n    p : REAL := 2;",
            zterms="    TERM a := p;\n    TERM b := 10;",
        ),
    ]
    out += [
        _p(t, ca, f"AND: {op}", (ca, f"AND: {op}"), ops=f"    AND : {op};\n    ACCU : MAX;")
        for op in ("PROD", "BDIF")
    ]
    out += [
        _p(
            t,
            ca,
            f"OR: {op}",
            (ca, f"OR: {op}"),
            ops=f"    AND : {pair};\n    OR : {op};\n    ACCU : MAX;",
            rules=_OR_RULES,
        )
        for op, pair in (("ASUM", "PROD"), ("BSUM", "BDIF"))
    ]
    out += [
        _p(t, ca, "OR: MAX (the pair of MIN)", (ca, "operator OR in a condition"), rules=_OR_RULES),
        _p(
            t,
            ca,
            "NOT: 1 - {argument}",
            (ca, "operator NOT"),
            rules=_rules("IF NOT x IS lo THEN z IS a", "IF x IS NOT lo THEN z IS b"),
        ),
        _p(
            t,
            "parentheses",
            "( )",
            ("parentheses", "( ) in conditions"),
            rules=_rules("IF (x IS lo OR y IS lo) AND x IS hi THEN z IS a"),
        ),
    ]
    out += [
        _p(
            t,
            "activation",
            f"ACT: {a}",
            ("activation", f"ACT: {a}"),
            ops=f"    AND : MIN;\n    ACT : {a};\n    ACCU : MAX;",
        )
        for a in ("MIN", "PROD")
    ]
    out += [
        _p(
            t,
            "accumulation",
            f"ACCU: {a}",
            ("accumulation", f"ACCU: {a}"),
            ops=f"    AND : MIN;\n    ACCU : {a};",
        )
        for a in ("BSUM", "NSUM")
    ]
    out.append(
        _p(
            t,
            "range for fuzzification",
            "RANGE(minimum..maximum) of an output",
            ("range", "RANGE(min..max) for an output"),
            zitems="    RANGE(0..10);\n    METHOD : CoGS;\n    DEFAULT := 0;",
        )
    )
    out += [
        _p(
            t,
            "defuzzification method",
            f"METHOD: {m}",
            ("defuzzification method", f"METHOD: {m.upper()}"),
            zterms=_AREA,
            zitems=_AREA_ITEMS.format(m=m),
        )
        for m in ("CoG", "CoA", "LM", "RM")
    ]
    out += [
        _p(
            t,
            "ruleblock",
            "RULEBLOCK: n rule blocks",
            ("ruleblock", "2 rule blocks"),
            more="RULEBLOCK s\n    AND : MIN;\n    ACCU : MAX;\n"
            "    RULE 1 : IF y IS hi THEN z IS b;\nEND_RULEBLOCK",
        ),
        _p(
            t,
            "condition",
            "IF: n input variables (imported degrees)",
            ("condition", "input variables as subconditions"),
            inputs="\n    d : REAL;",
            rules=_rules("IF x IS lo AND d THEN z IS a"),
        ),
        _p(
            t,
            "conclusion",
            "THEN: n subconclusions",
            ("conclusion", "n subconclusions"),
            outputs="\n    w : REAL;",
            blocks=_W_BLOCK,
            rules=_rules("IF x IS lo THEN z IS a, w IS c"),
        ),
        _p(
            t,
            "conclusion",
            "THEN: n output variables (exported degrees)",
            ("conclusion", "output variables as subconclusions"),
            outputs="\n    v : REAL;",
            rules=_rules("IF x IS lo THEN z IS a, v"),
        ),
        _p(
            t,
            "weighting factor",
            "WITH constant",
            ("weighting factor", "WITH constant"),
            rules=_rules("IF x IS lo THEN z IS a WITH 0.5"),
        ),
        _p(
            t,
            "weighting factor",
            "WITH a variable declared in VAR_INPUT",
            ("weighting factor", "WITH variable"),
            inputs="\n    wt : REAL := 0.8;",
            rules=_rules("IF x IS lo THEN z IS a WITH wt"),
        ),
    ]
    return out


# Parameters of a term of each parametric shape on the universe 0..10 (the registry's
# ``probe``; ``probe_output`` for an output on -20..20).  An entry without a probe says why
# (NA): the statement lists every shape.
SHAPE_PARAMS: dict[str, tuple[float, ...]] = {
    s.kind: s.probe for s in ENTRIES if isinstance(s.probe, tuple) and not s.takagi_sugeno
}
_TS = {s.kind: s.probe for s in ENTRIES if isinstance(s.probe, tuple) and s.takagi_sugeno}
#: The Takagi-Sugeno constant (the second output term of the Takagi-Sugeno probes).
_CONSTANT = next(s.kind for s in ENTRIES if s.takagi_sugeno and not s.variadic)


def _shape(kind: str, params: tuple[float, ...]) -> str:
    from fuzzyctl.fcl.writer import mf_text

    return mf_text(ShapeMF(kind, tuple(float(p) for p in params)))


def _open_shapes() -> list[Probe]:
    t, mf, el = "Table 10", "membership function", "free membership functions"
    out = []
    for kind, params in SHAPE_PARAMS.items():
        text = _shape(kind, params)
        out.append(_p(t, el, f"input {text.split()[0]} ({kind})", (mf, f"input shape {kind}"), xlo=text))
        wide_params = SHAPES[kind].output_probe()
        assert isinstance(wide_params, tuple)
        wide = _shape(kind, wide_params)
        out.append(
            _p(
                t,
                el,
                f"output {wide.split()[0]} ({kind})",
                (mf, f"output shape {kind}"),
                zterms=f"    TERM a := {wide};\n    TERM b := (12, 0) (16, 1) (20, 0);",
                zitems="    RANGE(-20..20);\n    METHOD : CoG;\n    DEFAULT := 0;",
            )
        )
    out.append(
        _p(
            t,
            el,
            "input COSINE with a variable half-width (cosine_half)",
            (mf, "input shape cosine_half"),
            inputs="\n    hw : REAL := 3;",
            xlo="COSINE hw 5",
        )
    )
    for kind, params in _TS.items():
        text = _shape(kind, params)
        out.append(
            _p(
                t,
                el,
                f"output {text.split()[0]} (Takagi-Sugeno {kind})",
                (mf, f"output shape {kind}"),
                zterms=f"    TERM a := {text};\n    TERM b := {_shape(_CONSTANT, (10.0,))};",
                zitems="    METHOD : WTAVER;\n    DEFAULT := 0;",
            )
        )
    return out


def _open_operators() -> list[Probe]:
    t, ca = "Table 10", "conditional aggregation"
    out = [
        _p(t, ca, f"AND: {op}", (ca, f"AND: {op}"), ops=f"    AND : {op};\n    ACCU : MAX;")
        for op in sorted(AND_OPERATORS - {"MIN", "PROD", "BDIF"})
    ]
    out += [
        _p(
            t,
            ca,
            f"OR: {op}",
            (ca, f"OR: {op}"),
            ops=f"    AND : MIN;\n    OR : {op};\n    ACCU : MAX;",
            rules=_OR_RULES,
        )
        for op in sorted(OR_OPERATORS - {"MAX", "ASUM", "BSUM"})
    ]
    out += [
        _p(
            t,
            "activation",
            f"ACT: {op}",
            ("activation", f"ACT: {op}"),
            ops=f"    AND : MIN;\n    ACT : {op};\n    ACCU : MAX;",
            zterms=_AREA,
            zitems=_AREA_ITEMS.format(m="CoG"),
        )
        for op in sorted(ACT_METHODS - {"MIN", "PROD"})
    ]
    out += [
        _p(
            t,
            "accumulation",
            f"ACCU: {op}",
            ("accumulation", f"ACCU: {op}"),
            ops=f"    AND : MIN;\n    ACCU : {op};",
        )
        for op in sorted(ACCU_METHODS - {"MAX", "BSUM", "NSUM"})
    ]
    out += [
        _p(
            t,
            "defuzzification method",
            f"METHOD: {m}",
            ("defuzzification method", f"METHOD: {m.upper()}"),
            zitems=f"    RANGE(0..10);\n    METHOD : {m};\n    DEFAULT := 0;",
        )
        for m in ("MoM", "CoGF", "WtAver", "WtSum")
    ]
    return out


def _open_other() -> list[Probe]:
    t, mf = "Table 10", "membership function"
    out = [
        _p(
            t,
            "membership function points",
            "more than four points",
            (mf, "input: more than four points"),
            xlo="(0, 1) (2, 1) (4, 0.5) (6, 0.5) (10, 0)",
        ),
        _p(
            t,
            "membership degrees",
            "degrees between 0 and 1",
            (mf, "input: degrees between 0 and 1"),
            xlo="(0, 0.5) (10, 0)",
        ),
        _p(
            t,
            "membership degrees",
            "variable membership values",
            (mf, "input: variable membership degrees"),
            inputs="\n    g : REAL := 0.5;",
            xlo="(0, g) (10, 0)",
        ),
        _p(t, mf, "input singleton", (mf, "input singleton"), xlo="3"),
        _p(
            t,
            mf,
            "output SINGLETONS (a discrete set, jFuzzyLogic)",
            (mf, "output SINGLETONS (discrete set)"),
            zterms="    TERM a := SINGLETONS (0, 1) (2, 0.5);\n    TERM b := 10;",
        ),
        _p(t, mf, "input FUNCTION term (jFuzzyLogic)", (mf, "input FUNCTION term"), xlo="FUNCTION y / 10"),
    ]
    out += [
        _p(
            t,
            "membership function spelling",
            f"{s.split()[0]} (another tool's name of a shape)",
            ("membership function spelling", s.split()[0]),
            xlo=s,
        )
        for s in ("TRIAN 0 5 10", "Triangle 0 5 10", "triangular 0 5 10")
    ]
    out += [
        _p(
            t,
            "condition",
            "hedges (very, somewhat, ...)",
            ("condition", "hedges (fuzzylite)"),
            rules=_rules("IF x IS very lo THEN z IS a"),
        ),
        _p(
            t,
            "conclusion",
            "hedges in conclusions",
            ("conclusion", "hedges in conclusions (fuzzylite)"),
            rules=_rules("IF x IS lo THEN z IS very a"),
        ),
        _p(
            t,
            "condition",
            "an output read in a condition (chained rules)",
            ("condition", "output variable in a condition (chained rules)"),
            outputs="\n    w : REAL;",
            blocks=_W_BLOCK,
            rules=_rules("IF x IS lo THEN z IS a") + "\n    RULE 3 : IF z IS a THEN w IS c;",
        ),
        _p(
            t,
            "function blocks",
            "several function blocks in one file",
            ("function blocks", "2 function blocks in one file"),
            after="FUNCTION_BLOCK second\nVAR_INPUT\n    u : REAL;\nEND_VAR\nEND_FUNCTION_BLOCK\n",
        ),
        _p(
            t,
            "range",
            "RANGE in FUZZIFY (the input's universe)",
            ("range", "RANGE in FUZZIFY (input universe)"),
            xrange="    RANGE(0..10);\n",
        ),
        _p(
            t,
            "declarations",
            "RANGE on a declaration line (jFuzzyLogic)",
            ("declarations", "RANGE on a declaration line (jFuzzyLogic)"),
            inputs="\n    q : REAL; RANGE(0..1);",
        ),
        _p(
            t,
            "default value",
            "DEFAULT := value | NC (fuzzylite)",
            ("default value", "DEFAULT := value | NC (fuzzylite)"),
            zitems="    METHOD : CoGS;\n    DEFAULT := 0 | NC;",
        ),
        _p(
            t,
            "default value",
            "DEFAULT := nan (fuzzylite)",
            ("default value", "DEFAULT := nan (fuzzylite)"),
            zitems="    METHOD : CoGS;\n    DEFAULT := nan;",
        ),
        _p(
            t,
            "accumulation",
            "ACCU inside DEFUZZIFY (fuzzylite)",
            ("accumulation", "ACCU inside DEFUZZIFY (fuzzylite)"),
            zitems="    METHOD : CoGS;\n    ACCU : MAX;\n    DEFAULT := 0;",
        ),
        _p(
            t,
            "options",
            "OPTIONS ... END_OPTIONS (kept verbatim)",
            ("options", "OPTIONS ... END_OPTIONS"),
            more="OPTIONS\n    anything here\nEND_OPTIONS",
        ),
    ]
    return out


def probes() -> list[Probe]:
    """Every element of the statement: Tables 8, 9 and 10."""
    return _basic() + _extension() + _open_shapes() + _open_operators() + _open_other()


@dataclass(frozen=True)
class ProbeResult:
    probe: Probe
    supported: bool
    codegen: bool
    reason: str = ""


def _values(doc: Document) -> dict[str, float]:
    return {v.name: 3.0 if v.name in ("x", "y") else 0.5 for v in doc.main.inputs if v.initial is None}


def run_probe(probe: Probe) -> ProbeResult:
    """Load, classify, evaluate and generate code for one probe.  Raises RuntimeError when
    ``fuzzyctl check`` classifies the program otherwise than the statement (a drift)."""
    import fuzzyctl

    result = load_text(probe.text())
    if not result.ok or result.document is None:
        first = next((d.message for d in result.diagnostics if d.is_error), "does not load")
        return ProbeResult(probe, False, False, first)
    doc = result.document
    feats = conformance.features(doc, result.spellings)
    found = {(f.element, f.detail): f.level for f in feats}
    level = conformance.level(feats)
    if probe.feature is None:
        if level is not Level.BASIC:
            raise RuntimeError(f"statement: Basic probe {probe.detail!r} needs {level}: {sorted(found)}")
    elif found.get(probe.feature) is not probe.level or level > probe.level:
        raise RuntimeError(
            f"statement: probe {probe.table} {probe.detail!r} expects {probe.feature} at {probe.level}; "
            f"fuzzyctl check finds {sorted((str(v), k) for k, v in found.items())}"
        )
    try:
        out = fuzzyctl.compile(doc, out_of_range="ignore").evaluate(_values(doc))
        value = out[doc.main.outputs[0].name]
        supported, reason = math.isfinite(value) or math.isnan(value), ""
    except Exception as exc:  # every refusal of the engine is an answer here
        supported, reason = False, str(exc).splitlines()[0]
    return ProbeResult(probe, supported, _codegen(doc), reason)


def _codegen(doc: Document) -> bool:
    from fuzzyctl.codegen import generate_c, generate_st

    try:
        generate_st(doc)
        generate_c(doc)
    except Exception:  # a refusal, with its reason, is for `fuzzyctl codegen`
        return False
    return True


def element_rows(progress: Callable[[], None] | None = None) -> list[ProbeResult]:
    """Every probe, run (``progress`` is called after each)."""
    out = []
    for probe in probes():
        out.append(run_probe(probe))
        if progress is not None:
            progress()
    return out
