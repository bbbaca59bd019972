"""Reading FCL source: bytes to text (UTF-8 with or without BOM, Latin-1 fallback), and
friendly errors for things that are not FCL text at all."""

from __future__ import annotations

import os
from dataclasses import dataclass

from fuzzyctl.diagnostics import DiagnosticError, error


@dataclass(frozen=True)
class Source:
    """Decoded source text and where it came from."""

    text: str
    path: str | None = None
    encoding: str = "utf-8"

    def line(self, number: int) -> str:
        from fuzzyctl.diagnostics import source_line

        return source_line(self.text, number) or ""


def decode(data: bytes, path: str | None = None) -> Source:
    """Decode FCL bytes: a UTF-8 BOM is dropped, invalid UTF-8 is read as Latin-1 (old
    European files), and binary data (NUL bytes) is refused."""
    if b"\x00" in data[:65536]:
        raise DiagnosticError([error("not a text file (it contains binary data)", file=path, code="binary")])
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    try:
        return Source(data.decode("utf-8"), path, "utf-8")
    except UnicodeDecodeError:
        return Source(data.decode("latin-1"), path, "latin-1")


def read_source(path: str | os.PathLike[str]) -> Source:
    """Read and decode a file; a missing file, a directory or a file over the size limit
    (:func:`fuzzyctl.limits.max_input_bytes`) is a diagnostic, not a crash."""
    from fuzzyctl.limits import read_input

    return decode(read_input(path, "fcl"), str(path))
