"""The Modelica Association's Reference FMUs (``../shared/tools/reference-fmus-src.tar.gz``,
BSD-2-Clause) built once with CMake into the test cache, keyed by the tarball's digest: FMUs
nobody on this project wrote, for the FMU plant tests.  Only ``StateSpace`` (FMI 3) is built
(about 2 s)."""

from __future__ import annotations

import hashlib
import shutil
import subprocess
import tarfile
from pathlib import Path

from tests.diskcache import cached_dir
from tests.extras import extra_path

TARBALL = extra_path("reference_fmus", "tools", "reference-fmus-src.tar.gz")


def _run(cmd: list[str], cwd: Path) -> None:
    proc = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=600, check=False)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}")


def build(model: str = "StateSpace") -> Path:
    """The path of ``model``.fmu (FMI 3), built on the first call."""
    digest = hashlib.sha256(TARBALL.read_bytes()).hexdigest()

    def _build(where: Path) -> None:
        with tarfile.open(TARBALL) as tf:
            tf.extractall(where / "src", filter="data")
        src = where / "src" / "Reference-FMUs"
        _run(
            [
                "cmake",
                "-S",
                str(src),
                "-B",
                str(where / "b"),
                "-DFMI_VERSION=3",
                "-DCMAKE_BUILD_TYPE=Release",
            ],
            where,
        )
        _run(["cmake", "--build", str(where / "b"), "--target", model], where)
        shutil.copy(where / "b" / "fmus" / f"{model}.fmu", where / f"{model}.fmu")
        shutil.rmtree(where / "src")
        shutil.rmtree(where / "b")

    return cached_dir("reference-fmus", (digest, model), _build) / f"{model}.fmu"
