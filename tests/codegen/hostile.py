"""Hostile model files for the code-injection tests: one small system per reader (FCL, FIS,
FLL, JSON, FPL, XFUZ) whose every text field is a placeholder, the strings to put there,
and scanners that reduce generated C / Structured Text to their code tokens (comments
dropped, identifiers folded) the way the languages' own front ends do."""

from __future__ import annotations

import json
import re
from collections.abc import Iterator
from typing import Any

#: Strings that would break out of a comment, a string, a line or an XML text if pasted.
HOSTILE: dict[str, str] = {
    "issue-14": '1 */ { extern int system(const char *); system("touch pwned"); } /*',
    "c-close": "*/ PWNED(); /*",
    "st-close": "*) PWNED := 1; (*",
    "newline": "x\nPWNED();\n",
    "splice": "x\\\nPWNED();",
    "trigraph": "??/\nPWNED();",
    "quotes": "x\" PWNED ' $' ",
    "nul": "a\x00PWNED\x1b[2J",
    "cdata": "]]> <PWNED/> <!--",
    "template": "${PWNED} %s {0}",
    "unicode-lines": "a\u2028PWNED\u2029b\u202eevil",
    "line-comment": "// PWNED\n",
    "flood": "P" * 20_000,
}

#: The FCL template.  Placeholders: QQfbQQ (block name), QQinQQ / QQoutQQ (variables),
#: QQtermQQ / QQotermQQ (terms), QQlabelQQ (rule label), QQblockQQ (rule block), QQcmtQQ /
#: QQvcmtQQ (comments), QQdefQQ (DEFAULT), QQhiQQ (a range bound).
FCL = """(* QQcmtQQ *)
FUNCTION_BLOCK QQfbQQ
VAR_INPUT
    QQinQQ : REAL; (* QQvcmtQQ *)
    rate : REAL;
END_VAR
VAR_OUTPUT
    QQoutQQ : REAL;
END_VAR
FUZZIFY QQinQQ
    TERM QQtermQQ := (-4, 1) (-2, 0);
    TERM zero := (-2, 0) (0, 1) (2, 0);
    TERM pos := (0, 0) (2, 1);
    RANGE := (-4 .. QQhiQQ);
END_FUZZIFY
FUZZIFY rate
    TERM neg := (-1.0, 1) (0, 0);
    TERM pos := (0, 0) (1.0, 1);
END_FUZZIFY
DEFUZZIFY QQoutQQ
    TERM QQotermQQ := -5;
    TERM zero := 0;
    TERM big := 5;
    METHOD : CoGS;
    DEFAULT := QQdefQQ;
END_DEFUZZIFY
RULEBLOCK QQblockQQ
    AND : MIN;
    ACCU : MAX;
    RULE QQlabelQQ : IF QQinQQ IS QQtermQQ AND rate IS neg THEN QQoutQQ IS QQotermQQ;
    RULE 2 : IF QQinQQ IS zero THEN QQoutQQ IS zero;
    RULE 3 : IF QQinQQ IS pos OR rate IS pos THEN QQoutQQ IS big;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""

FIS = """[System]
Name='QQfbQQ'
Type='sugeno'
Version=2.0
NumInputs=2
NumOutputs=1
NumRules=3
AndMethod='min'
OrMethod='max'
ImpMethod='min'
AggMethod='max'
DefuzzMethod='wtaver'

[Input1]
Name='QQinQQ'
Range=[-4 QQhiQQ]
NumMFs=3
MF1='QQtermQQ':'trapmf',[-inf -inf -4 -2]
MF2='zero':'trimf',[-2 0 2]
MF3='pos':'trapmf',[0 2 inf inf]

[Input2]
Name='rate'
Range=[-1 1]
NumMFs=2
MF1='neg':'trapmf',[-inf -inf -1 0]
MF2='pos':'trapmf',[0 1 inf inf]

[Output1]
Name='QQoutQQ'
Range=[-5 5]
NumMFs=3
MF1='QQotermQQ':'constant',[-5]
MF2='zero':'constant',[0]
MF3='big':'constant',[5]

[Rules]
1 1, 1 (1) : 1
2 0, 2 (1) : 1
3 2, 3 (1) : 2
"""

FLL = """# QQcmtQQ
Engine: QQfbQQ
  description: QQvcmtQQ
InputVariable: QQinQQ
  enabled: true
  range: -4 QQhiQQ
  lock-range: false
  term: QQtermQQ Discrete -4 1 -2 0
  term: zero Discrete -2 0 0 1 2 0
  term: pos Discrete 0 0 2 1
InputVariable: rate
  enabled: true
  range: -1 1
  lock-range: false
  term: neg Discrete -1 1 0 0
  term: pos Discrete 0 0 1 1
OutputVariable: QQoutQQ
  enabled: true
  range: -5 5
  lock-range: false
  aggregation: Maximum
  defuzzifier: WeightedAverage
  default: QQdefQQ
  lock-previous: false
  term: QQotermQQ Constant -5
  term: zero Constant 0
  term: big Constant 5
RuleBlock: QQblockQQ
  enabled: true
  conjunction: Minimum
  disjunction: Maximum
  implication: none
  activation: General
  rule: if QQinQQ is QQtermQQ and rate is neg then QQoutQQ is QQotermQQ
  rule: if QQinQQ is zero then QQoutQQ is zero
  rule: if QQinQQ is pos or rate is pos then QQoutQQ is big
"""

FPL = """/*QQcmtQQ*/
PROJECT QQfbQQ
VAR QQinQQ
TYPE float
MIN -4.0
MAX QQhiQQ
MEMBER QQtermQQ
POINTS -4.0,1.0 -2.0,0.0
END
MEMBER zero
POINTS -2.0,0.0 0.0,1.0 2.0,0.0
END
MEMBER pos
POINTS 0.0,0.0 2.0,1.0
END
END
VAR rate
TYPE float
MIN -1.0
MAX 1.0
MEMBER neg
POINTS -1.0,1.0 0.0,0.0
END
MEMBER pos
POINTS 0.0,0.0 1.0,1.0
END
END
VAR QQoutQQ
TYPE float
MIN -5.025
MAX 5.025
MEMBER QQotermQQ
POINTS -5.025,1.0 -4.975,1.0
END
MEMBER zero
POINTS -0.025,1.0 0.025,1.0
END
MEMBER big
POINTS 4.975,1.0 5.025,1.0
END
END
FUZZY QQblockQQ
RULE QQlabelQQ
IF (QQinQQ is QQtermQQ) AND (rate is neg)
THEN QQoutQQ = QQotermQQ
END
RULE 2
IF (QQinQQ is zero)
THEN QQoutQQ = zero
END
END
CONNECT
FROM QQinQQ
TO QQblockQQ
END
CONNECT
FROM rate
TO QQblockQQ
END
CONNECT
FROM QQblockQQ
TO QQoutQQ
END
END
"""

TEMPLATES = {"fcl": FCL, "fis": FIS, "fll": FLL, "fpl": FPL}
#: What a placeholder stands for in the benign system (the others are their own name).
BENIGN = {"QQdefQQ": "0", "QQhiQQ": "2", "QQcmtQQ": "a comment", "QQvcmtQQ": "a note"}
PLACEHOLDERS = (
    "QQfbQQ",
    "QQinQQ",
    "QQoutQQ",
    "QQtermQQ",
    "QQotermQQ",
    "QQlabelQQ",
    "QQblockQQ",
    "QQcmtQQ",
    "QQvcmtQQ",
    "QQdefQQ",
    "QQhiQQ",
)


def fill(template: str, field: str | None, text: str) -> str:
    """The template with ``field`` replaced by ``text`` and every other placeholder benign."""
    out = template
    for ph in PLACEHOLDERS:
        out = out.replace(ph, text if ph == field else BENIGN.get(ph, ph))
    return out


def json_model(fcl_document: Any, field: str | None, text: str) -> str:
    """The fuzzyctl JSON of the FCL template with ``field`` replaced in every string value
    (JSON carries names, labels and comments as free strings: no reader grammar in the way)."""
    from fuzzyctl.formats.json import writer as fj

    def walk(value: Any) -> Any:
        if isinstance(value, str):
            for ph in PLACEHOLDERS:
                if ph in value:
                    value = value.replace(ph, text if ph == field else BENIGN.get(ph, ph))
            return value
        if isinstance(value, list):
            return [walk(v) for v in value]
        if isinstance(value, dict):
            return {k: walk(v) for k, v in value.items()}
        return value

    data = walk(fj.to_dict(fcl_document))
    if field == "QQcmtQQ":
        data["blocks"][0]["comments"] = [text]
    return json.dumps(data)


def xfuz_words(text: str, n: int = 4) -> list[int]:
    """``text`` as the packed name words of an XFUZ table (two Latin-1 bytes a word, low
    byte first, signed 16 bit)."""
    raw = text.encode("latin-1", "replace")[: 2 * n].ljust(2 * n, b"\0")
    words = [raw[2 * k] | raw[2 * k + 1] << 8 for k in range(n)]
    return [w - 65536 if w >= 32768 else w for w in words]


# --------------------------------------------------------------------------- scanners

_TRIGRAPH = {"=": "#", "/": "\\", "'": "^", "(": "[", ")": "]", "!": "|", "<": "{", ">": "}", "-": "~"}
_C_TOKEN = re.compile(
    r"/\*.*?\*/|//[^\n]*|\"(?:\\.|[^\"\\\n])*\"|'(?:\\.|[^'\\\n])*'|[A-Za-z_]\w*"
    r"|\.?\d(?:[eEpP][+-]|[\w.])*|\S",
    re.S,
)


def c_tokens(text: str) -> Iterator[str]:
    """The tokens a C99 compiler sees (trigraphs and line splices applied, comments dropped),
    identifiers folded to ``ID`` and strings to ``STR`` so that renamed blocks and variables
    compare equal."""
    text = re.sub(r"\?\?([=/'()!<>-])", lambda m: _TRIGRAPH[m[1]], text).replace("\\\n", "")
    for m in _C_TOKEN.finditer(text):
        tok = m.group()
        if tok.startswith(("/*", "//")):
            continue
        if tok[0] == '"':  # only #include "NAME.h": the name is an identifier
            yield "STR"
            continue
        yield "ID" if tok[0].isalpha() or tok[0] == "_" else tok


_ST_TOKEN = re.compile(
    r"\(\*.*?\*\)|/\*.*?\*/|//[^\n]*|'(?:\$.|[^'$])*'|\"(?:\$.|[^\"$])*\"|REGION[^\n]*"
    r"|[A-Za-z_]\w*|\d[\w.#]*(?:[eE][+-]?\d+)?|:=|\S",
    re.S,
)


def st_tokens(text: str) -> Iterator[str]:
    """The tokens of Structured Text (comments dropped, an SCL REGION title dropped),
    identifiers folded; a comment holding ``(*`` would read differently on a compiler that
    nests comments, so it is an error here."""
    for m in _ST_TOKEN.finditer(text):
        tok = m.group()
        if tok.startswith("(*"):
            assert "(*" not in tok[2:-2] and "\n" not in tok, tok[:200]
            continue
        if tok.startswith(("/*", "//")):
            continue
        if tok.startswith("REGION"):
            yield "REGION"
            continue
        if tok[0] == '"':  # SCL's quoted block name: an identifier
            yield "ID"
            continue
        yield "ID" if tok[0].isalpha() or tok[0] == "_" else tok
