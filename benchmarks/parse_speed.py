"""Parse time of the largest corpus FCL file (290 KB); prints seconds, no assertion."""

from __future__ import annotations

import sys
import time
from pathlib import Path

from fuzzyctl.fcl.parser import parse_source
from fuzzyctl.fcl.source import read_source

ROOT = Path(__file__).resolve().parent.parent
FILE = (
    ROOT.parent
    / "shared"
    / "corpus"
    / "fcl"
    / "khalidwalit__HIRS__WebContent__WEB-INF__Fuzzy__FuzzySmoke.fcl"
)


def main() -> int:
    source = read_source(sys.argv[1] if len(sys.argv) > 1 else FILE)
    parse_source(source)  # builds the parser tables once
    times = []
    for _ in range(5):
        start = time.perf_counter()
        parse_source(source)
        times.append(time.perf_counter() - start)
    print(f"{len(source.text) / 1024:.0f} KB: best {min(times):.3f} s, median {sorted(times)[2]:.3f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
