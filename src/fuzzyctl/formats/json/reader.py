"""fuzzyctl's own JSON form of the model: complete, versioned, lossless.

Every field of every model class is written under its Python name, so ``model -> JSON ->
model`` gives an equal model (source spans and comments included).  Objects that can be one
of several classes carry a ``"type"`` tag (see :data:`TAGS`); numbers that JSON cannot hold
are the strings ``"NaN"``, ``"Infinity"``, ``"-Infinity"``.  A reader fills fields a file
leaves out with the model's defaults, so a tool may write only what it knows.  The layout
is described by the JSON Schema shipped next to this module
(``fuzzyctl-model.schema.json``) and documented in ``docs/formats.md``.
"""

from __future__ import annotations

import dataclasses
import json as _json
import math
import types
import typing
from enum import Enum
from importlib import resources
from typing import Any

from fuzzyctl import model as m
from fuzzyctl.diagnostics import DiagnosticError, error
from fuzzyctl.escape import json_text
from fuzzyctl.formats import Format, Loaded
from fuzzyctl.validation import at_json_paths

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
_OPTIONAL_WHEN_EMPTY = frozenset({"span", "comments", "placed_comments", "item_spans", "grouped"})


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
    # json_text: a lone surrogate (a JSON comment may hold one) as its escape, so UTF-8 can hold it
    return json_text(_json.dumps(to_dict(document), indent=2, ensure_ascii=False, allow_nan=False)) + "\n"


class JsonModelError(ValueError):
    """A JSON document that does not describe a model; ``where`` is a JSON path."""

    def __init__(self, where: str, message: str) -> None:
        super().__init__(f"{where}: {message}")
        self.where = where


_HINTS: dict[type, dict[str, Any]] = {}


def _hints(cls: type) -> dict[str, Any]:
    if cls not in _HINTS:
        _HINTS[cls] = typing.get_type_hints(cls, vars(m))
    return _HINTS[cls]


def _decode_float(value: Any, where: str) -> float:
    if isinstance(value, bool):
        raise JsonModelError(where, "expected a number, found a boolean")
    if isinstance(value, int | float):
        try:
            return float(value)
        except OverflowError:  # data not read by load_json (the studio's requests)
            raise JsonModelError(where, "the number is too large (beyond 1.8e308)") from None
    if value in ("NaN", "Infinity", "-Infinity"):
        return {"NaN": math.nan, "Infinity": math.inf, "-Infinity": -math.inf}[value]
    raise JsonModelError(where, f"expected a number, found {value!r}")


def decode(value: Any, tp: Any, where: str = "$") -> Any:
    """Build a value of type ``tp`` (a model annotation) from JSON data."""
    origin = typing.get_origin(tp)
    if origin in (typing.Union, types.UnionType):
        args = typing.get_args(tp)
        if value is None:
            if type(None) in args:
                return None
            raise JsonModelError(where, "must not be null")
        if isinstance(value, dict) and "type" in value:
            cls = CLASSES.get(value["type"])
            if cls is None or not any(_accepts(a, cls) for a in args):
                raise JsonModelError(where, f"unexpected type tag {value['type']!r}")
            return decode(value, cls, where)
        if isinstance(value, dict) and "text" in value and str in args:
            return str(value["text"])
        if isinstance(value, bool) and bool in args:
            return value
        if int in args and isinstance(value, int) and not isinstance(value, bool):
            return value
        if float in args and (isinstance(value, int | float) or value in ("NaN", "Infinity", "-Infinity")):
            return _decode_float(value, where)
        if str in args and isinstance(value, str):
            return value
        for a in args:
            if dataclasses.is_dataclass(a) and isinstance(value, dict):
                return decode(value, a, where)
        raise JsonModelError(where, f"unexpected value {value!r}")
    if origin is tuple:
        if not isinstance(value, list):
            raise JsonModelError(where, "expected a list")
        args = typing.get_args(tp)
        if len(args) == 2 and args[1] is Ellipsis:
            return tuple(decode(v, args[0], f"{where}[{i}]") for i, v in enumerate(value))
        if len(value) != len(args):
            raise JsonModelError(where, f"expected {len(args)} items, found {len(value)}")
        return tuple(decode(v, a, f"{where}[{i}]") for i, (v, a) in enumerate(zip(value, args, strict=True)))
    if tp is float:
        return _decode_float(value, where)
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise JsonModelError(where, f"expected an integer, found {value!r}")
        return value
    if tp is bool:
        if not isinstance(value, bool):
            raise JsonModelError(where, f"expected true or false, found {value!r}")
        return value
    if tp is str:
        if not isinstance(value, str):
            raise JsonModelError(where, f"expected a string, found {value!r}")
        return value
    if isinstance(tp, type) and issubclass(tp, Enum):
        try:
            return tp(value)
        except ValueError:
            raise JsonModelError(where, f"unknown value {value!r}") from None
    if isinstance(tp, type) and dataclasses.is_dataclass(tp):
        if not isinstance(value, dict):
            raise JsonModelError(where, f"expected an object for {tp.__name__}")
        hints = _hints(tp)
        names = {f.name for f in dataclasses.fields(tp)}
        unknown = set(value) - names - {"type"}
        if unknown:
            raise JsonModelError(where, f"unknown field(s) {', '.join(sorted(unknown))} for {tp.__name__}")
        kwargs = {}
        for f in dataclasses.fields(tp):
            if f.name in value:
                kwargs[f.name] = decode(value[f.name], hints[f.name], f"{where}.{f.name}")
            elif f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                raise JsonModelError(where, f"missing field {f.name!r} of {tp.__name__}")
        return tp(**kwargs)
    raise JsonModelError(where, f"cannot decode into {tp!r}")


def _accepts(annotation: Any, cls: type) -> bool:
    if annotation is cls:
        return True
    origin = typing.get_origin(annotation)
    if origin in (typing.Union, types.UnionType):
        return any(_accepts(a, cls) for a in typing.get_args(annotation))
    return False


def from_dict(data: Any) -> m.Document:
    """A document from JSON data; raises :class:`JsonModelError` naming the JSON path."""
    if not isinstance(data, dict):
        raise JsonModelError("$", "expected an object")
    if data.get("format") != FORMAT_NAME:
        raise JsonModelError("$.format", f"expected {FORMAT_NAME!r}")
    version = data.get("version")
    if version != VERSION:
        raise JsonModelError("$.version", f"this fuzzyctl reads version {VERSION}, the file has {version!r}")
    body = {k: v for k, v in data.items() if k not in {"format", "version"}}
    document = decode(body, m.Document)
    assert isinstance(document, m.Document)
    return document


def schema() -> dict[str, Any]:
    """The JSON Schema of this format (draft 2020-12)."""
    text = resources.files("fuzzyctl.formats").joinpath(SCHEMA_FILE).read_text(encoding="utf-8")
    loaded = _json.loads(text)
    assert isinstance(loaded, dict)
    return loaded


def read(text: str, path: str | None = None) -> Loaded:
    from fuzzyctl.limits import load_json

    data = load_json(text, path)  # the nesting and number limits of every reader
    try:
        document = from_dict(data)
    except JsonModelError as exc:
        raise DiagnosticError(
            [error(f"not a fuzzyctl model: {exc}", None, code="json-model", file=path)], text
        ) from None
    return Loaded(dataclasses.replace(document, path=path))


def _write(document: m.Document) -> str:
    return dumps(document)


FORMAT = Format(
    name="json",
    extensions=(".json",),
    description="fuzzyctl model as JSON (lossless; schema in fuzzyctl/formats/fuzzyctl-model.schema.json)",
    read=read,
    write=_write,
    place=at_json_paths,
)
