"""Imports every command module so that each registers its commands on the app."""

from fuzzyctl.cli import (
    analyze,  # noqa: F401  (analyze: static checks of a rule base)
    blocks,  # noqa: F401  (fuzzyctl blocks ...)
    codegen,  # noqa: F401  (fuzzyctl codegen)
    convert,  # noqa: F401
    lang,  # noqa: F401  (check, fmt)
    run,  # noqa: F401  (eval, explain)
    serve,  # noqa: F401  (serve: the soft controller)
    simulate,  # noqa: F401  (simulate)
    studio,  # noqa: F401  (studio: the browser configuration tool)
    tune,  # noqa: F401  (learn, tune: design from data and from the plant)
)
