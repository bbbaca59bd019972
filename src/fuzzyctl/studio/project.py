"""Projects on disk: the project directory the studio may touch, FCL files saved
atomically, and the reading of the studio settings older versions kept in an OPTIONS block
of the FCL file (new settings live in a sidecar: studio/viewsettings.py).

Every path the browser sends is relative to the project directory and is refused when it
leaves it (``..``, an absolute path, a symbolic link pointing outside, a NUL byte).
"""

from __future__ import annotations

import errno
import hashlib
import json
import os
import re
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.files import write_atomic
from fuzzyctl.model import Document

STUDIO_KEYWORD = "STUDIO"
"""An OPTIONS block whose text is ``STUDIO {json}`` held the studio's view settings in files
saved by older versions; they are read (``split_settings``) and moved to the sidecar on Save."""

_STUDIO_LINE = re.compile(r"^\s*STUDIO\s+(\{.*\})\s*;?\s*$", re.DOTALL)
NAME_MAX = 255
"""Bytes of one file or directory name, at most (Linux, macOS and Windows file systems)."""
MAX_FILE = 16 * 1024 * 1024
"""The largest file the studio opens (the request-body limit: the model travels back)."""
PROJECT_EXTENSIONS = (".fcl",)
LOOP_EXTENSIONS = (".toml",)
"""Loop configurations (``fuzzyctl simulate``), listed beside the formats of the registry."""
MAX_LISTED = 2000


class PathError(FuzzyctlError):
    """A path outside the project directory, or not usable as a project file."""


class FileProblem(FuzzyctlError):
    """A file the studio cannot read or write, for a reason the user can act on: answered
    with ``status`` and the message (never a traceback)."""

    def __init__(self, status: int, message: str) -> None:
        self.status = status
        super().__init__(message)


# errno -> (HTTP status, what the user is told); the rest is a 500 with the system's reason.
_OS_PROBLEMS: dict[int, tuple[int, str]] = {
    errno.ENOSPC: (507, "the disk is full"),
    errno.EDQUOT: (507, "the disk quota is exhausted"),
    errno.EFBIG: (413, "the file is too big for the file system"),
    errno.EACCES: (403, "permission denied"),
    errno.EPERM: (403, "permission denied"),
    errno.EROFS: (403, "the file system is read-only"),
    errno.ENAMETOOLONG: (400, f"a name is too long (at most {NAME_MAX} bytes)"),
    errno.ENOTDIR: (400, "a part of the path is a file, not a directory"),
    errno.EEXIST: (400, "a part of the path is a file, not a directory"),
    errno.EISDIR: (400, "it is a directory"),
    errno.ENOENT: (404, "no such file or directory"),
}


def os_problem(exc: OSError, relative: str, doing: str) -> FileProblem:
    """What an OSError while ``doing`` (``"save"``, ``"open"``) ``relative`` tells the user;
    the file on disk is unchanged (the writes are atomic: fuzzyctl.files)."""
    status, reason = _OS_PROBLEMS.get(exc.errno or 0, (500, exc.strerror or type(exc).__name__))
    unchanged = "; the file on disk is unchanged" if doing == "save" else ""
    return FileProblem(status, f"cannot {doing} {relative!r}: {reason}{unchanged}")


def check_save_name(relative: str) -> None:
    """Refuse, before touching the disk, a name the file system would refuse (over
    ``NAME_MAX`` bytes) and a path into a hidden directory or to a hidden file (``.git/``,
    ``.venv/``, any name starting with '.': never the project's, and Save must not write there)."""
    for part in re.split(r"[/\\]", relative):
        if len(os.fsencode(part)) > NAME_MAX:
            raise FileProblem(
                400, f"the name {part[:40]!r}... is too long: at most {NAME_MAX} bytes per name"
            )
        if part.startswith(".") and part not in (".", ""):
            raise PathError(f"{relative!r}: the studio does not write into hidden files or directories")


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
        from fuzzyctl import formats

        listed = (*formats.extensions(), *LOOP_EXTENSIONS)
        out: list[dict[str, Any]] = []
        for dirpath, dirnames, filenames in os.walk(self.root):
            dirnames[:] = sorted(d for d in dirnames if not d.startswith(".") and d != "__pycache__")
            for name in sorted(filenames):
                if name.startswith(".") or not name.lower().endswith(listed):
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
