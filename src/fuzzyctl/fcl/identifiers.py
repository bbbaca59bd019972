"""Which names FCL can read back.

The writer must never produce text the parser rejects: a variable called ``if`` or a term
called ``RULE`` would end the statement it stands in.  The keyword list is read from the
grammar itself so the two cannot drift apart.
"""

from __future__ import annotations

import re
from functools import cache
from importlib import resources

__all__ = ["fcl_block_name", "fcl_keywords", "fcl_name", "fcl_term"]


@cache
def fcl_keywords() -> frozenset[str]:
    """Upper-case words FCL reads as something other than a name: every keyword terminal of
    the grammar (``fcl.lark``: ``IF: "IF"i``, ...), and ``NAN``/``INF``/``INFINITY``, which
    the grammar reads as numbers wherever a number may stand."""
    grammar = resources.files("fuzzyctl.fcl").joinpath("fcl.lark").read_text(encoding="utf-8")
    words = re.findall(r'^[A-Z_]+\s*:\s*"([A-Za-z_]+)"i\s*$', grammar, re.MULTILINE)
    return frozenset(w.upper() for w in words) | {"NAN", "INF", "INFINITY"}


_FCL_ID = re.compile(r"[^\W\d]\w*")  # fcl.lark's ID: a Unicode letter or '_', then word characters


def fcl_name(name: str) -> bool:
    """True when FCL reads ``name`` back as one variable name: an identifier, no keyword
    in any letter case (a variable ``if`` or ``Rule`` would end the statement)."""
    return _FCL_ID.fullmatch(name) is not None and name.upper() not in fcl_keywords()


def fcl_term(name: str) -> bool:
    """Term names may be several words (ridderware JFuzzy's ``Rear Left``), each a name."""
    return bool(name) and all(fcl_name(w) for w in name.split(" "))


def fcl_block_name(name: str) -> bool:
    """fcl.lark's FB_NAME also takes hyphens inside (``FUNCTION_BLOCK tank-level``)."""
    return all(fcl_name(w) for w in name.split("-"))
