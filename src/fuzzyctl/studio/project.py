"""Projects on disk: the project directory the studio may touch, FCL files saved
atomically, and the studio's own settings kept in an OPTIONS block of the FCL file.

Every path the browser sends is relative to the project directory and is refused when it
leaves it (``..``, an absolute path, a symbolic link pointing outside, a NUL byte).
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.files import write_atomic
from fuzzyctl.model import Document, FunctionBlock, OptionsBlock

STUDIO_KEYWORD = "STUDIO"
"""An OPTIONS block whose text is ``STUDIO {json}`` holds the studio's view settings
(curve selection, test signals, display ranges, 3D axes); the knowledge base never sees it."""

_STUDIO_LINE = re.compile(r"^\s*STUDIO\s+(\{.*\})\s*;?\s*$", re.DOTALL)
PROJECT_EXTENSIONS = (".fcl",)
LISTED_EXTENSIONS = (".fcl", ".fis", ".fll", ".json", ".fpl", ".xfuz", ".toml")
MAX_LISTED = 2000


class PathError(FuzzyctlError):
    """A path outside the project directory, or not usable as a project file."""


@dataclass(frozen=True)
class ProjectDir:
    """The directory the studio serves; every file access goes through :meth:`resolve`."""

    root: Path

    @classmethod
    def at(cls, root: str | os.PathLike[str]) -> ProjectDir:
        path = Path(root).resolve()
        if not path.is_dir():
            raise PathError(f"{root}: not a directory")
        return cls(path)

    def resolve(self, relative: str, *, must_exist: bool = False) -> Path:
        """The absolute path of ``relative`` inside the project directory."""
        if not relative or "\x00" in relative:
            raise PathError("empty or invalid path")
        candidate = Path(relative)
        if candidate.is_absolute() or relative.startswith(("/", "\\")) or re.match(r"^[A-Za-z]:", relative):
            raise PathError(f"{relative!r}: give a path relative to the project directory")
        if any(part == ".." for part in candidate.parts):
            raise PathError(f"{relative!r}: '..' leaves the project directory")
        full = (self.root / candidate).resolve()
        if full != self.root and self.root not in full.parents:
            raise PathError(f"{relative!r} is outside the project directory")
        if must_exist and not full.is_file():
            raise PathError(f"{relative!r}: no such file in the project directory")
        return full

    def relative(self, path: Path) -> str:
        return path.resolve().relative_to(self.root).as_posix()

    def listing(self) -> list[dict[str, Any]]:
        """Files the studio can open (FCL, the other formats, loop configurations), sorted,
        hidden files and directories left out."""
        out: list[dict[str, Any]] = []
        for dirpath, dirnames, filenames in os.walk(self.root):
            dirnames[:] = sorted(d for d in dirnames if not d.startswith(".") and d != "__pycache__")
            for name in sorted(filenames):
                if name.startswith(".") or not name.lower().endswith(LISTED_EXTENSIONS):
                    continue
                full = Path(dirpath) / name
                if not full.resolve().is_relative_to(self.root):
                    continue  # a symbolic link that points outside
                out.append({"path": self.relative(full), "size": full.stat().st_size})
                if len(out) >= MAX_LISTED:
                    return out
        return out


def sha256(text: str) -> str:
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def save_atomically(path: Path, text: str) -> None:
    """Write ``text`` so that ``path`` holds the old or the new content after a crash, never a
    part (fsync of the file and of the directory: fuzzyctl.files)."""
    write_atomic(path, text, durable=True)


# ---------------------------------------------------------------------------- settings


def split_settings(document: Document) -> tuple[Document, dict[str, Any]]:
    """The document without the studio's OPTIONS block, and the settings it held (those
    of the first function block; other blocks keep theirs verbatim)."""
    settings: dict[str, Any] = {}
    blocks = []
    for index, fb in enumerate(document.blocks):
        kept = []
        for opt in fb.options:
            match = _STUDIO_LINE.match(opt.text)
            if match is None:
                kept.append(opt)
                continue
            if index == 0:
                try:
                    value = json.loads(match.group(1))
                except json.JSONDecodeError:
                    value = None
                if isinstance(value, dict):
                    settings = value
        blocks.append(replace(fb, options=tuple(kept)))
    return replace(document, blocks=tuple(blocks)), settings


def with_settings(document: Document, settings: dict[str, Any] | None) -> Document:
    """The document with ``settings`` in an OPTIONS block of its first function block
    (replacing an older one); no block when there are no settings."""
    bare, _old = split_settings(document)
    if not settings:
        return bare
    encoded = json.dumps(settings, separators=(",", ":"), sort_keys=True, ensure_ascii=True)
    if re.search(r"END_OPTIONS?|\(\*|\*\)", encoded, re.IGNORECASE):
        raise FuzzyctlError("studio settings may not contain END_OPTIONS or comment brackets")
    text = f"\n        {STUDIO_KEYWORD} {encoded};\n    "
    first: FunctionBlock = bare.blocks[0]
    first = replace(first, options=(*first.options, OptionsBlock(text)))
    return replace(bare, blocks=(first, *bare.blocks[1:]))
