"""Execution time and memory of the example programs for the conformance statement (IEC
61131-7 Table 11, docs/conformance.md): ``python benchmarks/conformance.py`` prints the
statement with the examples measured on this machine, ``--write`` puts it in
docs/conformance.md.  The rest of that file is generated from the code and compared by
tests/test_statement.py; only the measured section comes from here.  Run it on a quiet
machine: the times are the best of several runs, but a loaded machine still shows."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from fuzzyctl import statement

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = sorted((ROOT / "examples").glob("*.fcl"))
TARGET = ROOT / "docs" / "conformance.md"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--write", action="store_true", help=f"write {TARGET.relative_to(ROOT)}")
    args = parser.parse_args()
    text = statement.statement(EXAMPLES)
    if args.write:
        TARGET.write_text(text, encoding="utf-8")
        print(f"wrote {TARGET}", file=sys.stderr)
    else:
        sys.stdout.write(text)


if __name__ == "__main__":
    main()
