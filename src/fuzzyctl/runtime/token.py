"""The API token: generated at the first start, stored with mode 0600, required for every
request that changes anything."""

from __future__ import annotations

import os
import secrets
import stat
from pathlib import Path

from fuzzyctl.diagnostics import FuzzyctlError

__all__ = ["load_or_create_token"]


def load_or_create_token(path: Path) -> str:
    """The token stored at ``path``; a new random one (256 bits) when the file does not
    exist.  A token file that others can read is refused: the token would not be secret."""
    try:
        st = path.stat()
    except FileNotFoundError:
        path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
        token = secrets.token_urlsafe(32)
        # O_EXCL + mode 0600 from the start: the token is never readable by others, not even briefly.
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "w", encoding="ascii") as f:
            f.write(token + "\n")
        return token
    if st.st_mode & (stat.S_IRWXG | stat.S_IRWXO):
        raise FuzzyctlError(
            f"{path}: the API token file is accessible to other users (mode {stat.S_IMODE(st.st_mode):o}); "
            f"run 'chmod 600 {path}' or delete it to get a new token"
        )
    token = path.read_text(encoding="ascii").strip()
    if len(token) < 16:
        raise FuzzyctlError(f"{path}: the API token file holds no usable token; delete it to get a new one")
    return token
