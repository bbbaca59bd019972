"""The public facade: ``load()`` a fuzzy system from any supported format and
``compile()`` it into something that evaluates.

Both cache their work on disk, keyed by content (:mod:`fuzzyctl.cache`): a file read before
is not parsed again (its document is unpickled), and a document compiled before is not
lowered again (its plan is unpickled); the native backend finds its library by the plan.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import pickle
from collections import OrderedDict
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from fuzzyctl.diagnostics import Diagnostic
    from fuzzyctl.engine.controller import Controller
    from fuzzyctl.engine.plan import Plan
    from fuzzyctl.engine.variables import VariableInfo
    from fuzzyctl.model import Document, FunctionBlock

#: Backends of :func:`compile` (``auto``: native when possible, else python).
BACKENDS = ("auto", "native", "python", "interpreted", "table")
#: Content keys of documents this process loaded (by identity; a few recent ones).
_KEYS: OrderedDict[int, tuple[Document, str]] = OrderedDict()


def load(
    path_or_text: str | Path, *, format: str | None = None, strict: bool = False, compat: str = "iec"
) -> Document:
    """Read a fuzzy system from a file path or from source text.

    ``format`` (``"fcl"``, ...) overrides detection by file extension; text that is not an
    existing path is parsed as FCL unless ``format`` says otherwise.  ``strict``: refuse, as
    a strict IEC 61131-7 tool would, FCL whose identifiers are reserved keywords (Table 7),
    and in every format a WITH (or rule) weight above 1 (5.2.4).  ``compat``: read FCL as
    that tool's profile does (``"jfuzzylogic"`` takes a term of one point, with a warning,
    as jFuzzyLogic runs it; IEC 61131-7 5.2.2 asks for two).
    Raises :class:`fuzzyctl.diagnostics.DiagnosticError` with file:line:column diagnostics
    when the input is not valid.

    ```python
    >>> import fuzzyctl
    >>> doc = fuzzyctl.load("examples/tank.fcl")
    >>> [fb.name for fb in doc.blocks]
    ['tank']
    >>> fuzzyctl.load("FUNCTION_BLOCK empty END_FUNCTION_BLOCK").blocks[0].name   # text, not a path
    'empty'

    ```
    """
    fmt = (format or "").lower() or None
    if isinstance(path_or_text, Path) or _looks_like_path(path_or_text):
        path = Path(path_or_text)
        require_file(path)  # before the extension is read: a typo in it is still a missing file
        fmt = fmt or (path.suffix.lower().lstrip(".") or "fcl")
        doc = _load_path(path, fmt, strict, compat)
        if strict and fmt != "fcl" and (found := _strict_findings(doc)):  # FCL's reader said it
            from fuzzyctl.diagnostics import DiagnosticError

            raise DiagnosticError(found)
        return doc
    from fuzzyctl import formats
    from fuzzyctl.diagnostics import DiagnosticError, error
    from fuzzyctl.fcl import load_text

    if fmt not in (None, "fcl"):
        doc = formats.read_text(str(path_or_text), fmt).document
        if strict and (found := _strict_findings(doc)):
            raise DiagnosticError(found)
        return doc
    text = str(path_or_text)
    if not text.strip():
        raise DiagnosticError([error("empty input: no FUNCTION_BLOCK", code="empty")])
    return load_text(text, strict=strict, compat=compat).raise_for_errors()


#: Files up to this size have their parsed document cached on disk.  Above it, pickling the
#: document costs about what reading it does (40 % of loading a 1 MB FPL file, 0.4 s of the
#: 10,000-rule FCL system's 1.0 s) and unpickling saves little: the plan and the native
#: library are still cached, keyed by the file's bytes.
DOCUMENT_CACHE_MAX_BYTES = 256 * 1024


def _load_path(path: Path, fmt: str, strict: bool = False, compat: str = "iec") -> Document:
    from fuzzyctl import cache
    from fuzzyctl.diagnostics import DiagnosticError

    key = None
    small = False  # a file whose document is cached
    if cache.enabled():
        from fuzzyctl.limits import read_input

        try:
            data: bytes | None = read_input(path, fmt)  # the size limit holds for cached files too
        except DiagnosticError:
            data = None  # the reader reports it with its place
        if data is not None:
            key = content_key(
                data, fmt + (":strict" if strict else "") + (f":{compat}" if compat != "iec" else "")
            )
            small = len(data) <= DOCUMENT_CACHE_MAX_BYTES
            doc = _cached(f"documents/{key}.pickle") if small else None
            from fuzzyctl.model import Document

            if isinstance(doc, Document):
                doc = Document(doc.blocks, str(path), doc.comments)
                _remember(doc, key)
                return doc
    if fmt == "fcl":
        from fuzzyctl.fcl import load_file

        doc = load_file(path, strict=strict, compat=compat).raise_for_errors()
    else:
        from fuzzyctl import formats

        doc = formats.read_path(path, fmt).document
    if key is not None:
        if small:
            _store(f"documents/{key}.pickle", doc)
        _remember(doc, key)  # the plan and library caches still find this document's work
    return doc


def content_key(data: bytes, fmt: str) -> str:
    """The cache key of a file's bytes read as ``fmt`` (with fuzzyctl's code fingerprint)."""
    from fuzzyctl import cache

    h = hashlib.sha256()
    h.update(cache.code_fingerprint().encode() + b"\0" + fmt.encode() + b"\0")
    h.update(data)
    return h.hexdigest()[:32]


def require_file(path: Path) -> None:
    """ "no such file" (or "is a directory") for a path that names no file."""
    from fuzzyctl.diagnostics import DiagnosticError, error

    try:
        exists = path.exists()
    except OSError as exc:  # a name too long for the file system, say
        raise DiagnosticError(
            [error(f"cannot read: {exc.strerror}", file=str(path), code="no-file")]
        ) from None
    if not exists:
        raise DiagnosticError([error("no such file", file=str(path), code="no-file")])
    if path.is_dir():
        raise DiagnosticError([error("is a directory, not a file", file=str(path), code="no-file")])


def _looks_like_path(value: str) -> bool:
    """Text holding a newline, ';' or ':=', starting with '{' or '[', or longer than any path
    is source; anything else is taken as a path (a missing file is then reported as such,
    not parsed as FCL)."""
    # line ends of any kind (the FLL reader takes U+2028, U+0085, ...) mean source text
    if (
        any(c in value for c in "\n\r\0;\v\f\x1c\x1d\x1e\x85\u2028\u2029")
        or ":=" in value
        or len(value) > 4096
    ):
        return False
    if value.lstrip()[:1] in ("{", "["):  # JSON, a FIS section
        return False
    try:
        return "FUNCTION_BLOCK" not in value.upper() or Path(value).exists()
    except OSError:  # not a name the file system takes: source text
        return False


def compile(
    model: Document | FunctionBlock | str | Path,
    *,
    block: str | None = None,
    backend: str | None = None,
    out_of_range: str = "warn",
    **options: Any,
) -> Controller:
    """Turn a model into a :class:`~fuzzyctl.engine.Controller` (see ``fuzzyctl.engine``).

    ``model`` is a loaded document or function block, or what :func:`load` takes (a path:
    ``compile("crane.fcl")`` is ``compile(load("crane.fcl"))``).  ``out_of_range`` is what
    an input outside its range (declared, else its terms' span) does by default: ``"warn"``
    (the result as computed, and an
    :class:`~fuzzyctl.engine.ranges.InputRangeWarning`), ``"clamp"``, ``"raise"`` or
    ``"ignore"`` (the controller's ``out_of_range``; each evaluation can override it).

    ``block`` names the function block of a document (default: the first); ``backend`` is
    ``"auto"`` (the default, or ``$FUZZYCTL_BACKEND``: native when a C compiler is present
    and the C generator expresses the system, else python; a missing compiler is a one-line
    notice), ``"native"`` (generated C compiled into a cached shared library, see
    docs/codegen.md; without a C compiler it warns and uses the Python path), ``"python"``
    (generated Python for single evaluations, numpy for batches), ``"interpreted"`` (the
    reference interpreter only) or ``"table"`` (a lookup table with a proven error bound,
    ``tolerance=`` a fraction of each output's range, default 0.001, and ``max_bytes=``: see
    docs/codegen.md, lookup tables); ``compat="fuzzylite"`` etc. reproduces other tools'
    semantics (default IEC 61131-7).  ``strict=True`` refuses what a strict IEC 61131-7
    reading refuses and the engine otherwise settles with a warning: an output without RANGE
    whose terms do not fall to 0, identifiers that are Table 7 keywords; the warnings it
    settles with are the controller's ``warnings``.  Raises
    :class:`~fuzzyctl.diagnostics.DiagnosticError` for what the engine cannot evaluate.

    ```python
    >>> import fuzzyctl
    >>> ctl = fuzzyctl.compile(fuzzyctl.load("examples/figure7.fcl"))
    >>> list(ctl.inputs), list(ctl.outputs)
    (['temp', 'pressure'], ['valve'])
    >>> round(ctl.evaluate(temp=10, pressure=60)["valve"], 10)   # IEC 61131-7 figure 7
    51.8518518519

    ```
    """
    from fuzzyctl.engine.ranges import check_mode
    from fuzzyctl.gcpause import gc_paused
    from fuzzyctl.model import Document

    check_mode(out_of_range)
    table: dict[str, Any] = {k: options.pop(k) for k in ("tolerance", "max_bytes") if k in options}
    if table and backend != "table":
        from fuzzyctl.diagnostics import FuzzyctlError

        raise FuzzyctlError(f"{', '.join(table)}: options of backend='table'")
    if isinstance(model, (str, Path)):  # a path, or FCL source text as load() takes it
        model = load(model, strict=bool(options.get("strict")))
    if options.get("strict"):
        _refuse_reserved(model)
    fb = model.block(block) if isinstance(model, Document) else model
    if fb.is_type2:  # interval type-2: its own evaluator (fuzzyctl.engine.type2)
        from fuzzyctl.engine.type2 import compile_type2

        return compile_type2(fb, backend or os.environ.get("FUZZYCTL_BACKEND"), **options)  # type: ignore[return-value]
    with gc_paused():  # lowering and generating build large acyclic structures
        plan, key, found = _plan(model, block, options)
        fb = model.block(block) if isinstance(model, Document) else model
        ctl = _controller(plan, backend, key, fb, found, table)
    ctl.out_of_range = out_of_range
    return ctl


def _refuse_reserved(model: Document | FunctionBlock) -> None:
    from fuzzyctl.diagnostics import DiagnosticError, has_errors
    from fuzzyctl.fcl.reserved import check_reserved_words
    from fuzzyctl.model import Document

    doc = model if isinstance(model, Document) else Document((model,))
    found = check_reserved_words(doc, doc.path, strict=True) + _strict_findings(doc)
    if has_errors(found):
        raise DiagnosticError(found)


def _strict_findings(doc: Document) -> list[Diagnostic]:
    """What every reader accepts with a warning and ``strict`` refuses (a WITH weight above
    1), placed as the file's reader places it (a JSON model's spans are those of the file it
    came from)."""
    from fuzzyctl import formats
    from fuzzyctl.diagnostics import FuzzyctlError, Severity
    from fuzzyctl.validation import Placer, at_spans, validate

    place: Placer = at_spans
    if doc.path:
        with contextlib.suppress(FuzzyctlError):
            place = formats.for_path(doc.path).place
    return place([f for f in validate(doc, strict=True) if f.severity is Severity.ERROR], doc.path)


def compile_path(
    path: str | Path,
    *,
    block: str | None = None,
    backend: str | None = None,
    format: str | None = None,
    out_of_range: str = "warn",
    **options: Any,
) -> Controller:
    """``compile(load(path), ...)``, answered from the caches without reading the model when
    a file with this content was compiled with these options before (the quick start of
    ``fuzzyctl eval``)."""
    from fuzzyctl import cache

    path = Path(path)
    fmt = (format or "").lower() or (path.suffix.lower().lstrip(".") or "fcl")
    key = None
    if cache.enabled():
        from fuzzyctl.diagnostics import DiagnosticError
        from fuzzyctl.limits import read_input

        try:
            key = _plan_key(content_key(read_input(path, fmt), fmt), block, options)
        except DiagnosticError:
            key = None  # load() reports it
        hit = _cached_plan(key) if key is not None else None
        ranges = _cached(f"ranges/{key}.pickle") if hit is not None else None
        if hit is not None and isinstance(ranges, dict):
            ctl = _controller(hit[0], backend, key, None, hit[1])
            ctl.input_ranges = ranges  # (the model, where they are declared, was not read)
            ctl.out_of_range = out_of_range
            return ctl
    ctl = compile(load(path, format=fmt), block=block, backend=backend, out_of_range=out_of_range, **options)
    if key is not None:
        _store(f"ranges/{key}.pickle", ctl.input_ranges)
    return ctl


def _controller(
    plan: Plan,
    backend: str | None,
    key: str | None,
    model: FunctionBlock | None = None,
    found: tuple[Diagnostic, ...] = (),
    table: dict[str, Any] | None = None,
) -> Controller:
    ctl = _backend(plan, backend, key, model, table or {})
    ctl.warnings = found
    return ctl


def _backend(
    plan: Plan, backend: str | None, key: str | None, model: FunctionBlock | None, table: dict[str, Any]
) -> Controller:
    backend = backend or os.environ.get("FUZZYCTL_BACKEND") or "auto"
    if backend not in BACKENDS:
        from fuzzyctl.diagnostics import FuzzyctlError

        raise FuzzyctlError(f"unknown backend {backend!r} (available: {', '.join(BACKENDS)})")
    if backend == "table":
        from fuzzyctl.engine.table import TableController, build_table

        return TableController(plan, build_table(plan, model=model, **table), model)
    if backend in ("native", "auto") and plan.options.emulate is None:
        # (an emulated tool's arithmetic - jFuzzyLogic's 1000-point sets - has no C form: the
        # controller's own evaluator serves every path)
        from fuzzyctl import cache
        from fuzzyctl.engine.native import compile_native

        hint = cache.cache_dir() / "plans" / f"{key}.lib" if key is not None and cache.enabled() else None
        return compile_native(plan, model, explicit=backend == "native", hint=hint, content_key=key)
    from fuzzyctl.engine.controller import Controller

    return Controller(plan, specialise=backend == "python", model=model)


def compile_plan(model: Document | FunctionBlock, *, block: str | None = None, **options: Any) -> Plan:
    """The lowered plan of ``model`` (``compile``'s first step), from the cache when the
    document was loaded from a file this fuzzyctl has compiled before."""
    return _plan(model, block, options)[0]


def _cached_plan(key: str) -> tuple[Plan, tuple[Diagnostic, ...]] | None:
    """A plan and the warnings compiling it gave, from the cache."""
    hit = _cached(f"plans/{key}.pickle")
    return hit if isinstance(hit, tuple) and len(hit) == 2 else None


def _plan(
    model: Document | FunctionBlock, block: str | None, options: dict[str, Any]
) -> tuple[Plan, str | None, tuple[Diagnostic, ...]]:
    from fuzzyctl import cache
    from fuzzyctl.engine.compile import compile_block

    doc_key = _KEYS.get(id(model))
    key = None
    if doc_key is not None and doc_key[0] is model and cache.enabled():
        key = _plan_key(doc_key[1], block, options)
        if key is not None:
            hit = _cached_plan(key)
            if hit is not None:
                return hit[0], key, hit[1]
    from fuzzyctl.gcpause import gc_paused

    with gc_paused():  # (compile() pauses it too; compile_plan() comes here directly)
        ctl = compile_block(model, block=block, backend="interpreted", **options)
    if key is not None:
        _store(f"plans/{key}.pickle", (ctl.plan, ctl.warnings))
    return ctl.plan, key, ctl.warnings


def _plan_key(doc_key: str, block: str | None, options: dict[str, Any]) -> str | None:
    try:
        spec = repr((doc_key, block, sorted(options.items())))
    except TypeError:  # options that do not sort: no cache
        return None
    return hashlib.sha256(spec.encode()).hexdigest()[:32]


def _remember(doc: Document, key: str) -> None:
    _KEYS[id(doc)] = (doc, key)
    while len(_KEYS) > 32:
        _KEYS.popitem(last=False)


def _cached(rel: str) -> Any:
    from fuzzyctl import cache
    from fuzzyctl.gcpause import gc_paused

    path = cache.cache_dir() / rel
    try:
        with open(path, "rb") as fh, gc_paused():
            obj = pickle.load(fh)
    except (OSError, pickle.UnpicklingError, EOFError, AttributeError, ImportError, TypeError, ValueError):
        return None
    cache.touch(path)
    return obj


def _store(rel: str, obj: Any) -> None:
    from fuzzyctl import cache
    from fuzzyctl.gcpause import gc_paused

    path = cache.cache_dir() / rel
    try:
        with gc_paused():  # the collector walking the model under the pickler: 0.9 s, not 0.3
            data = pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL)
    except Exception:  # pragma: no cover - an unpicklable model: no cache
        return
    if cache.write_atomic(path, data):
        cache.prune(path.parent, cache.limit_bytes(), keep=path)


def plot_terms(variable: VariableInfo, *, points: int = 1001, ax: Axes | None = None) -> Figure:
    """The membership functions of a variable as a labelled matplotlib Figure:
    ``fuzzyctl.plot_terms(ctl.inputs["temp"]).savefig("temp.png")`` (as scikit-fuzzy's
    ``view()`` or simpful's ``plot_variable``).

    ```python
    >>> import fuzzyctl
    >>> ctl = fuzzyctl.compile(fuzzyctl.load("examples/figure7.fcl"))
    >>> fig = fuzzyctl.plot_terms(ctl.inputs["temp"])
    >>> [line.get_label() for line in fig.axes[0].get_lines()]
    ['cold', 'hot']

    ```
    """
    from fuzzyctl.engine.plot import plot_terms as draw

    return draw(variable, points=points, ax=ax)
