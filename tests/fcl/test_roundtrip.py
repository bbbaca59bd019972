"""write -> parse gives back the model, for random valid models."""

from __future__ import annotations

from hypothesis import HealthCheck, given, settings

from fuzzyctl.fcl import load_text, write
from fuzzyctl.model import Document
from tests.fcl.strategies import documents


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(documents)
def test_random_models_round_trip(doc: Document) -> None:
    text = write(doc)
    result = load_text(text)
    assert result.document == doc, text
