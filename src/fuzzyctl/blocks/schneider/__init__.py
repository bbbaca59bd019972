"""The Schneider/Telemecanique XFUZ function block (OFB-FUZZY) and its inference.

The knowledge-base tables (ESV/FA/RG) are encoded and checked in
:mod:`fuzzyctl.formats.xfuz.tables`, which the block and the file format share."""

from fuzzyctl.blocks.schneider.fb import XfuzFB, XfuzSnapshot
from fuzzyctl.blocks.schneider.inference import InferenceResult, XfuzInference
from fuzzyctl.formats.xfuz.tables import KnowledgeBase, StatusBit, XfuzConstants

__all__ = [
    "InferenceResult",
    "KnowledgeBase",
    "StatusBit",
    "XfuzConstants",
    "XfuzFB",
    "XfuzInference",
    "XfuzSnapshot",
]
