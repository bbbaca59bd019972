"""The Siemens S7 Fuzzy Control blocks: FUZZY (FB30), FUZZY_AI (FC30), FUZZY_AO (FC31),
and the ``siemens`` profile that says whether a controller fits them."""

from fuzzyctl.blocks.siemens.analog import AnalogResult, fuzzy_ai, fuzzy_ao
from fuzzyctl.blocks.siemens.fb import FuzzyFB
from fuzzyctl.blocks.siemens.info import Info
from fuzzyctl.blocks.siemens.profile import LIMITS, check_siemens

__all__ = ["LIMITS", "AnalogResult", "FuzzyFB", "Info", "check_siemens", "fuzzy_ai", "fuzzy_ao"]
