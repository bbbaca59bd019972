"""Reading fuzzyctl's own JSON form of the model: complete, versioned, lossless.

Every field of every model class is written under its Python name, so ``model -> JSON ->
model`` gives an equal model (source spans and comments included).  Objects that can be one
of several classes carry a ``"type"`` tag (see :data:`TAGS`); numbers that JSON cannot hold
are the strings ``"NaN"``, ``"Infinity"``, ``"-Infinity"``.  A reader fills fields a file
leaves out with the model's defaults, so a tool may write only what it knows.  The layout
is described by the JSON Schema shipped next to this module
(``fuzzyctl-model.schema.json``) and documented in ``docs/formats.md``.  The writer is
:mod:`.writer`; what both use is in :mod:`.names`.
"""

from __future__ import annotations

import dataclasses
import math
import types
import typing
from enum import Enum
from typing import Any

from fuzzyctl import model as m
from fuzzyctl.diagnostics import DiagnosticError, error
from fuzzyctl.formats import Loaded
from fuzzyctl.formats.json.names import CLASSES, FORMAT_NAME, VERSION


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


def read(text: str, path: str | None = None) -> Loaded:
    """The model of JSON ``text``; an error names the JSON path where it does not fit."""
    from fuzzyctl.limits import load_json

    data = load_json(text, path)  # the nesting and number limits of every reader
    try:
        document = from_dict(data)
    except JsonModelError as exc:
        raise DiagnosticError(
            [error(f"not a fuzzyctl model: {exc}", None, code="json-model", file=path)], text
        ) from None
    return Loaded(dataclasses.replace(document, path=path))


__all__ = ["JsonModelError", "decode", "from_dict", "read"]
