"""The studio's import dialog offers what the server's format registry reads (issue 27, A3):
the file input's accept list and the button's title come from ``/api/info``, not from a
list in the page."""

from __future__ import annotations

from typing import Any

from fuzzyctl import formats


def test_import_dialog_offers_the_registry(page: Any) -> None:
    readable = [f for f in formats.available() if f.read is not None]
    accept = page.get_attribute("#import-file", "accept")
    assert accept is not None and accept.split(",") == [e for f in readable for e in f.extensions]
    title = page.get_attribute("#btn-import", "title")
    assert title == "Import " + ", ".join(f.name.upper() for f in readable)
    assert {".fcl", ".fis", ".fll", ".fpl", ".xfuz", ".json"} <= set(accept.split(","))
