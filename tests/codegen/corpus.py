"""The corpus files the code-generation corpus tests read, and the C compile check they share."""

from __future__ import annotations

import shutil
import subprocess
import warnings
from collections.abc import Sequence
from pathlib import Path

import fuzzyctl
from fuzzyctl.diagnostics import FuzzyctlError
from tests.extras import extra_files

#: Every corpus file in a format that code generation reads (FCL, FIS, FLL).
FILES = [
    p for p in extra_files("corpus", "corpus", recursive=True) if p.suffix.lower() in (".fcl", ".fis", ".fll")
]


def load(path: Path) -> fuzzyctl.model.Document | None:
    """The corpus file ``path`` loaded without its warnings, or None where it does not load."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return fuzzyctl.load(path)
    except (FuzzyctlError, UnicodeDecodeError):
        return None


def compile_sample(samples: list[dict[str, str]], where: Path, flags: Sequence[str]) -> None:
    """Write each sample's files (name -> text) to its own folder below ``where`` and run the
    system compiler ``cc`` with ``flags`` on every ``.c`` among them: each must pass."""
    cc = shutil.which("cc")
    assert cc, "the corpus tests check a sample of the C with the system compiler 'cc'"
    assert samples
    for i, files in enumerate(samples):
        d = where / f"s{i}"
        d.mkdir()
        for name, text in files.items():
            (d / name).write_text(text)
        for name in files:
            if name.endswith(".c"):
                res = subprocess.run([cc, *flags, str(d / name)], capture_output=True, text=True)
                assert res.returncode == 0, res.stderr[:2000]
