"""Large and pathological inputs: every reader must accept or refuse a 10 MB file in under
5 s and 500 MB (issue 14, point 4).

For each format (FCL, FIS, FLL, JSON, FPL, XFUZ) the script writes files of the requested
size in several shapes - a valid system with very many rules, a file with an error on every
line, random garbage, one single enormous line, deep nesting; FPL also the shapes of
FPL_SHAPES: rules only the general reader takes, CR line ends, many MEMBERs or points, a
warning every 4 bytes, unclosed objects and comments, bytes FPL has no token for, the real
tool's largest project grown - and runs the CLI on each in a fresh process
(``fuzzyctl.load`` inside the CLI's error boundary, which prints the diagnostics as the CLI
does; FCL also through ``fuzzyctl check``), printing wall and CPU time, peak resident memory
(of that process) and the exit code.
Files over the size limit (``FUZZYCTL_MAX_INPUT_BYTES``, per format: docs/limits.md) are
refused up front, so the script also runs each shape just under the limit (--under-limit).

usage: python benchmarks/large_inputs.py [--mb 10] [--formats fcl,fis,...] [--shapes ...]
exit status 1 when a case breaks the goal (time, memory, or an exit code other than 0/1).
"""

from __future__ import annotations

import argparse
import json
import os
import random
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

GOAL_S, GOAL_MB = 5.0, 500.0


def _repeat(head: str, unit: Callable[[int], str], tail: str, size: int) -> str:
    parts, n, k = [head], len(head) + len(tail), 0
    while n < size:
        s = unit(k)
        parts.append(s)
        n += len(s)
        k += 1
    parts.append(tail)
    return "".join(parts)


def _garbage(size: int, seed: int = 1) -> str:
    rng = random.Random(seed)
    alphabet = "abcdefXYZ_0123456789 ();:=,.*/-+[]{}'\"\n\t"
    return "".join(rng.choice(alphabet) for _ in range(min(size, 1 << 16))) * max(1, size >> 16)


FCL_HEAD = """FUNCTION_BLOCK big
VAR_INPUT a : REAL; b : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY a TERM lo := (0, 1) (1, 0); TERM hi := (0, 0) (1, 1); END_FUZZIFY
FUZZIFY b TERM lo := (0, 1) (1, 0); TERM hi := (0, 0) (1, 1); END_FUZZIFY
DEFUZZIFY y TERM lo := 0; TERM hi := 1; METHOD : COGS; DEFAULT := 0; END_DEFUZZIFY
RULEBLOCK r
AND : MIN;
"""
FCL_TAIL = "END_RULEBLOCK\nEND_FUNCTION_BLOCK\n"


def fcl(shape: str, size: int) -> str:
    if shape == "valid":
        return _repeat(
            FCL_HEAD, lambda k: f"RULE {k} : IF a IS lo AND b IS hi THEN y IS lo;\n", FCL_TAIL, size
        )
    if shape == "errors":
        return _repeat(FCL_HEAD, lambda k: f"RULE {k} : IF a IS nothing THEN y IS ;\n", FCL_TAIL, size)
    if shape == "one-line":
        return _repeat(
            FCL_HEAD.replace("\n", " "), lambda k: "RULE 1 : IF a IS lo THEN y IS lo; ", FCL_TAIL, size
        )
    if shape == "deep":
        depth = size // 2
        return (
            FCL_HEAD + "RULE 1 : IF " + "(" * depth + "a IS lo" + ")" * depth + " THEN y IS lo;\n" + FCL_TAIL
        )
    if shape == "not":
        return FCL_HEAD + "RULE 1 : IF " + "NOT " * (size // 4) + "a IS lo THEN y IS lo;\n" + FCL_TAIL
    return _fcl_more(shape, size)


def _fcl_more(shape: str, size: int) -> str:
    """The FCL-only shapes (not in SHAPES: see FCL_SHAPES)."""
    if shape == "and-chain":  # one rule, one line: a IS lo AND a IS lo AND ...
        return (
            FCL_HEAD + "RULE 1 : IF " + "a IS lo AND " * (size // 12) + "b IS hi THEN y IS lo;\n" + FCL_TAIL
        )
    if shape == "nest-99":  # rules nesting 99 levels (the limit is 100), one after the other
        cond = "a IS lo AND (" * 98 + "b IS hi" + ")" * 98
        return _repeat(FCL_HEAD, lambda k: f"RULE {k} : IF {cond} THEN y IS lo;\n", FCL_TAIL, size)
    if shape == "not-paren":  # NOT (NOT (... : real nesting, refused
        return (
            FCL_HEAD
            + "RULE 1 : IF "
            + "NOT (" * (size // 6)
            + "a IS lo"
            + ")" * (size // 6)
            + " THEN y IS lo;\n"
            + FCL_TAIL
        )
    if shape == "unclosed":  # deep redundant parentheses, one missing: a syntax error
        d = size // 2
        return FCL_HEAD + "RULE 1 : IF " + "(" * d + "a IS lo" + ")" * (d - 1) + " THEN y IS lo;\n" + FCL_TAIL
    if shape == "comments":  # a comment between every two tokens
        return _repeat(
            FCL_HEAD,
            lambda k: (
                f"RULE {k} (* r *) : IF a /* x */ IS lo // c\n AND (* y *) b IS hi THEN y (* z *) IS lo;\n"
            ),
            FCL_TAIL,
            size,
        )
    if shape == "points":  # one TERM with a huge list of points
        head = FCL_HEAD.replace(
            "TERM hi := (0, 0) (1, 1);", "TERM hi := " + "(0.5, 1) " * (size // 9) + ";", 1
        )
        return head + "RULE 1 : IF a IS hi THEN y IS lo;\n" + FCL_TAIL
    if shape == "fuzzify":  # very many small FUZZIFY blocks
        block = "FUZZIFY v{k} TERM lo := (0, 1) (1, 0); TERM hi := (0, 0) (1, 1); END_FUZZIFY\n"
        return _repeat(
            FCL_HEAD.replace("RULEBLOCK r\nAND : MIN;\n", ""),
            lambda k: block.format(k=k),
            "END_FUNCTION_BLOCK\n",
            size,
        )
    return _fcl_blocks(shape, size)


def _fcl_blocks(shape: str, size: int) -> str:
    """FCL shapes of very many small blocks or declarations (little for the fast reader's
    runs of RULE and TERM statements)."""
    no_rules = FCL_HEAD.replace("RULEBLOCK r\nAND : MIN;\n", "")
    if shape == "defuzzify":  # very many small DEFUZZIFY blocks
        block = "DEFUZZIFY w{k} TERM lo := 0; TERM hi := 1; METHOD : COGS; DEFAULT := 0; END_DEFUZZIFY\n"
        return _repeat(no_rules, lambda k: block.format(k=k), "END_FUNCTION_BLOCK\n", size)
    if shape == "var-input":  # one VAR_INPUT block declaring very many variables
        return _repeat(
            "FUNCTION_BLOCK big\nVAR_INPUT\n",
            lambda k: f"v{k} : REAL;\n",
            "END_VAR\n" + FCL_HEAD.split("\n", 1)[1] + FCL_TAIL,
            size,
        )
    if shape == "ruleblocks":  # very many RULEBLOCKs of one or two rules
        return _repeat(
            no_rules,
            lambda k: (
                f"RULEBLOCK r{k}\nRULE 1 : IF a IS lo THEN y IS lo;\n"
                + ("RULE 2 : IF b IS hi THEN y IS hi;\n" if k % 2 else "")
                + "END_RULEBLOCK\n"
            ),
            "END_FUNCTION_BLOCK\n",
            size,
        )
    if shape == "fblocks":  # very many small FUNCTION_BLOCKs
        small = FCL_HEAD.replace("FUNCTION_BLOCK big", "FUNCTION_BLOCK f{k}")
        small += "RULE 1 : IF a IS lo AND b IS hi THEN y IS lo;\n" + FCL_TAIL
        return _repeat("", lambda k: small.format(k=k), "", size)
    return _garbage(size)


#: Shapes only FCL has (adversarial inputs for the fast reader, fcl/fast.py).
FCL_SHAPES = (
    "and-chain",
    "nest-99",
    "not-paren",
    "unclosed",
    "comments",
    "points",
    "fuzzify",
    "defuzzify",
    "var-input",
    "ruleblocks",
    "fblocks",
)


FIS_HEAD = """[System]
Name='big'
Type='mamdani'
NumInputs=1
NumOutputs=1
NumRules={n}
AndMethod='min'
OrMethod='max'
ImpMethod='min'
AggMethod='max'
DefuzzMethod='centroid'
[Input1]
Name='a'
Range=[0 1]
NumMFs=2
MF1='lo':'trimf',[0 0 1]
MF2='hi':'trimf',[0 1 1]
[Output1]
Name='y'
Range=[0 1]
NumMFs=2
MF1='lo':'trimf',[0 0 1]
MF2='hi':'trimf',[0 1 1]
[Rules]
"""


def _fis_inputs(n: int, size: int) -> str:
    """``n`` inputs of two terms each and rules of ``n`` entries up to ``size``."""
    head = FIS_HEAD.format(n=1).split("[Input1]")[0].replace("NumInputs=1", f"NumInputs={n}")
    terms = "NumMFs=2\nMF1='lo':'trimf',[0 0 1]\nMF2='hi':'trimf',[0 1 1]\n"
    inputs = "".join(f"[Input{i}]\nName='x{i}'\nRange=[0 1]\n{terms}" for i in range(1, n + 1))
    output = FIS_HEAD[FIS_HEAD.index("[Output1]") :]
    rule = " ".join(["1"] * n) + ", 1 (1) : 1\n"
    return _repeat(head + inputs + output, lambda k: rule, "", size)


def _fis_mfs(size: int, name: Callable[[int], str]) -> str:
    """One input with as many membership functions as fit in ``size``."""
    head, tail = FIS_HEAD.format(n=1).split("[Output1]")
    head = head.replace("NumMFs=2\nMF1='lo':'trimf',[0 0 1]\nMF2='hi':'trimf',[0 1 1]\n", "")
    return _repeat(
        head,
        lambda k: f"MF{k + 1}='{name(k)}':'trimf',[0 0 1]\n",
        "[Output1]" + tail + "1, 1 (1) : 1\n",
        size,
    )


def fis(shape: str, size: int) -> str:
    if shape == "valid":
        return _repeat(
            FIS_HEAD.format(n=size // 14), lambda k: f"{k % 2 + 1}, {k % 2 + 1} (1) : 1\n", "", size
        )
    if shape == "errors":
        return _repeat(FIS_HEAD.format(n=3), lambda k: f"{k} x, y (1) : 9\n", "", size)
    if shape == "one-line":
        return FIS_HEAD.format(n=1) + "1, 1 (1) : 1 " + "1 " * (size // 2) + "\n"
    if shape == "deep":
        d = size // 2
        return (
            FIS_HEAD.format(n=1).replace("[0 0 1]", "[" + "(" * d + "0" + ")" * d + " 0 1]", 1)
            + "1, 1 (1) : 1\n"
        )
    if shape == "not":
        return FIS_HEAD.format(n=1).replace("NumRules=1", "NumRules=" + "9" * 5001)
    # the densest rules: version 1.0 lines without punctuation, 8 bytes each
    if shape == "dense":
        return _repeat(FIS_HEAD.format(n=size // 8), lambda k: f"{k % 2 + 1} {k % 2 + 1} 1 1\n", "", size)
    if shape == "cr-only":
        return fis("valid", size).replace("\n", "\r")
    if shape == "hedges":  # fractional codes take the general path
        return _repeat(
            FIS_HEAD.format(n=size // 16), lambda k: f"{k % 2 + 1}.2, {k % 2 + 1} (1) : 1\n", "", size
        )
    if shape == "exprs":  # a different expression on every line
        return _repeat(FIS_HEAD.format(n=size // 20), lambda k: f"{k + 1}/{k + 1}, 1 (1) : 1\n", "", size)
    if shape == "warnings":  # a warning on every line
        return _repeat(FIS_HEAD.format(n=size // 9), lambda k: "1,1(2):1\n", "", size)
    if shape == "inputs":  # 2,000 inputs, rules of 2,000 entries
        return _fis_inputs(2000, size)
    if shape == "mfs":  # one input with hundreds of thousands of terms
        return _fis_mfs(size, lambda k: f"t{k}")
    if shape == "same-mfs":  # ... all of one name (renamed t_2, t_3, ...)
        return _fis_mfs(size, lambda k: "t")
    if shape == "params":  # one term with millions of parameters (extra ones ignored)
        return (
            FIS_HEAD.format(n=1).replace("[0 0 1]", "[0 0 1 " + "0 " * (size // 2) + "]", 1)
            + "1, 1 (1) : 1\n"
        )
    if shape == "expr-params":  # ... each a different expression
        exprs = " ".join(f"{k}/7" for k in range(size // 9))
        return FIS_HEAD.format(n=1).replace("[0 0 1]", f"[0 0 1 {exprs}]", 1) + "1, 1 (1) : 1\n"
    if shape == "system":  # a [System] section of a million keys
        head, rest = FIS_HEAD.format(n=1).split("[Input1]")
        return _repeat(head, lambda k: f"Key{k}='value'\n", "[Input1]" + rest + "1, 1 (1) : 1\n", size)
    if shape == "counts":  # counts of a billion, on few lines
        return FIS_HEAD.format(n=999_999_999).replace("NumMFs=2", "NumMFs=999999999") + "1, 1 (1) : 1\n"
    if shape == "comments":  # a quoted string and a comment on every line
        return _repeat(FIS_HEAD.format(n=size // 30), lambda k: "1, 1 (1) : 1 % 'it''s' # x\n", "", size)
    return _garbage(size)


FLL_HEAD = """Engine: big
InputVariable: a
  range: 0 1
  term: lo Triangle 0 0 1
  term: hi Triangle 0 1 1
OutputVariable: y
  range: 0 1
  default: 0
  aggregation: Maximum
  defuzzifier: Centroid 100
  term: lo Triangle 0 0 1
  term: hi Triangle 0 1 1
RuleBlock: r
  conjunction: Minimum
  implication: Minimum
"""


def fll(shape: str, size: int) -> str:
    if shape == "valid":
        return _repeat(FLL_HEAD, lambda k: "  rule: if a is lo then y is hi\n", "", size)
    if shape == "errors":
        return _repeat(FLL_HEAD, lambda k: f"  rule: if a is nothing{k} then y is\n", "", size)
    if shape == "one-line":
        return FLL_HEAD + "  rule: if " + "a is lo and " * (size // 12) + "a is lo then y is hi\n"
    if shape == "deep":
        d = size // 2
        return FLL_HEAD + "  rule: if " + "(" * d + "a is lo" + ")" * d + " then y is hi\n"
    if shape == "not":
        return FLL_HEAD + "  rule: if " + "not " * (size // 4) + "a is lo then y is hi\n"
    return _fll_more(shape, size)


# More FLL shapes (each valid unless said): long mixed and/or rules, conditions nested 90
# deep, Function terms nested or chained past the limit (refused) and many valid ones,
# thousands of terms and variables, duplicate term names (renamed with a warning), a
# number of a million digits (refused), a Discrete term of a million points, hedge chains
# in a condition and in a conclusion (refused over 100), CR-only line ends.
FLL_SHAPES = (
    "or-and",
    "nested",
    "fn-deep",
    "fn-chain",
    "fn-many",
    "terms",
    "dup-terms",
    "variables",
    "huge-number",
    "discrete",
    "hedges",
    "then-hedges",
    "cr",
)


def _fll_more(shape: str, size: int) -> str:
    rule = "  rule: if a is lo then y is hi\n"
    if shape == "or-and":
        return (
            FLL_HEAD
            + "  rule: if "
            + "a is lo or a is very hi and " * (size // 28)
            + "a is lo then y is hi\n"
        )
    if shape == "nested":
        d = 45
        cond = "(a is lo and " * d + "(a is hi or " * d + "a is lo" + ")" * (2 * d)
        return _repeat(FLL_HEAD, lambda k: f"  rule: if {cond} then y is hi\n", "", size)
    if shape == "fn-deep":
        d = size // 2
        return FLL_HEAD.replace("term: hi Triangle 0 1 1", "term: f Function " + "(" * d + "x" + ")" * d, 1)
    if shape == "fn-chain":
        return FLL_HEAD.replace(
            "term: hi Triangle 0 1 1", "term: f Function " + "x + " * (size // 4) + "x", 1
        )
    if shape == "fn-many":
        head = FLL_HEAD.split("OutputVariable")[0]
        return _repeat(
            head, lambda k: f"  term: f{k} Function 1 / (1 + exp(-(x - {k % 9}) ^ 2)) * sin(x)\n", "", size
        )
    if shape == "terms":
        head = FLL_HEAD.split("OutputVariable")[0]
        n = size // 60
        terms = "".join(f"  term: t{k} Triangle 0 0.5 1\n" for k in range(n))
        tail = FLL_HEAD[FLL_HEAD.index("OutputVariable") :]
        return _repeat(head + terms + tail, lambda k: f"  rule: if a is t{k % n} then y is hi\n", "", size)
    if shape == "dup-terms":
        head = FLL_HEAD.split("OutputVariable")[0]
        return _repeat(head, lambda k: "  term: lo Triangle 0 0 1\n", "", size)
    if shape == "variables":
        return _repeat(
            "Engine: many\n",
            lambda k: f"InputVariable: v{k}\n  range: 0 1\n  term: lo Triangle 0 0 1\n",
            "",
            size,
        )
    if shape == "huge-number":
        return FLL_HEAD.replace("range: 0 1", "range: 0 " + "9" * size, 1)
    if shape == "discrete":
        return FLL_HEAD.replace("Triangle 0 0 1", "Discrete " + "0.5 1 " * (size // 6) + "1 0", 1)
    if shape == "hedges":
        return FLL_HEAD + "  rule: if a is " + "very " * (size // 5) + "lo then y is hi\n"
    if shape == "then-hedges":
        return FLL_HEAD + "  rule: if a is lo then " + "y is very hi and " * (size // 17) + "y is hi\n"
    if shape == "cr":
        return _repeat(FLL_HEAD, lambda k: rule, "", size).replace("\n", "\r")
    return _garbage(size)


def _json_doc() -> dict[str, object]:
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "src"))
    import fuzzyctl
    from fuzzyctl.formats.json import writer as fj

    return fj.to_dict(fuzzyctl.load(FCL_HEAD + "RULE 1 : IF a IS lo THEN y IS lo;\n" + FCL_TAIL))


def jsonf(shape: str, size: int) -> str:
    doc = _json_doc()
    if shape == "valid":
        rules = doc["blocks"][0]["rule_blocks"][0]["rules"]  # type: ignore[index]
        one = json.dumps(rules[0])
        rules.extend([rules[0]] * (size // len(one)))
        return json.dumps(doc)
    if shape == "errors":
        doc["blocks"][0]["rule_blocks"][0]["rules"] = [{"label": 1, "bogus": k} for k in range(size // 30)]  # type: ignore[index]
        return json.dumps(doc)
    if shape == "one-line":
        return json.dumps(doc) + " " * size
    if shape == "deep":
        d = size // 2
        return "[" * d + "]" * d
    if shape == "not":
        cond: dict[str, object] = {"type": "is", "variable": "a", "term": "lo"}
        text = json.dumps(cond)
        depth = size // 32
        text = '{"type": "not", "operand": ' * depth + text + "}" * depth
        base = json.dumps(doc)
        marker = json.dumps(doc["blocks"][0]["rule_blocks"][0]["rules"][0]["condition"])  # type: ignore[index]
        return base.replace(marker, text, 1)
    return _garbage(size)


FPL_HEAD = """PROJECT big
VAR a
TYPE float
MIN 0.0
MAX 1.0
MEMBER lo
POINTS 0.0,1.0 1.0,0.0
END
MEMBER hi
POINTS 0.0,0.0 1.0,1.0
END
END
VAR y
TYPE float
MIN 0.0
MAX 1.0
MEMBER lo
POINTS 0.0,1.0 0.01,1.0
END
END
FUZZY r
"""
FPL_TAIL = "END\nCONNECT\nFROM a\nTO r\nEND\nCONNECT\nFROM r\nTO y\nEND\nEND\n"


def s7_largest(conditions_per_input: int = 1, rules: int = 200) -> str:
    """With the defaults, the largest configuration Siemens S7 Fuzzy Control allows (manual
    1.3 and 2: 8 inputs of 7 terms, 4 outputs of 9 terms, 200 rules; 10-character variable
    and 7-character term names; CRLF line ends), each rule naming every input
    (``conditions_per_input`` terms of each: 7 gives the 56 conditions per rule of the manual,
    chapter 4) and every output: 77 KB, 346 KB with 7 conditions per input."""
    ins, outs = [f"Input{i:05d}" for i in range(8)], [f"Outpt{i:05d}" for i in range(4)]
    t_in, t_out = [f"InTerm{k}" for k in range(7)], [f"OuTerm{k}" for k in range(9)]
    out = ["/*FPL file generated by Fuzzy Control on 05.06.95*/", "PROJECT PROJNAME"]
    for v in ins:
        out += [f"VAR {v}", "TYPE float", "MIN -10000.00", "MAX 10000.00"]
        for k, t in enumerate(t_in):
            a, b = 9000 - 100 * k, 8000 - 100 * k
            out += [f"MEMBER {t}", f"POINTS -{a:.2f},0.0 -{b:.2f},1.0 {b:.2f},1.0 {a:.2f},0.0", "END"]
        out.append("END")
    for v in outs:
        out += [f"VAR {v}", "TYPE float", "MIN -10000.00", "MAX 10000.00"]
        for k, t in enumerate(t_out):
            out += [f"MEMBER {t}", f"POINTS -{9000 - 100 * k:.2f},1.0 -{8900 - 100 * k:.2f},1.0", "END"]
        out.append("END")
    out.append("FUZZY ProFuzzy")
    for r in range(rules):
        conds = [
            f"({v} is {t_in[(r + j + c) % 7]})"
            for j, v in enumerate(ins)
            for c in range(conditions_per_input)
        ]
        then = " AND ".join(f"{v} = {t_out[(r + j) % 9]}" for j, v in enumerate(outs))
        out += [f"RULE Rule_{r + 1:03d}", "IF " + " AND ".join(conds), "THEN " + then, "END"]
    out.append("END")
    out += [x for v in ins for x in ("CONNECT", f"FROM {v}", "TO ProFuzzy", "END")]
    out += [x for v in outs for x in ("CONNECT", "FROM ProFuzzy", f"TO {v}", "END")]
    return "\r\n".join([*out, "END", ""])


def fpl(shape: str, size: int) -> str:
    if shape == "valid":
        return _repeat(FPL_HEAD, lambda k: f"RULE R{k}\nIF (a is lo)\nTHEN y = lo\nEND\n", FPL_TAIL, size)
    if shape == "errors":
        return _repeat(FPL_HEAD, lambda k: f"RULE R{k}\nIF (a is nothing)\nTHEN y = \nEND\n", FPL_TAIL, size)
    if shape == "one-line":
        return (
            FPL_HEAD
            + "RULE R1 IF "
            + "(a is lo) AND " * (size // 14)
            + "(a is lo) THEN y = lo END\n"
            + FPL_TAIL
        )
    if shape == "deep":
        d = size // 2
        return FPL_HEAD + "RULE R1\nIF " + "(" * d + "a is lo" + ")" * d + "\nTHEN y = lo\nEND\n" + FPL_TAIL
    if shape == "not":
        return FPL_HEAD + "RULE R1\nIF " + "NOT " * (size // 4) + "(a is lo)\nTHEN y = lo\nEND\n" + FPL_TAIL
    if shape == "s7-style":  # the real tool's largest file (56 conditions a rule), more rules
        return s7_largest(7, max(1, 200 * size // len(s7_largest(7))))
    if shape == "commented":  # rules the plain-rule reader leaves to the general one
        return _repeat(
            FPL_HEAD, lambda k: f"RULE R{k} /* {k} */\nIF (a IS lo)\nTHEN y = lo\nEND\n", FPL_TAIL, size
        )
    if shape == "cr-only":  # one line for the diagnostics
        return fpl("valid", size).replace("\n", "\r")
    if shape == "wide-deep":  # a long AND chain inside 100 levels of parentheses
        chain = "a is lo AND " * ((size - 2000) // 12) + "a is lo"
        return (
            FPL_HEAD
            + "RULE R1 IF "
            + "(a is lo AND " * 99
            + chain
            + ")" * 99
            + " THEN y = lo END\n"
            + FPL_TAIL
        )
    if shape == "members":  # one VAR with very many MEMBERs, each used by a rule
        members = _repeat("", lambda k: f"MEMBER m{k} POINTS {k},0 {k + 1},1 {k + 2},0 END\n", "", size // 2)
        n = members.count("MEMBER")
        rules = "".join(f"RULE R{k} IF x is m{k} THEN y = lo END\n" for k in range(n))
        return (
            FPL_HEAD.replace("VAR y", f"VAR x MIN 0 MAX {n + 2}\n{members}END\nVAR y") + rules + "END\nEND\n"
        )
    if shape == "points":  # one MEMBER with a very long POINTS list
        pts = _repeat("", lambda k: f"{k}.5,{k % 2} ", "", size)
        return FPL_HEAD.replace("POINTS 0.0,0.0 1.0,1.0", "POINTS " + pts) + FPL_TAIL
    if shape == "long-word":  # a name of the whole size, where no name may stand
        return "PROJECT p\n" + "w" * size + "\nEND\n"
    if shape == "tolerated":  # a warning every 4 bytes (Siemens 1.3: MAP is tolerated)
        return "PROJECT p\n" + "MAP\n" * (size // 4) + "END\n"
    if shape == "unclosed":  # an OPTIONS object that is never closed
        return "PROJECT p\nOPTIONS " + "x 1 " * (size // 4)
    if shape == "comments-open":  # "/*" that no "*/" closes, over and over
        return "PROJECT p /* ok */\n" + "/* " * (size // 3)
    if shape == "bad-chars":  # a character FPL has no token for, everywhere
        return "*" * size
    return _garbage(size)


# FPL shapes beyond the common ones (run by default for FPL, or named with --shapes).
FPL_SHAPES = (
    "s7-style",
    "commented",
    "cr-only",
    "wide-deep",
    "members",
    "points",
    "long-word",
    "tolerated",
    "unclosed",
    "comments-open",
    "bad-chars",
)


def xfuz(shape: str, size: int) -> str:
    head = "table,index,value,note\nCONST,OP_ET,0,\n"
    if shape == "valid":
        return _repeat(head, lambda k: f"FA,{k % 576},{k % 100},note {k}\n", "", size)
    if shape == "errors":
        return _repeat(head, lambda k: f"XX,{k},not-a-number,\n", "", size)
    if shape == "one-line":
        return head + "FA,0,1," + "n" * size + "\n"
    if shape == "deep":
        return "\r".join(f"FA,{k % 576},1," for k in range(size // 10))  # CR-only line ends
    if shape == "not":
        return head + "FA,0," + "9" * 5001 + ",\n"
    return _garbage(size)


FORMATS: dict[str, tuple[str, Callable[[str, int], str]]] = {
    "fcl": (".fcl", fcl),
    "fis": (".fis", fis),
    "fll": (".fll", fll),
    "json": (".json", jsonf),
    "fpl": (".fpl", fpl),
    "xfuz": (".csv.xfuz", xfuz),
}
SHAPES = ("valid", "errors", "garbage", "one-line", "deep", "not")
#: Further shapes of FIS files .
FIS_SHAPES = (
    "dense",
    "cr-only",
    "hedges",
    "exprs",
    "warnings",
    "inputs",
    "mfs",
    "same-mfs",
    "params",
    "expr-params",
    "system",
    "counts",
    "comments",
)
#: Shapes run for one format only (by default, after the common ones).
FORMAT_SHAPES: dict[str, tuple[str, ...]] = {
    "fll": FLL_SHAPES,
    "fis": FIS_SHAPES,
    "fcl": FCL_SHAPES,
    "fpl": FPL_SHAPES,
}


# The child: fuzzyctl.load() inside the CLI's error boundary (diagnostics printed as the CLI
# prints them, exit 1 on a refusal, 3 on anything else); FCL also goes through `check`.
_CHILD = """
import atexit, sys
def _peak():  # VmHWM: this address space's own peak (ru_maxrss keeps the parent's from fork)
    for line in open("/proc/self/status"):
        if line.startswith("VmHWM:"):
            open(sys.argv[3], "w").write(line.split()[1])
atexit.register(_peak)
if sys.argv[1] == "check":  # the console script's own entry point
    from fuzzyctl.cli.entry import run
    sys.argv = ["fuzzyctl", "check", sys.argv[2]]
    run()
import fuzzyctl
from fuzzyctl.diagnostics import DiagnosticError
try:
    fuzzyctl.load(sys.argv[2])
except DiagnosticError as exc:
    sys.stderr.write(exc.render())
    sys.exit(1)
except Exception as exc:
    sys.stderr.write(repr(exc)[:2000])
    sys.exit(3)
"""


def run_case(path: Path, mode: str, timeout: float) -> tuple[float, float, float, int | None]:
    """(wall seconds, CPU seconds, peak RSS in MB, exit code or None on timeout) of a fresh
    process reading ``path`` (``mode``: load or check)."""
    start = time.perf_counter()
    peak_file = path.with_suffix(".peak")
    peak_file.unlink(missing_ok=True)
    proc = subprocess.Popen(
        [sys.executable, "-c", _CHILD, mode, str(path), str(peak_file)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )

    def peak_mb(usage: Any) -> float:
        try:
            return int(peak_file.read_text()) / 1024
        except (OSError, ValueError):  # killed: the last figure the kernel has
            return float(usage.ru_maxrss) / 1024

    deadline = start + timeout
    while True:
        pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
        if pid:
            wall = time.perf_counter() - start
            cpu = usage.ru_utime + usage.ru_stime
            return wall, cpu, peak_mb(usage), os.waitstatus_to_exitcode(status)
        if time.perf_counter() > deadline:
            proc.kill()
            _pid, _status, usage = os.wait4(proc.pid, 0)
            cpu = usage.ru_utime + usage.ru_stime
            return time.perf_counter() - start, cpu, peak_mb(usage), None
        time.sleep(0.01)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mb", type=float, default=10.0, help="size of each file in MB (default 10)")
    ap.add_argument("--formats", default=",".join(FORMATS))
    ap.add_argument("--shapes", default="", help="default: the common shapes and the format's own")
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument(
        "--under-limit", action="store_true", help="also run each shape just under the size limit"
    )
    args = ap.parse_args()
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "src"))
    from fuzzyctl.limits import max_input_bytes

    sizes = [int(args.mb * 1_000_000)]
    if args.under_limit:
        sizes.append(-1)  # each format's own limit, minus 4 KiB
    failed = 0
    print(
        f"goal: < {GOAL_S} s and < {GOAL_MB} MB; exit 0 (accepted) or 1 (refused); "
        f"machine: {os.cpu_count()} cores"
    )
    print(
        f"load average: {os.getloadavg()[0]:.1f} (the goal is judged on CPU time when the machine is shared)"
    )
    print(f"{'format':6} {'shape':10} {'mode':5} {'MB':>6} {'wall s':>7} {'CPU s':>6} {'RSS MB':>7} exit")
    with tempfile.TemporaryDirectory() as tmp:
        for fmt in args.formats.split(","):
            ext, make = FORMATS[fmt]
            shapes = args.shapes.split(",") if args.shapes else [*SHAPES, *FORMAT_SHAPES.get(fmt, ())]
            for shape in shapes:
                for size in sizes:
                    path = Path(tmp) / f"{fmt}-{shape}{ext}"
                    size = size if size > 0 else max_input_bytes(fmt) - 4096
                    path.write_text(make(shape, size), encoding="utf-8")
                    mb = path.stat().st_size / 1e6
                    for mode in ("load", "check") if fmt == "fcl" else ("load",):
                        wall, cpu, rss, code = run_case(path, mode, args.timeout)
                        ok = code in (0, 1) and cpu < GOAL_S and rss < GOAL_MB
                        failed += not ok
                        shown = "hung" if code is None else str(code)
                        flag = "" if ok else "   <-- over the goal"
                        print(
                            f"{fmt:6} {shape:10} {mode:5} {mb:6.1f} {wall:7.2f} {cpu:6.2f} {rss:7.0f} "
                            f"{shown}{flag}",
                            flush=True,
                        )
                    path.unlink()
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
