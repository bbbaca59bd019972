"""The ``fuzzyctl`` console script: the quick path of ``fuzzyctl eval`` first (no command
framework imported), then the full command line (:func:`fuzzyctl.cli.app.main`)."""

from __future__ import annotations

import sys


def run() -> None:
    from fuzzyctl.cli.quick import try_quick

    code = try_quick(sys.argv[1:])
    if code is None:
        from fuzzyctl.cli.app import main

        code = main()
    # The process ends here: freezing what it built keeps the interpreter's shutdown from
    # walking it with the garbage collector again (1.4 s after reading a 2 MB rule base).
    import gc

    gc.freeze()
    sys.exit(code)
