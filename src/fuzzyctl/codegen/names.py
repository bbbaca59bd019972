"""Identifier rules of the generated code: the combined reserved words of IEC 61131-3,
Beckhoff TwinCAT 3 / CODESYS and Siemens SCL, IEC identifier syntax and C keywords.

They live in :mod:`fuzzyctl.escape` (the one module every string reaching generated code
goes through); this module keeps the names the code generator has always used."""

from __future__ import annotations

from fuzzyctl.escape import C_KEYWORDS, RESERVED
from fuzzyctl.escape import c_ident as check_c
from fuzzyctl.escape import st_ident as check_st

__all__ = ["C_KEYWORDS", "RESERVED", "check_c", "check_st"]
