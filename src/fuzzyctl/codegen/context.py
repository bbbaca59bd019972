"""The program-building state moved to :mod:`fuzzyctl.engine.irgen`."""

from fuzzyctl.engine.irgen import (  # noqa: F401
    Target as Target,
    PREFIX as PREFIX,
    MAX_IDENT as MAX_IDENT,
    CodegenError as CodegenError,
    Gen as Gen,
    flat as flat,
)
