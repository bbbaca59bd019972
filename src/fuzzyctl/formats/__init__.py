"""Interchange formats: one registry of readers, writers and expressibility checks.

Every file format fuzzyctl reads or writes is a :class:`Format` in :data:`REGISTRY`:
``fcl`` (IEC 61131-7, from :mod:`fuzzyctl.fcl`), ``fis`` (MATLAB / Octave / fuzzylite),
``fll`` (fuzzylite language), ``json`` (our own lossless form) and, when their modules are
present, ``fpl`` and ``xfuz`` (PLC tools).  :func:`fuzzyctl.api.load` and ``fuzzyctl
convert`` go through this registry and nothing else.

Each format is a subpackage of one shape: ``fuzzyctl/formats/<name>/`` with ``reader.py``,
``writer.py`` and ``names.py`` (what both use; the reader and the writer never import each
other), and an ``__init__.py`` that exposes ``FORMAT: Format`` and loads the reader and
writer on first use.  What several formats share is in :mod:`fuzzyctl.formats.common`.
``adapt(doc)`` turns a model into what the format can say, returning the list of
:class:`Loss` it had to accept; a conversion is lossless exactly when that list is empty.
Meaning-preserving rewrites (renaming a ``LDL-Level`` to ``LDL_Level`` for FCL, a point list
that is a triangle to ``trimf``) are not losses.

This registry is the one list of formats: each format's name, extensions, size limit and
description are its entry in :mod:`fuzzyctl.formatspec` (at the bottom of the stack, so that
the FCL parser's size limit comes from it too) and its ``FORMAT`` is built from that entry;
the CLI's help, the studio's file list and dialogs, the runtime API and
:func:`fuzzyctl.limits.max_input_bytes` are built from them.
"""

from __future__ import annotations

import importlib
import importlib.util
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from fuzzyctl.diagnostics import Diagnostic, DiagnosticError, FuzzyctlError
from fuzzyctl.files import write_atomic
from fuzzyctl.formatspec import DEFAULT_MAX_BYTES, SPECS, FormatSpec
from fuzzyctl.gcpause import gc_paused

if TYPE_CHECKING:  # the model and its checks load on first use: the CLI's help needs names only
    from fuzzyctl.model import Document
    from fuzzyctl.validation import Placer


@dataclass(frozen=True)
class Loss:
    """Something of the model that a target format cannot express.

    ``element`` names where it is (``rule 3 of block 'No1'``, ``term 'cold' of 'temp'``),
    ``reason`` says what the target lacks."""

    element: str
    reason: str

    def __str__(self) -> str:
        return f"{self.element}: {self.reason}"


@dataclass(frozen=True)
class Loaded:
    """What a reader returns: the model and the warnings met on the way."""

    document: Document
    diagnostics: tuple[Diagnostic, ...] = ()


Reader = Callable[[str, "str | None"], Loaded]
"""``read(text, path) -> Loaded``; raises :class:`DiagnosticError` on invalid input."""
Writer = Callable[["Document"], str]
"""``write(document) -> text``; expects a document :attr:`Format.adapt` returned."""
Adapter = Callable[["Document"], "tuple[Document, list[Loss]]"]
"""``adapt(document) -> (document, losses)``: the model in what the format can say."""


def _nothing_lost(document: Document) -> tuple[Document, list[Loss]]:
    return document, []


def _no_notes(document: Document) -> list[Loss]:
    return []


def on_use(module: str, function: str) -> Callable[..., Any]:
    """``module.function``, imported on the first call: a format package names its reader
    and writer this way, so that importing the registry reads no format's code."""

    def call(*args: Any) -> Any:
        return getattr(importlib.import_module(module), function)(*args)

    call.__name__ = call.__qualname__ = function
    call.__doc__ = f"{module}.{function}, imported on first use."
    return call


def losses_of(adapt: Callable[[Document], tuple[Document, Sequence[tuple[str, str]]]]) -> Adapter:
    """An :data:`Adapter` of a writer's ``adapt`` that names its losses as ``(element, reason)``
    pairs (the PLC formats' writers, which the blocks use without the registry)."""

    def adapted(document: Document) -> tuple[Document, list[Loss]]:
        result, losses = adapt(document)
        return result, [Loss(element, reason) for element, reason in losses]

    return adapted


@dataclass(frozen=True)
class Format:
    """A file format: name, file extensions, size limit, reader, writer and expressibility
    check."""

    name: str
    extensions: tuple[str, ...]
    description: str
    read: Reader | None = None
    write: Writer | None = None
    adapt: Adapter = field(default=_nothing_lost)
    max_bytes: int = DEFAULT_MAX_BYTES
    """The largest file read (:func:`fuzzyctl.limits.max_input_bytes`): every shape of file at
    the limit is read (accepted or refused) well within the 5 s of issue 14
    (benchmarks/large_inputs.py; docs/limits.md has the figures)."""
    notes: Callable[[Document], list[Loss]] = field(default=_no_notes)
    """What the writer says in a nearest form of its own rather than as the model does: not a
    loss (the written file computes the same), but worth a warning to whoever reads the file
    with another tool (FCL: a rule without an IF part becomes ``IF ALWAYS THEN``)."""
    place: Placer = field(default_factory=lambda: on_use("fuzzyctl.validation", "at_spans"))
    """Where this format's diagnostics put what :func:`fuzzyctl.validation.validate` finds:
    at the spans the reader kept (file:line:column), or at JSON paths."""
    validates: bool = False
    """The reader runs :func:`fuzzyctl.validation.validate` itself (FCL, among its checks)."""
    type2: bool = False
    """The format expresses interval type-2 terms (lower membership functions); converting a
    type-2 model to one that does not drops them, as a loss (:mod:`.common.type2`)."""

    @classmethod
    def builtin(cls, spec: FormatSpec, **parts: Any) -> Format:
        """A built-in format: its name, extensions, size limit and description from its
        entry in :mod:`fuzzyctl.formatspec`, the reader, writer, ... from ``parts``."""
        return cls(spec.name, spec.extensions, spec.description, max_bytes=spec.max_bytes, **parts)

    @classmethod
    def lazy(cls, spec: FormatSpec, **parts: Any) -> Format:
        """:meth:`builtin`, where a part given as ``"module:function"`` names a function of the
        format's own package (``fuzzyctl.formats.<name>.module``), imported on first use."""
        for key, part in parts.items():
            if isinstance(part, str):
                module, _, function = part.partition(":")
                parts[key] = on_use(f"fuzzyctl.formats.{spec.name}.{module}", function)
        return cls.builtin(spec, **parts)

    def losses(self, document: Document) -> list[Loss]:
        """What this format cannot express of ``document`` (empty: a lossless write)."""
        return self.adapt(document)[1]


REGISTRY: dict[str, Format] = {}
"""Registered formats by name.  Use :func:`get` and :func:`available`, which load the
built-in ones on first use."""

KNOWN_NAMES: tuple[str, ...] = tuple(SPECS)
"""The built-in formats, each the subpackage ``fuzzyctl.formats.<name>`` (optional ones may be
absent from an installation).  Their ``__init__`` modules are small: a reader or writer is
imported when a file of that kind is used."""


def register(fmt: Format) -> None:
    """Add (or replace) a format in the registry."""
    REGISTRY[fmt.name] = fmt


def find(name: str) -> Format | None:
    """The format called ``name`` (any case, with or without a dot), None when unknown or not
    available here."""
    name = name.lower().lstrip(".")
    if name in REGISTRY:
        return REGISTRY[name]
    module_name = f"{__name__}.{name}"
    if name not in KNOWN_NAMES or importlib.util.find_spec(module_name) is None:
        return None
    module = importlib.import_module(module_name)
    fmt = getattr(module, "FORMAT", None)
    if not isinstance(fmt, Format) or (fmt.read is None and fmt.write is None):
        return None  # a module that exists but provides no usable format yet
    register(fmt)
    return fmt


def available() -> list[Format]:
    """Every format that can be used here, built-in ones first."""
    for name in KNOWN_NAMES:
        find(name)
    # the built-in order, whichever was looked up first; plug-ins after them
    builtin = [REGISTRY[n] for n in KNOWN_NAMES if n in REGISTRY]
    return builtin + [f for n, f in REGISTRY.items() if n not in KNOWN_NAMES]


def get(name: str) -> Format:
    """The format called ``name``; a clear error when it is unknown or not available."""
    key = name.lower().lstrip(".")
    fmt = find(key)
    if fmt is not None:
        return fmt
    usable = ", ".join(f.name for f in available())
    if key in KNOWN_NAMES:
        raise FuzzyctlError(f"format {key!r} is not available in this installation (available: {usable})")
    raise FuzzyctlError(f"unknown format {name!r} (available: {usable})")


def for_path(path: str | Path) -> Format:
    """The format a file name's extension says (``.fis`` -> fis)."""
    suffix = Path(path).suffix.lower()
    for fmt in available():
        if suffix in fmt.extensions:
            return fmt
    if suffix.lstrip(".") in KNOWN_NAMES:
        return get(suffix.lstrip("."))  # known but missing: let get() say so
    known = ", ".join(ext for f in available() for ext in f.extensions)
    raise FuzzyctlError(
        f"cannot tell the format of {str(path)!r} from its extension (known: {known}); "
        "name it with --from/--to"
    )


def extensions() -> tuple[str, ...]:
    """Every file extension of the formats available here (``.fcl``, ``.fis``, ...), in the
    registry's order: what the CLI's help, the studio's file list and dialogs offer."""
    return tuple(ext for f in available() for ext in f.extensions)


def names_text(last: str = ", ", *, upper: bool = False) -> str:
    """The built-in formats' names for a help text: ``fcl, fis, ..., xfuz`` (``last`` joins
    the last two; ``upper``: ``FCL, FIS, ...``)."""
    names = [n.upper() if upper else n for n in KNOWN_NAMES]
    return ", ".join(names[:-1]) + last + names[-1]


def decode(data: bytes) -> str:
    """Source bytes as text: UTF-8 (with or without BOM), else Latin-1, which never fails
    (the corpus has both)."""
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        return data.decode("latin-1")


@gc_paused()
def read_text(text: str, format: str, *, path: str | None = None) -> Loaded:
    """Parse ``text`` as ``format``."""
    from fuzzyctl.limits import check_document, check_text
    from fuzzyctl.validation import validate

    fmt = get(format)
    if fmt.read is None:
        raise FuzzyctlError(f"format {fmt.name!r} can be written but not read")
    check_text(text, path, fmt.name)
    loaded = fmt.read(text, path)
    too_deep = check_document(loaded.document, path)
    if too_deep:  # refused here, before anything walks the trees recursively
        raise DiagnosticError(too_deep, text)
    if fmt.validates:
        return loaded
    found = fmt.place(validate(loaded.document), path)  # the same rules for every reader
    if any(d.is_error for d in found):
        raise DiagnosticError(found, text)
    return Loaded(loaded.document, (*loaded.diagnostics, *found)) if found else loaded


def read_path(path: str | Path, format: str | None = None) -> Loaded:
    """Read a file, choosing the format by ``format`` or by the file's extension; a missing
    or unreadable file, or one over the size limit, is a :class:`DiagnosticError`."""
    from fuzzyctl.limits import read_input

    fmt = get(format) if format else for_path(path)
    data = read_input(path, fmt.name)
    return read_text(decode(data), fmt.name, path=str(path))


def convert(document: Document, format: str, *, lossy: bool = False) -> tuple[str, list[Loss]]:
    """Write ``document`` as ``format``.

    Raises :class:`FuzzyctlError` listing every loss unless ``lossy``; with ``lossy`` the
    text is written without what the format cannot express and the losses are returned."""
    fmt = get(format)
    if fmt.write is None:
        raise FuzzyctlError(f"format {fmt.name!r} can be read but not written")
    dropped: list[Loss] = []
    if not fmt.type2 and any(b.is_type2 for b in document.blocks):
        from fuzzyctl.formats.common.type2 import drop_type2

        document, dropped = drop_type2(document, fmt.name)
    adapted, losses = fmt.adapt(document)
    losses = dropped + losses
    if losses and not lossy:
        raise LossError(fmt.name, losses)
    return fmt.write(adapted), losses


class LossError(FuzzyctlError):
    """A conversion would lose meaning; ``losses`` says what, one item per element."""

    def __init__(self, format: str, losses: Sequence[Loss]) -> None:
        self.format = format
        self.losses = list(losses)
        lines = "\n".join(f"  - {loss}" for loss in self.losses)
        super().__init__(
            f"{format} cannot express {len(self.losses)} element(s) of this model "
            f"(use --lossy to convert anyway):\n{lines}"
        )


__all__ = [
    "KNOWN_NAMES",
    "REGISTRY",
    "DiagnosticError",
    "Format",
    "Loaded",
    "Loss",
    "LossError",
    "available",
    "convert",
    "decode",
    "extensions",
    "find",
    "for_path",
    "get",
    "names_text",
    "read_path",
    "read_text",
    "register",
    "write_atomic",
]
