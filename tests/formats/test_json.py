"""The JSON form: lossless round trip (hypothesis), schema validity, clear errors."""

from __future__ import annotations

import json

import jsonschema
import pytest
from hypothesis import HealthCheck, given, settings

from fuzzyctl.diagnostics import DiagnosticError
from fuzzyctl.formats.json import names, reader, writer
from fuzzyctl.model import Document, FunctionBlock

from .strategies import documents

VALIDATOR = jsonschema.Draft202012Validator(names.schema())


def _same_everywhere(a: object, b: object) -> bool:
    """Equality that also compares fields excluded from ``==`` (spans, comments)."""
    import dataclasses

    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        return type(a) is type(b) and all(
            f.name == "path" or _same_everywhere(getattr(a, f.name), getattr(b, f.name))
            for f in dataclasses.fields(a)
        )
    if isinstance(a, tuple):
        return (
            isinstance(b, tuple)
            and len(a) == len(b)
            and all(_same_everywhere(x, y) for x, y in zip(a, b, strict=True))
        )
    if isinstance(a, float) and isinstance(b, float) and a != a:
        return b != b
    return type(a) is type(b) and a == b


def test_schema_is_a_valid_schema() -> None:
    jsonschema.Draft202012Validator.check_schema(names.schema())


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(documents)
def test_any_model_round_trips_and_validates(document: Document) -> None:
    text = writer.dumps(document)
    data = json.loads(text)
    VALIDATOR.validate(data)
    back = reader.read(text).document
    assert back == document
    assert _same_everywhere(back, document)


def test_layout_is_the_documented_one() -> None:
    data = writer.to_dict(Document((FunctionBlock("fb"),)))
    assert data == {
        "format": "fuzzyctl-model",
        "version": 1,
        "blocks": [
            {"name": "fb", "variables": [], "fuzzify": [], "defuzzify": [], "rule_blocks": [], "options": []}
        ],
    }


def test_errors_name_the_json_path() -> None:
    bad = {
        "format": "fuzzyctl-model",
        "version": 1,
        "blocks": [{"name": "x", "variables": [{"name": "v", "kind": "IN"}]}],
    }
    with pytest.raises(DiagnosticError, match=r"\$\.blocks\[0\]\.variables\[0\]\.kind"):
        reader.read(json.dumps(bad))
    with pytest.raises(DiagnosticError) as err:
        reader.read('{"format": "fuzzyctl-model",\n "version": }')
    assert err.value.diagnostics[0].span is not None and err.value.diagnostics[0].span.line == 2
    with pytest.raises(DiagnosticError, match="version"):
        reader.read('{"format": "fuzzyctl-model", "version": 99, "blocks": []}')
