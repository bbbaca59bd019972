"""The IR formulas moved to :mod:`fuzzyctl.engine.irterms`."""

from fuzzyctl.engine.irterms import (
    _BINOPS as _BINOPS,
)
from fuzzyctl.engine.irterms import (
    _C_FUNCS as _C_FUNCS,
)
from fuzzyctl.engine.irterms import (
    _CMPOPS as _CMPOPS,
)
from fuzzyctl.engine.irterms import (
    _COMPARE as _COMPARE,
)
from fuzzyctl.engine.irterms import (
    _HELPERS as _HELPERS,
)
from fuzzyctl.engine.irterms import (
    _PI as _PI,
)
from fuzzyctl.engine.irterms import (
    P as P,
)
from fuzzyctl.engine.irterms import (
    _absv as _absv,
)
from fuzzyctl.engine.irterms import (
    _interp as _interp,
)
from fuzzyctl.engine.irterms import (
    _simple as _simple,
)
from fuzzyctl.engine.irterms import (
    _tr as _tr,
)
from fuzzyctl.engine.irterms import (
    accumulate as accumulate,
)
from fuzzyctl.engine.irterms import (
    accumulate_into as accumulate_into,
)
from fuzzyctl.engine.irterms import (
    expression as expression,
)
from fuzzyctl.engine.irterms import (
    hedge as hedge,
)
from fuzzyctl.engine.irterms import (
    hedged as hedged,
)
from fuzzyctl.engine.irterms import (
    left_limit as left_limit,
)
from fuzzyctl.engine.irterms import (
    mul as mul,
)
from fuzzyctl.engine.irterms import (
    pwl_value as pwl_value,
)
from fuzzyctl.engine.irterms import (
    right_limit as right_limit,
)
from fuzzyctl.engine.irterms import (
    smooth as smooth,
)
from fuzzyctl.engine.irterms import (
    snorm as snorm,
)
from fuzzyctl.engine.irterms import (
    sort_points as sort_points,
)
from fuzzyctl.engine.irterms import (
    template as template,
)
from fuzzyctl.engine.irterms import (
    tnorm as tnorm,
)
