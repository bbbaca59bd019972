"""The studio's view settings (curve selection, test signals, display ranges, 3D axes)
kept beside the user's file, never in it.

Saving them in the FCL file made a Basic-level file an Open-level one (an OPTIONS block)
and `fuzzyctl convert X.fcl X.fll` refused it.  They now live in a sidecar file under the
project directory, ``.fuzzyctl-studio/<the file's path>.json``: hidden (the file list and
Save never show or write it), kept with the project when the directory is copied or
committed, and read whichever browser opens the project (browser storage would lose them
on another machine or browser).  A file that still holds an ``OPTIONS STUDIO {...}`` block
opens with those settings; the next Save moves them to the sidecar and leaves the block out.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from fuzzyctl.files import write_atomic

SIDECAR_DIR = ".fuzzyctl-studio"
"""The directory, in the project directory, that holds the view settings of its files."""
MAX_SIDECAR = 1024 * 1024
"""A sidecar larger than this is ignored (the settings are a few kilobytes)."""


def sidecar(root: Path, relative: str) -> Path:
    """Where the view settings of the project file ``relative`` are kept."""
    return root / SIDECAR_DIR / f"{relative}.json"


def read_settings(root: Path, relative: str) -> dict[str, Any]:
    """The view settings kept for ``relative``; ``{}`` when there are none or the sidecar
    does not read (a broken sidecar never keeps a file from opening)."""
    path = sidecar(root, relative)
    try:
        if not path.is_file() or path.stat().st_size > MAX_SIDECAR:
            return {}
        value = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return value if isinstance(value, dict) else {}


def merged(root: Path, relative: str, in_file: dict[str, Any]) -> dict[str, Any]:
    """The settings a file opens with: the sidecar's, else those of an OPTIONS STUDIO block
    in the file (written by earlier versions)."""
    return read_settings(root, relative) or in_file


def write_settings(root: Path, relative: str, settings: dict[str, Any]) -> None:
    """Keep ``settings`` for ``relative`` (atomically); no settings: the sidecar is removed.
    A sidecar that cannot be written does not fail the Save of the user's file."""
    path = sidecar(root, relative)
    settings = pruned(settings)
    try:
        if not settings:
            path.unlink(missing_ok=True)
            return
        path.parent.mkdir(parents=True, exist_ok=True)
        text = json.dumps(settings, indent=1, sort_keys=True, ensure_ascii=False) + "\n"
        write_atomic(path, text)
    except OSError:
        pass


def pruned(settings: dict[str, Any]) -> dict[str, Any]:
    """``settings`` without empty values (``{}``, ``[]``, None): a view never touched keeps
    no sidecar."""
    out: dict[str, Any] = {}
    for key, value in settings.items():
        if isinstance(value, dict):
            value = pruned(value)
        if value is None or value == {} or value == []:
            continue
        out[key] = value
    return out
