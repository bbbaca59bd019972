"""The front door's parsing of Host headers and bearer tokens (its behaviour on real
servers is tested in tests/runtime/test_api_process.py and tests/studio/test_security.py)."""

from __future__ import annotations

from fuzzyctl.webguard import bearer_token, host_name, token_matches


def test_host_names_lose_the_port_and_the_brackets() -> None:
    assert host_name("127.0.0.1:8765") == "127.0.0.1"
    assert host_name("[::1]:8765") == "::1"
    assert host_name("[::1]") == "::1"
    assert host_name("Plant.Local") == "plant.local"
    assert host_name("attacker.example:80") == "attacker.example"
    assert host_name("") == ""


def test_bearer_tokens() -> None:
    assert bearer_token({"authorization": "Bearer abc"}) == "abc"
    assert bearer_token({"authorization": "bearer  abc "}) == "abc"
    assert bearer_token({"authorization": "Basic abc"}) is None
    assert bearer_token({"authorization": "Bearer "}) is None
    assert bearer_token({}) is None
    assert token_matches("abc", "abc") and not token_matches("abd", "abc")
    assert not token_matches(None, "abc") and not token_matches("", "") and not token_matches("abc", None)
