"""The IR moved to :mod:`fuzzyctl.engine.ir` (the engine renders it to Python and numpy too)."""

from fuzzyctl.engine.ir import (
    Assign as Assign,
)
from fuzzyctl.engine.ir import (
    Bin as Bin,
)
from fuzzyctl.engine.ir import (
    Bool as Bool,
)
from fuzzyctl.engine.ir import (
    Builder as Builder,
)
from fuzzyctl.engine.ir import (
    Call as Call,
)
from fuzzyctl.engine.ir import (
    Comment as Comment,
)
from fuzzyctl.engine.ir import (
    Decl as Decl,
)
from fuzzyctl.engine.ir import (
    Ex as Ex,
)
from fuzzyctl.engine.ir import (
    ExLike as ExLike,
)
from fuzzyctl.engine.ir import (
    For as For,
)
from fuzzyctl.engine.ir import (
    If as If,
)
from fuzzyctl.engine.ir import (
    Index as Index,
)
from fuzzyctl.engine.ir import (
    Int as Int,
)
from fuzzyctl.engine.ir import (
    Neg as Neg,
)
from fuzzyctl.engine.ir import (
    Not as Not,
)
from fuzzyctl.engine.ir import (
    Num as Num,
)
from fuzzyctl.engine.ir import (
    Program as Program,
)
from fuzzyctl.engine.ir import (
    Region as Region,
)
from fuzzyctl.engine.ir import (
    Stmt as Stmt,
)
from fuzzyctl.engine.ir import (
    Storage as Storage,
)
from fuzzyctl.engine.ir import (
    Type as Type,
)
from fuzzyctl.engine.ir import (
    Var as Var,
)
from fuzzyctl.engine.ir import (
    While as While,
)
from fuzzyctl.engine.ir import (
    _arith as _arith,
)
from fuzzyctl.engine.ir import (
    call as call,
)
from fuzzyctl.engine.ir import (
    ex as ex,
)
from fuzzyctl.engine.ir import (
    not_ as not_,
)
from fuzzyctl.engine.ir import (
    subexprs as subexprs,
)
from fuzzyctl.engine.ir import (
    walk_exprs as walk_exprs,
)
