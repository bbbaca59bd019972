"""Writing fuzzyctl's own JSON form of the model: every field of every model class under its
Python name, a ``"type"`` tag where a field can hold several classes, and the numbers JSON
cannot hold as the strings ``"NaN"``, ``"Infinity"``, ``"-Infinity"`` (:mod:`.reader` reads
it back to an equal model)."""

from __future__ import annotations

import dataclasses
import json
import math
from enum import Enum
from typing import Any

from fuzzyctl import model as m
from fuzzyctl.escape import json_text
from fuzzyctl.formats.json.names import FORMAT_NAME, TAGS, VERSION

# (``lower`` and ``type_reduction``: type-2 only, so a type-1 model is written as before)
_OPTIONAL_WHEN_EMPTY = frozenset(
    {"span", "comments", "placed_comments", "item_spans", "grouped", "lower", "type_reduction"}
)


def _number(value: float) -> float | str:
    if math.isnan(value):
        return "NaN"
    if math.isinf(value):
        return "Infinity" if value > 0 else "-Infinity"
    return value


def encode(obj: Any) -> Any:
    """The JSON-ready value of a model object."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        out: dict[str, Any] = {}
        tag = TAGS.get(type(obj))
        if tag:
            out["type"] = tag
        for f in dataclasses.fields(obj):
            value = getattr(obj, f.name)
            if f.name in _OPTIONAL_WHEN_EMPTY and not value:
                continue
            if isinstance(obj, m.Document) and f.name == "path":
                continue  # where the file was, not what it says
            if isinstance(obj, m.Variable) and f.name == "initial" and isinstance(value, str):
                out[f.name] = {"text": value}  # keeps a text initial value apart from "NaN"
                continue
            out[f.name] = encode(value)
        return out
    if isinstance(obj, Enum):
        return obj.value
    if isinstance(obj, bool) or obj is None or isinstance(obj, str):
        return obj
    if isinstance(obj, int | float):
        return _number(float(obj)) if isinstance(obj, float) else obj
    if isinstance(obj, tuple | list):
        return [encode(v) for v in obj]
    raise TypeError(f"cannot encode {type(obj).__name__}")


def to_dict(document: m.Document) -> dict[str, Any]:
    """The whole document as a JSON-ready dict (``format``, ``version``, ``blocks``...)."""
    body = encode(document)
    return {"format": FORMAT_NAME, "version": VERSION, **body}


def dumps(document: m.Document) -> str:
    """The document as JSON text (:func:`to_dict`, indented)."""
    # json_text: a lone surrogate (a JSON comment may hold one) as its escape, so UTF-8 can hold it
    return json_text(json.dumps(to_dict(document), indent=2, ensure_ascii=False, allow_nan=False)) + "\n"


__all__ = ["dumps", "encode", "to_dict"]
