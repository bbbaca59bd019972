"""The one place where text from a model becomes part of generated source.

A model file is untrusted input: a rule label, a block name or a term name may hold
``*/``, ``(*``, a newline, a quote, a NUL or a bidirectional-override character.  Every
string that reaches generated code goes through exactly one function of this module per
target, which either makes it inert or refuses it:

========================  =====================================================================
target                    functions
========================  =====================================================================
C                         :func:`c_comment` (body of ``/* */``), :func:`c_string` (a literal),
                          :func:`c_ident` (refuses what is not a plain identifier)
IEC 61131-3 ST / SCL      :func:`st_comment` (body of ``(* *)``, also an SCL ``REGION`` title),
                          :func:`st_string` (a literal), :func:`st_ident` (refuses)
XML (PLCopen TC6)         :func:`xml_text`, :func:`xml_attr`, :func:`xml_comment`
Python                    :func:`py_str` (a literal), :func:`py_ident` (refuses)
IEC 61131-7 FCL           :func:`fcl_comment` (a whole comment), :func:`fcl_options` (the text
                          of an ``OPTIONS`` block); names are checked by the FCL writer
line-based formats        :func:`one_line` (a name or description that must stay on its line:
                          FLL, FIS)
JSON                      :func:`json_text` (the written document, lone surrogates escaped)
========================  =====================================================================

Comment bodies are one line of printable ASCII: ``*/``, ``/*``, ``(*``, ``*)`` and ``??``
(trigraphs) are split by a space, every other character outside ``' '..'~'`` (newlines,
NUL, U+2028, bidirectional controls - the "Trojan Source" trick - and any non-ASCII
letter) is written as ``<U+XXXX>``, and the body is cut to :data:`MAX_COMMENT` characters.
Identifiers are never rewritten (that could merge two names): what is not an identifier of
the target is refused with :class:`CodegenError` naming it.

Interchange formats keep more than generated code: comments may span lines and hold any
letter, so :func:`fcl_comment` keeps newlines, tabs and printable Unicode and writes only the
characters a reader could take for a line end or that a file cannot hold (other control
characters, U+2028/U+2029, U+0085, the BOM, bidirectional controls, lone surrogates) as
``<U+XXXX>``; ``\r\n`` and a lone ``\r`` become ``\n``.

This module imports nothing of fuzzyctl but the error base class, so the engine (Python
source of the specialised path), the code generators and the PLCopen writer share it.
"""

from __future__ import annotations

import re

from fuzzyctl.diagnostics import FuzzyctlError

#: Longest comment body written (longer text is cut and ends with ``...``).
MAX_COMMENT = 500
#: Longest identifier the portable ST subset allows (and the C code keeps to).
MAX_IDENT_ST = 24
#: C99 guarantees 63 significant characters of an internal identifier.
MAX_IDENT_C = 63


class CodegenError(FuzzyctlError):
    """The block uses something the code generator cannot express; the message names it."""


# --------------------------------------------------------------------------- comments

_PRINTABLE = re.compile(r"[^\x20-\x7e]")
# '*' next to '/' or to a parenthesis could open or close a C or ST comment; '??' starts a
# C trigraph ('??/' is a backslash).  A space between them makes every one inert.
_OPENERS = re.compile(r"\*(?=[/)])|[/(](?=\*)|\?(?=\?)")


def _one_line(text: str, limit: int) -> str:
    text = _PRINTABLE.sub(lambda m: f"<U+{ord(m.group()):04X}>", str(text))
    text = _OPENERS.sub(lambda m: m.group() + " ", text)
    if len(text) > limit:
        text = text[: limit - 3].rstrip("\\") + "..."
    return text


def c_comment(text: str) -> str:
    """``text`` as the body of a C ``/* ... */`` comment: one line that cannot end the
    comment, open another one, splice a line (no newline, no trigraph) or hide code from a
    reader (no control or bidirectional characters)."""
    return _one_line(text, MAX_COMMENT)


def st_comment(text: str) -> str:
    """``text`` as the body of a Structured Text ``(* ... *)`` comment (and of an SCL
    ``REGION`` title, which runs to the end of the line): one line of printable ASCII with
    no ``(*``, ``*)``, ``/*`` or ``*/``."""
    return _one_line(text, MAX_COMMENT)


# --------------------------------------------------------------------------- interchange formats

# What a text of an interchange file may not hold as it is: control characters but tab and
# newline, the other line ends (U+0085, U+2028, U+2029), format characters (BOM, the
# bidirectional controls, zero-width ones), lone surrogates (no UTF-8 for them) and the two
# noncharacters U+FFFE/U+FFFF.
_UNSAFE_TEXT = re.compile(
    "[\x00-\x08\x0b-\x1f\x7f-\x9f\u00ad\u061c\u180e\u200b-\u200f\u2028-\u202e"
    "\u2060-\u206f\ufeff\ufff9-\ufffb\ufffe\uffff\ud800-\udfff]"
)
# One comment of FCL as the lark and the fast reader both end it (they do not nest).
_FCL_COMMENT = re.compile(r"\(\*(?:(?!\*\)).)*\*\)|/\*(?:(?!\*/).)*\*/|//[^\n]*", re.S)
# '*' next to ')' or '/' ends a comment, '(' or '/' before '*' opens one (in a reader that
# nests): a space between them makes each inert.
_FCL_DELIMITERS = re.compile(r"\*(?=[)/])|[(/](?=\*)")
_END_OPTIONS = re.compile(r"\b(END)_(OPTIONS?)\b", re.I)


def visible_text(text: str) -> str:
    """``text`` with line ends as ``\\n`` (``\\r\\n`` and ``\\r`` too) and every character of
    ``_UNSAFE_TEXT`` as ``<U+XXXX>``: newlines, tabs and printable Unicode are kept."""
    text = str(text).replace("\r\n", "\n").replace("\r", "\n")
    return _UNSAFE_TEXT.sub(lambda m: f"<U+{ord(m.group()):04X}>", text)


def one_line(text: str) -> str:
    """``text`` on one line: :func:`visible_text` with newlines and tabs as ``<U+000A>`` and
    ``<U+0009>`` (a name or description of a line-based format, FLL or FIS)."""
    return visible_text(text).replace("\n", "<U+000A>").replace("\t", "<U+0009>")


def fcl_comment(text: str) -> str:
    """``text`` (a model comment: the source text of an FCL comment with its delimiters, or the
    plain text another format gave) as exactly one FCL comment, which may span lines.

    The body (the text without its ``(* *)``, ``/* */`` or ``//``) goes between ``(* *)``.  When
    it holds ``(*`` or ``*)``, a comment that is already exactly one FCL comment of visible text
    (FCL's own ``/* a *) b */``) is kept as written; any other text has every ``*)``, ``(*``,
    ``*/`` and ``/*`` split by a space, so it can neither end the comment (and become FCL) nor
    open another one in a reader that nests comments."""
    text = str(text)
    safe = visible_text(text)  # line ends as "\n", what a file cannot hold as <U+XXXX>
    body = safe
    if safe.startswith("//"):
        body = safe[2:].strip()
    elif len(safe) >= 4 and (
        (safe.startswith("/*") and safe.endswith("*/")) or (safe.startswith("(*") and safe.endswith("*)"))
    ):
        body = safe[2:-2].strip()
    if "*)" in body or "(*" in body:
        if safe == text.replace("\r\n", "\n").replace("\r", "\n") and _FCL_COMMENT.fullmatch(safe):
            return safe  # one comment of FCL already, as the file had it (line ends "\n")
        body = _FCL_DELIMITERS.sub(lambda m: m.group() + " ", body)
    return f"(* {body} *)"


def fcl_options(text: str) -> str:
    """The text of an FCL ``OPTIONS`` block (vendor-specific, read up to the first word
    ``END_OPTIONS``/``END_OPTION``): :func:`visible_text`, with such a word inside written
    ``END<U+005F>OPTIONS`` so that it cannot end the block early."""
    return _END_OPTIONS.sub(lambda m: f"{m.group(1)}<U+005F>{m.group(2)}", visible_text(text))


def json_text(text: str) -> str:
    """JSON text (written with ``ensure_ascii=False``) with each lone surrogate as its
    ``\\uXXXX`` escape: JSON reads it back as the same string, and the file can be UTF-8."""
    return re.sub("[\ud800-\udfff]", lambda m: f"\\u{ord(m.group()):04x}", text)


# --------------------------------------------------------------------------- string literals


def c_string(text: str) -> str:
    """A C99 string literal (quotes included) holding the UTF-8 bytes of ``text``: every
    byte outside printable ASCII, the quote, the backslash and ``?`` (trigraphs) are octal
    escapes, which unlike ``\\x`` never swallow a following digit."""
    out = []
    for b in str(text).encode("utf-8", "surrogatepass"):
        ch = chr(b)
        if 0x20 <= b <= 0x7E and ch not in '"\\?':
            out.append(ch)
        else:
            out.append(f"\\{b:03o}")
    return '"' + "".join(out) + '"'


def st_string(text: str) -> str:
    """An IEC 61131-3 STRING literal (quotes included): ``$`` escapes for ``$``, the quote
    and control characters, ``$hh`` for every other byte outside printable ASCII (Latin-1
    when it fits, ``?`` otherwise: a STRING is single-byte)."""
    named = {"$": "$$", "'": "$'", "\n": "$N", "\r": "$R", "\t": "$T", "\f": "$P"}
    out = []
    for ch in str(text):
        if ch in named:
            out.append(named[ch])
        elif " " <= ch <= "~":
            out.append(ch)
        else:
            code = ord(ch) if ord(ch) < 256 else ord("?")
            out.append(f"${code:02X}")
    return "'" + "".join(out) + "'"


def py_str(text: str) -> str:
    """A Python string literal (quotes included) equal to ``text``: ``repr`` of an exact
    ``str`` always is one, whatever the text holds."""
    return str.__repr__(str(text))


# --------------------------------------------------------------------------- XML

# Characters XML 1.0 cannot hold at all (not even as a character reference).
_XML_INVALID = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")
_XML_TEXT = {"&": "&amp;", "<": "&lt;", ">": "&gt;"}
_XML_ATTR = {**_XML_TEXT, '"': "&quot;", "'": "&apos;", "\t": "&#9;", "\n": "&#10;", "\r": "&#13;"}


def _xml_valid(text: str) -> str:
    return _XML_INVALID.sub("\ufffd", str(text))


def xml_text(text: str) -> str:
    """``text`` as XML character data: ``& < >`` escaped (so no ``]]>`` either) and the
    characters XML 1.0 forbids (NUL, most C0 controls, lone surrogates, U+FFFE/U+FFFF)
    replaced by U+FFFD."""
    valid = _xml_valid(text)
    return "".join(_XML_TEXT.get(ch, ch) for ch in valid).replace("\r", "&#13;")


def xml_attr(text: str) -> str:
    """``text`` as the value of an XML attribute in either quote: also ``" '`` escaped and
    tab / newline / carriage return as character references (an attribute value's
    whitespace would otherwise be normalised to spaces)."""
    return "".join(_XML_ATTR.get(ch, ch) for ch in _xml_valid(text))


def xml_comment(text: str) -> str:
    """``text`` as the body of ``<!-- ... -->``: no ``--`` and no trailing ``-``."""
    body = _xml_valid(text).replace("--", "- -").replace("--", "- -")
    return body + " " if body.endswith("-") else body


# --------------------------------------------------------------------------- identifiers

# IEC 61131-3 (3rd edition) keywords, elementary types and standard function names
_IEC = """
ACTION END_ACTION ARRAY OF AT CASE ELSE END_CASE CONFIGURATION END_CONFIGURATION CONSTANT
DO END_FOR END_IF END_REPEAT END_WHILE EN ENO EXIT FALSE FOR FROM FUNCTION END_FUNCTION
FUNCTION_BLOCK END_FUNCTION_BLOCK IF ELSIF INITIAL_STEP END_STEP INTERVAL NON_RETAIN ON
PRIORITY PROGRAM END_PROGRAM READ_ONLY READ_WRITE REPEAT RESOURCE END_RESOURCE RETAIN RETURN
SINGLE STEP STRUCT END_STRUCT TASK THEN TO BY TRANSITION END_TRANSITION TRUE TYPE END_TYPE
UNTIL VAR END_VAR VAR_ACCESS VAR_CONFIG VAR_EXTERNAL VAR_GLOBAL VAR_INPUT VAR_IN_OUT
VAR_OUTPUT VAR_TEMP WHILE WITH AND OR XOR NOT MOD CLASS END_CLASS METHOD END_METHOD
INTERFACE END_INTERFACE PROPERTY END_PROPERTY NAMESPACE END_NAMESPACE USING EXTENDS
IMPLEMENTS THIS SUPER ABSTRACT FINAL OVERRIDE PUBLIC PRIVATE PROTECTED INTERNAL REF REF_TO
NULL CONTINUE VAR_STAT
BOOL BYTE WORD DWORD LWORD SINT INT DINT LINT USINT UINT UDINT ULINT REAL LREAL TIME LTIME
DATE LDATE TIME_OF_DAY TOD LTOD DATE_AND_TIME DT LDT STRING WSTRING CHAR WCHAR ANY ANY_NUM
ANY_REAL ANY_INT ANY_BIT ANY_DATE ANY_STRING ANY_ELEMENTARY ANY_MAGNITUDE ANY_DERIVED
ABS SQRT LN LOG EXP SIN COS TAN ASIN ACOS ATAN ATAN2 EXPT MOVE ADD SUB MUL DIV GT GE EQ LE LT
NE SEL MAX MIN LIMIT MUX SHL SHR ROR ROL LEN LEFT RIGHT MID CONCAT INSERT DELETE REPLACE FIND
TRUNC ROUND CEIL FLOOR R_TRIG F_TRIG TON TOF TP CTU CTD CTUD SR RS
"""
# Beckhoff TwinCAT 3 / CODESYS additions
_TWINCAT = """
POINTER POINTER_TO REFERENCE REFERENCE_TO __NEW __DELETE __ISVALIDREF __QUERYINTERFACE
__QUERYPOINTER __TRY __CATCH __FINALLY __ENDTRY JMP CAL CALC CALCN RET RETC RETCN LD LDN ST
STN S R ADR ADRINST BITADR SIZEOF INDEXOF UNION END_UNION VAR_INST PERSISTENT XSIZE
__SYSTEM PRAGMA QUERYINTERFACE UXINT XINT XWORD BIT
"""
# Siemens SCL (TIA Portal) additions
_SCL = """
BEGIN ORGANIZATION_BLOCK END_ORGANIZATION_BLOCK DATA_BLOCK END_DATA_BLOCK TITLE VERSION
AUTHOR FAMILY NAME KNOW_HOW_PROTECT REGION END_REGION GOTO BLOCK_DB BLOCK_FB BLOCK_FC
BLOCK_SDB BLOCK_SFB BLOCK_SFC COUNTER TIMER S5TIME VARIANT VOID DB FB FC OB SFB SFC UDT
DINT_TO_REAL INT_TO_REAL REAL_TO_INT NORM_X SCALE_X OK
"""

RESERVED: frozenset[str] = frozenset((_IEC + _TWINCAT + _SCL).split())

# C keywords and the library names the generated code uses
C_KEYWORDS: frozenset[str] = frozenset(
    [
        "auto",
        "break",
        "case",
        "char",
        "const",
        "continue",
        "default",
        "do",
        "double",
        "else",
        "enum",
        "extern",
        "float",
        "for",
        "goto",
        "if",
        "inline",
        "int",
        "long",
        "register",
        "restrict",
        "return",
        "short",
        "signed",
        "sizeof",
        "static",
        "struct",
        "switch",
        "typedef",
        "union",
        "unsigned",
        "void",
        "volatile",
        "while",
        "_Bool",
        "_Complex",
        "_Imaginary",
        "bool",
        "true",
        "false",
        "NULL",
        "NAN",
        "INFINITY",
        "main",
        "exp",
        "log",
        "sqrt",
        "pow",
        "fabs",
        "cos",
        "sin",
        "tan",
        "size_t",
    ]
)


_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
_PY_KEYWORDS = frozenset(
    [
        "False",
        "None",
        "True",
        "and",
        "as",
        "assert",
        "async",
        "await",
        "break",
        "class",
        "continue",
        "def",
        "del",
        "elif",
        "else",
        "except",
        "finally",
        "for",
        "from",
        "global",
        "if",
        "import",
        "in",
        "is",
        "lambda",
        "nonlocal",
        "not",
        "or",
        "pass",
        "raise",
        "return",
        "try",
        "while",
        "with",
        "yield",
        "match",
        "case",
        "type",
        "_",
    ]
)
#: Python keywords (and ``_``): no generated Python name is one.
PY_KEYWORDS = _PY_KEYWORDS

# Object-like macros of <math.h> and <stddef.h>: a member of that name would be rewritten by
# the preprocessor.
_C_MACRO = re.compile(r"(M_|FP_|HUGE_VAL|MATH_ERR|math_errhandling|INFINITY$|NAN$|NULL$|offsetof$)")


def st_ident(name: str, what: str) -> str:
    """``name`` when it is an identifier of portable ST (IEC letters, digits and single inner
    underscores, at most :data:`MAX_IDENT_ST` characters, no reserved word of IEC 61131-3,
    TwinCAT or SCL); else :class:`CodegenError` naming ``what``."""
    shown = _shown(name)
    if not isinstance(name, str) or not _IDENT.match(name) or "__" in name or name.endswith("_"):
        raise CodegenError(
            f"{what} {shown} is not a portable IEC 61131-3 identifier "
            "(letters, digits, single inner underscores)"
        )
    if len(name) > MAX_IDENT_ST:
        raise CodegenError(f"{what} {shown} is longer than {MAX_IDENT_ST} characters (portable ST limit)")
    if name.upper() in RESERVED:
        raise CodegenError(f"{what} {shown} is a reserved word in IEC 61131-3, TwinCAT or SCL")
    return name


def c_ident(name: str, what: str) -> str:
    """``name`` when it is a C identifier that cannot clash with the language, the C library
    macros or the generated code's own names; else :class:`CodegenError` naming ``what``."""
    shown = _shown(name)
    if not isinstance(name, str) or not _IDENT.match(name):
        raise CodegenError(f"{what} {shown} is not a C identifier")
    if len(name) > MAX_IDENT_C:
        raise CodegenError(f"{what} {shown} is longer than {MAX_IDENT_C} characters")
    if name in C_KEYWORDS or _C_MACRO.match(name):
        raise CodegenError(f"{what} {shown} is a C keyword or a name the generated code uses")
    if name.startswith("__") or (name[0] == "_" and name[1:2].isupper()):
        raise CodegenError(f"{what} {shown} is reserved to the C implementation")
    return name


def py_ident(name: str, what: str) -> str:
    """``name`` when it is a plain ASCII Python identifier and no keyword; else
    :class:`CodegenError`."""
    if not isinstance(name, str) or not _IDENT.match(name) or name in _PY_KEYWORDS:
        raise CodegenError(f"{what} {_shown(name)} is not a plain Python identifier")
    return name


def _shown(name: object) -> str:
    """A name quoted for an error message: ``repr``, cut, so a hostile name cannot flood a
    terminal or hide control characters in it."""
    text = repr(name)
    return text if len(text) <= 60 else text[:57] + "..."


# The functions and function blocks of the library matiec (the compiler of OpenPLC and
# Beremiz) loads with every program, typed variants and conversions included (e.g. ADD_REAL,
# INT_TO_REAL, PID, RAMP, INTEGRAL): matiec refuses them as variable names.
_IEC_TYPES = (
    "(?:BOOL|SINT|INT|DINT|LINT|USINT|UINT|UDINT|ULINT|REAL|LREAL|TIME|DATE|TOD|DT|STRING|BYTE|"
    "WORD|DWORD|LWORD|DATE_AND_TIME|TIME_OF_DAY)"
)
_IEC_POUS = """
ABS ACOS ADD AND ASIN ATAN CONCAT COS CTD CTU CTUD DELETE DERIVATIVE DIV DIVTIME EQ EXP EXPT
FIND F_TRIG GE GT HYSTERESIS INSERT INTEGRAL LE LEFT LEN LIMIT LN LOG LT MAX MID MIN MOD MOVE
MUL MULTIME MUX NE NOT OR PID RAMP REPLACE RIGHT ROL ROR RS RTC R_TRIG SEL SEMA SHL SHR SIN
SQRT SR SUB TAN TOF TON TP TRUNC XOR
"""
_IEC_LIBRARY = re.compile(
    rf"(?:{'|'.join(_IEC_POUS.split())})(?:_{_IEC_TYPES}){{0,2}}"
    rf"|(?:{_IEC_TYPES}_)?(?:{_IEC_TYPES}|BCD)_TO_(?:BCD_)?{_IEC_TYPES}|{_IEC_TYPES}_TO_BCD(?:_{_IEC_TYPES})?",
    re.IGNORECASE,
)


def st_ident_iec(name: str, what: str) -> str:
    """:func:`st_ident`, and not the name of a function or function block of matiec's library
    (OpenPLC, Beremiz), which matiec refuses as a variable name."""
    st_ident(name, what)
    if _IEC_LIBRARY.fullmatch(name):
        raise CodegenError(
            f"{what} {_shown(name)} is the name of a standard function or function block "
            "in OpenPLC's compiler (matiec): rename it"
        )
    return name
