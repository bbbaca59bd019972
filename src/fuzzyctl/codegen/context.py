"""The program-building state moved to :mod:`fuzzyctl.engine.irgen`."""

from fuzzyctl.engine.irgen import (
    MAX_IDENT as MAX_IDENT,
)
from fuzzyctl.engine.irgen import (
    PREFIX as PREFIX,
)
from fuzzyctl.engine.irgen import (
    CodegenError as CodegenError,
)
from fuzzyctl.engine.irgen import (
    Gen as Gen,
)
from fuzzyctl.engine.irgen import (
    Target as Target,
)
from fuzzyctl.engine.irgen import (
    flat as flat,
)
