"""``fuzzyctl convert`` from the command line between every pair of registered formats, on
the IEC figure 7 example (FCL, singletons, WITH) and a MATLAB Sugeno FIS (tippersg).

First hop, source -> every format: without ``--lossy`` the command either writes the file
(nothing lost) or fails with exit 1, naming exactly what the target's ``lower`` reports and
leaving no file; with ``--lossy`` it writes and prints one ``dropped:`` line per loss.  A
lossless result read back evaluates like the source on 200 random inputs (1e-9).  Second hop,
each written file -> every format with ``--lossy``: a file or a diagnostic (exit 1), never an
internal error (exit 3).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl import formats
from fuzzyctl.cli.app import main
from tests.conftest import EXAMPLES, data_path

SOURCES = {
    "figure7.fcl": EXAMPLES / "figure7.fcl",
    "tippersg.fis": data_path("fuzzylite", "original", "takagi-sugeno", "matlab", "tippersg.fis"),
}
WRITABLE = [f.name for f in formats.available() if f.write is not None]


def test_every_format_of_the_issue_is_registered() -> None:
    assert {"fcl", "fis", "fll", "json", "fpl", "xfuz"} <= set(WRITABLE)


def _same_evaluation(a: fuzzyctl.model.Document, b: fuzzyctl.model.Document) -> None:
    ca, cb = fuzzyctl.compile(a), fuzzyctl.compile(b)
    rng = np.random.default_rng(3)
    data = {name: rng.uniform(-5.0, 105.0, 200) for name in ca.inputs}
    ra, rb = ca.evaluate_batch(data), cb.evaluate_batch(data)
    assert set(ra) == set(rb)
    for name, values in ra.items():
        assert np.allclose(values, rb[name], rtol=0.0, atol=1e-9, equal_nan=True), name


@pytest.mark.parametrize("target", WRITABLE)
@pytest.mark.parametrize("source", sorted(SOURCES))
def test_convert_each_pair(
    source: str, target: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src = SOURCES[source]
    document = formats.read_path(src).document
    losses = formats.get(target).losses(document)
    out = tmp_path / f"out.{target}"
    code = main(["convert", str(src), str(out)])
    err = capsys.readouterr().err
    if losses:
        assert code == 1 and not out.exists()
        assert f"cannot express {len(losses)} element(s)" in err
        assert all(str(loss) in err for loss in losses)
        assert main(["convert", str(src), str(out), "--lossy"]) == 0
        err = capsys.readouterr().err
        assert err.count("dropped: ") == len(losses)
        assert all(f"dropped: {loss}" in err for loss in losses)
    else:
        assert code == 0 and "dropped" not in err
    assert out.exists()
    if formats.get(target).read is None:
        return
    again = formats.read_path(out).document
    if not losses:
        _same_evaluation(document, again)
    for second in WRITABLE:  # second hop
        code = main(["convert", str(out), str(tmp_path / f"again.{second}"), "--lossy"])
        err = capsys.readouterr().err
        assert code in (0, 1), f"{target} -> {second}: exit {code}\n{err}"
        assert code == 0 or "error" in err
