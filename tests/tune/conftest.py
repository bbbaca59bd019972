"""Shared set-ups of the tune tests: one Dask LocalCluster (2 workers on 127.0.0.1) for the
whole session, a small fuzzy-PI loop on the FOPDT plant, data sets made from closed forms."""

from __future__ import annotations

import textwrap
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

FUZZY_PI = textwrap.dedent(
    """\
    (* A fuzzy PI for a first-order lag: error and its rate in, a rate of the drive out. *)
    FUNCTION_BLOCK fpi
        VAR_INPUT
            e : REAL;   (* setpoint - measurement *)
            de : REAL;  (* its rate *)
        END_VAR
        VAR_OUTPUT
            du : REAL;
        END_VAR
        FUZZIFY e
            TERM neg := (-1, 1) (0, 0);
            TERM zero := (-1, 0) (0, 1) (1, 0);
            TERM pos := (0, 0) (1, 1);
        END_FUZZIFY
        FUZZIFY de
            TERM neg := (-1, 1) (0, 0);
            TERM zero := (-1, 0) (0, 1) (1, 0);
            TERM pos := (0, 0) (1, 1);
        END_FUZZIFY
        DEFUZZIFY du
            RANGE(-1..1);
            TERM nb := -1;
            TERM ns := -0.4;
            TERM ze := 0;
            TERM ps := 0.4;
            TERM pb := 1;
            METHOD : CoGS;
            DEFAULT := 0;
        END_DEFUZZIFY
        RULEBLOCK pi
            AND : MIN;
            ACCU : MAX;
            RULE 1 : IF e IS neg AND de IS neg THEN du IS nb;
            RULE 2 : IF e IS neg AND de IS zero THEN du IS ns;
            RULE 3 : IF e IS neg AND de IS pos THEN du IS ze;
            RULE 4 : IF e IS zero AND de IS neg THEN du IS ns;
            RULE 5 : IF e IS zero AND de IS zero THEN du IS ze;
            RULE 6 : IF e IS zero AND de IS pos THEN du IS ps;
            RULE 7 : IF e IS pos AND de IS neg THEN du IS ze;
            RULE 8 : IF e IS pos AND de IS zero THEN du IS ps;
            RULE 9 : IF e IS pos AND de IS pos THEN du IS pb;
        END_RULEBLOCK
    END_FUNCTION_BLOCK
    """
)

LOOP = textwrap.dedent(
    """\
    title = "fuzzy PI on a lag"
    duration = 30
    [plant]
    model = "fopdt"
    gain = 1
    time_constant = 5
    dead_time = 0.5
    [controller]
    structure = "fuzzy_pi"
    file = "fpi.fcl"
    cycle = 0.25
    output = "du"
    drive = "u"
    gain = 0.5
    low = -5
    high = 5
    inputs = { e = "w - y", de = "ddt(e)" }
    [setpoints]
    w = 1
    [quality]
    signal = "y"
    setpoint = "w"
    band = 0.05
    [tune]
    cost = { iae = 1, "max:u" = 0.1 }
    [[tune.scenarios]]
    name = "step to 1"
    [[tune.scenarios]]
    name = "step to 0.5"
    setpoints = { w = 0.5 }
    duration = 20
    """
)


@pytest.fixture
def loop(tmp_path: Path) -> tuple[Path, Path]:
    """(fpi.fcl, loop.toml) in a temporary directory."""
    fcl = tmp_path / "fpi.fcl"
    fcl.write_text(FUZZY_PI, encoding="utf-8")
    toml = tmp_path / "loop.toml"
    toml.write_text(LOOP, encoding="utf-8")
    return fcl, toml


def surface(n: int, seed: int) -> dict[str, np.ndarray]:
    """A smooth two-input function on [-3, 3]^2: z = sin(x) cos(y) + x / 5."""
    rng = np.random.default_rng(seed)
    x = rng.uniform(-3.0, 3.0, n)
    y = rng.uniform(-3.0, 3.0, n)
    return {"x": x, "y": y, "z": np.sin(x) * np.cos(y) + x / 5.0}


@pytest.fixture(scope="session")
def dask_client() -> Iterator[Any]:
    """One LocalCluster for the session: 2 single-threaded worker processes on 127.0.0.1."""
    from fuzzyctl.tune.parallel import local_cluster

    client, cluster = local_cluster(2)
    try:
        yield client
    finally:
        client.close()
        cluster.close()
