"""Reading FCL (IEC 61131-7) for the format registry: :func:`fuzzyctl.fcl.load_text` parses
and checks; the registry gets the model and the warnings."""

from __future__ import annotations

from fuzzyctl.formats import Loaded
from fuzzyctl.formats.fcl.names import fcl_api
from fuzzyctl.model import Document


def read(text: str, path: str | None = None) -> Loaded:
    """The model of FCL ``text`` and its warnings; raises on errors."""
    api = fcl_api()
    assert api is not None
    result = api.load_text(text, path)
    document = result.raise_for_errors()
    assert isinstance(document, Document)
    return Loaded(document, tuple(d for d in result.diagnostics if not d.is_error))


__all__ = ["read"]
