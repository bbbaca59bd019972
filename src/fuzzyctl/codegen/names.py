"""Identifier rules of the generated code: the combined reserved words of IEC 61131-3,
Beckhoff TwinCAT 3 / CODESYS and Siemens SCL (so one file pastes into all three), IEC
identifier syntax, and C keywords."""

from __future__ import annotations

import re

from fuzzyctl.codegen.context import MAX_IDENT, CodegenError

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
    ]
)

_IEC_IDENT = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


def check_st(name: str, what: str) -> None:
    """Raise :class:`CodegenError` when ``name`` cannot be an identifier of portable ST."""
    if not _IEC_IDENT.match(name) or "__" in name or name.endswith("_"):
        raise CodegenError(
            f"{what} {name!r} is not a portable IEC 61131-3 identifier "
            "(letters, digits, single inner underscores)"
        )
    if len(name) > MAX_IDENT:
        raise CodegenError(f"{what} {name!r} is longer than {MAX_IDENT} characters (portable ST limit)")
    if name.upper() in RESERVED:
        raise CodegenError(f"{what} {name!r} is a reserved word in IEC 61131-3, TwinCAT or SCL")


def check_c(name: str, what: str) -> None:
    if not _IEC_IDENT.match(name):
        raise CodegenError(f"{what} {name!r} is not a C identifier")
    if name in C_KEYWORDS:
        raise CodegenError(f"{what} {name!r} is a C keyword or a name the generated code uses")
