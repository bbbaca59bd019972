"""Other fuzzy libraries, run in their own venv and driven over a pipe.

pyfuzzylite, scikit-fuzzy and simpful pin numpy < 2; the project's venv has numpy 2 (what
users get), so they live in ``.venv-peers`` (``make test`` creates it from
tests/peers/requirements.txt; ``FUZZYCTL_PEERS_PYTHON`` names another interpreter).  One
long-lived peer process per test process answers :func:`run` calls (tests/peers/server.py).
A missing peer venv is a failure, never a skip."""

from __future__ import annotations

import atexit
import json
import os
import subprocess
import sys
import threading
from pathlib import Path
from typing import Any

import pytest

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
PYTHON = Path(os.environ.get("FUZZYCTL_PEERS_PYTHON", ROOT / ".venv-peers" / "bin" / "python"))

_lock = threading.Lock()
_process: subprocess.Popen[str] | None = None


def _start() -> subprocess.Popen[str]:
    if not PYTHON.exists():
        pytest.fail(f"peer venv missing: {PYTHON} (`make test` creates it; or `make .venv-peers/.installed`)")
    process = subprocess.Popen(
        [str(PYTHON), str(HERE / "server.py")],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=sys.stderr,
        text=True,
        bufsize=1,
    )
    atexit.register(process.kill)
    return process


def run(code: str, **variables: Any) -> Any:
    """Run ``code`` in the peer venv with ``variables`` bound (lists of numbers arrive as numpy
    arrays; ``np``, ``math``, ``fl`` = pyfuzzylite, ``fuzz`` = scikit-fuzzy are imported) and
    return what it left in ``result`` (numpy values as lists)."""
    global _process
    with _lock:
        if _process is None or _process.poll() is not None:
            _process = _start()
        assert _process.stdin is not None and _process.stdout is not None
        _process.stdin.write(json.dumps({"code": code, "vars": _plain(variables)}) + "\n")
        _process.stdin.flush()
        line = _process.stdout.readline()
    if not line:
        pytest.fail("the peer process ended without answering (see stderr)")
    answer = json.loads(line)
    if "error" in answer:
        pytest.fail(f"peer raised:\n{answer['error']}")
    return answer["result"]


def _plain(value: Any) -> Any:
    if hasattr(value, "tolist"):
        return value.tolist()
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    return value


def membership(expression: str, x: Any) -> Any:
    """``expression`` evaluated in the peer with ``x`` a numpy array (e.g.
    ``"fuzz.trimf(x, [1, 4, 7])"``), as a numpy array here."""
    import numpy as np

    return np.asarray(run(f"result = np.asarray({expression}, dtype=float)", x=x), dtype=float)


#: pyfuzzylite evaluating FLL text on rows of inputs, in order, on one engine (its state, such
#: as lock-previous, carries from row to row); the last value of each output.
PYFUZZYLITE_FLL = """
engine = fl.FllImporter().from_string(text)
result = []
for row in rows:
    for name, value in zip(names, row):
        engine.input_variable(name).value = float(value)
    engine.process()
    result.append([float(np.asarray(engine.output_variable(o).value).reshape(-1)[-1]) for o in outputs])
"""


def pyfuzzylite_fll(
    text: str, names: list[str], rows: list[list[float]], outputs: list[str]
) -> list[list[float]]:
    """Outputs per row (one list per row, in ``outputs`` order) of pyfuzzylite on FLL text."""
    return run(
        PYFUZZYLITE_FLL, text=text, names=names, rows=[list(map(float, r)) for r in rows], outputs=outputs
    )
