"""What fuzzyctl's JSON reader and writer share: the format tag and version, the type tags of
the model's classes, and the JSON Schema shipped next to this module."""

from __future__ import annotations

import json
from importlib import resources
from typing import Any

from fuzzyctl import model as m

FORMAT_NAME = "fuzzyctl-model"
VERSION = 1
SCHEMA_FILE = "fuzzyctl-model.schema.json"

TAGS: dict[type, str] = {
    m.Ref: "ref",
    m.PointsMF: "points",
    m.SingletonMF: "singleton",
    m.SingletonsMF: "singletons",
    m.ShapeMF: "shape",
    m.FunctionMF: "function",
    m.LowerMF: "lower",
    m.Num: "num",
    m.Name: "name",
    m.Unary: "unary",
    m.Binary: "binary",
    m.Call: "call",
    m.Is: "is",
    m.Degree: "degree",
    m.Not: "not",
    m.And: "and",
    m.Or: "or",
}
CLASSES: dict[str, type] = {tag: cls for cls, tag in TAGS.items()}


def schema() -> dict[str, Any]:
    """The JSON Schema of this format (draft 2020-12)."""
    text = resources.files("fuzzyctl.formats.json").joinpath(SCHEMA_FILE).read_text(encoding="utf-8")
    loaded = json.loads(text)
    assert isinstance(loaded, dict)
    return loaded
