"""What ``fuzzyctl codegen`` produces: the code of one target (``st``, ``plcopen``, ``c`` or
``fmu``), printed or written where asked, and its JSON report.  The CLI and the Python API both call
:func:`emit`; the generators themselves are :func:`~fuzzyctl.codegen.generate_st`,
:func:`~fuzzyctl.codegen.generate_plcopen` and :func:`~fuzzyctl.codegen.generate_c`."""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from fuzzyctl.diagnostics import OptionError
from fuzzyctl.kinds import arith as arith_kinds
from fuzzyctl.kinds import targets
from fuzzyctl.model import Document
from fuzzyctl.type2 import refuse as refuse_type2

if TYPE_CHECKING:
    from fuzzyctl.codegen.api import Generated

DEFAULT_DIALECT = next(iter(targets.DIALECTS))
READ_ONLY_HINT = "make it writable to replace it"
"""What a read-only file to replace is told (the CLI says ``--force replaces it``)."""


@dataclass
class Emitted:
    """The outcome of :func:`emit`: the text when nothing was written (``st`` and ``plcopen``
    without an output file), else the files written; ``blocks`` is what the generator
    changed to express each block (``plcopen`` reports none)."""

    lang: str
    blocks: list[Generated] = field(default_factory=list)
    text: str | None = None
    written: list[Path] = field(default_factory=list)
    fmu: Any = None
    """The FMU written (:class:`fuzzyctl.codegen.fmu.FmuResult`, ``fmu`` only)."""
    fmi: int | None = None

    @property
    def renames(self) -> list[Any]:
        """What the generator renamed for the target, block after block."""
        if self.fmu is not None:
            return list(self.fmu.renames)
        return [r for g in self.blocks for r in g.renames]

    def wrote(self) -> str:
        """The line that says what was written."""
        if self.fmu is not None:
            built = f", binary {self.fmu.binary}" if self.fmu.binary else ", sources only"
            return f"wrote {self.fmu.path} (FMI {self.fmi} co-simulation{built})"
        return f"wrote {', '.join(str(p) for p in self.written)}"

    @property
    def reports(self) -> bool:
        """Whether this target has a JSON report (PLCopen XML has none: ``--json`` is not
        one of its options)."""
        return self.fmu is not None or targets.cli_target(self.lang).report

    def to_dict(self) -> dict[str, Any]:
        """The JSON report: the target, each block's renames and notes, and the text or the
        files written."""
        if self.fmu is not None:
            return {"lang": "fmu", **self.fmu.to_dict()}
        out: dict[str, Any] = {"lang": self.lang, "blocks": [g.to_dict() for g in self.blocks]}
        if self.text is not None:
            out["text"] = self.text
        else:
            out["written"] = [str(p) for p in self.written]
        return out


def accepting(option: str) -> list[str]:
    """The ``--lang`` choices an option applies to (their records' ``cli_options``)."""
    return [t.cli for t in targets.TARGETS.values() if t.cli is not None and option in t.cli_options]


def generator_of(caps: targets.Target) -> Callable[..., Any]:
    """The function the record names (``module:function``), imported on use."""
    module, _, name = caps.generator.partition(":")
    fn: Callable[..., Any] = getattr(importlib.import_module(module), name)
    return fn


def check_options(
    lang: str,
    *,
    dialect: str | None,
    lreal: bool,
    single: bool,
    default: str | None,
    testbench: int = 0,
    fmi: int | None = None,
    binary: bool = True,
    arith: str = arith_kinds.DEFAULT,
    lookup: bool = False,
    tolerance: str | float | None = None,
    max_bytes: int | None = None,
    int_output: str | None = None,
    term_tolerance: str | float | None = None,
) -> None:
    """Refuse options that do not apply to ``lang`` before anything is read
    (:class:`OptionError` names the option); what applies is the target's record."""
    from fuzzyctl.codegen.defaults import parse_default
    from fuzzyctl.escape import CodegenError

    caps = targets.cli_target(lang)
    takes = caps.cli_options
    if "fmi" in takes:
        _check_fmu_options(lang, fmi, dialect is not None or lreal or single or bool(testbench))
    elif fmi is not None or not binary:
        raise OptionError(f"--fmi and --no-binary apply to --lang {' and '.join(accepting('fmi'))}", "--fmi")
    if ("dialect" not in takes and dialect is not None) or ("lreal" not in takes and lreal):
        raise OptionError(
            f"--dialect and --lreal apply to --lang {' and '.join(accepting('dialect'))}", "--lang"
        )
    if "float" not in takes and single:
        hint = " (use --lreal)" if "lreal" in takes else ""
        raise OptionError(f"--float applies to --lang {' and '.join(accepting('float'))}{hint}", "--lang")
    if arith != arith_kinds.DEFAULT and "arith" not in takes:
        raise OptionError(f"--arith applies to --lang {' and '.join(accepting('arith'))}", "--arith")
    try:
        arith_kinds.get(arith)
    except ValueError as exc:
        raise OptionError(str(exc), "--arith") from None
    _check_lookup(lookup, tolerance, max_bytes, "lookup" in takes)
    if int_output is not None:
        if not arith_kinds.get(arith).integer or lookup:
            raise OptionError(
                "--int-output applies to --arith int16 and int32 (without --lookup)", "--int-output"
            )
        if int_output not in arith_kinds.INT_OUTPUTS:
            raise OptionError(
                f"--int-output {int_output!r}: choose {' or '.join(arith_kinds.INT_OUTPUTS)}", "--int-output"
            )
    if term_tolerance is not None:
        _check_term_tolerance(term_tolerance, arith_kinds.get(arith).integer and not lookup)
    refusal = targets.dialect(dialect).refused_by.get(caps.name) if dialect is not None else None
    if refusal is not None:
        raise OptionError(f"{refusal}: use --lang st --dialect {dialect}", "--dialect")
    try:
        parse_default(default)
    except CodegenError as exc:
        raise OptionError(str(exc), "--default") from None


def _check_lookup(lookup: bool, tolerance: str | float | None, max_bytes: int | None, takes: bool) -> None:
    from fuzzyctl.codegen.lookup import parse_tolerance

    if lookup and not takes:
        raise OptionError(f"--lookup applies to --lang {' and '.join(accepting('lookup'))}", "--lookup")
    if not lookup and (tolerance is not None or max_bytes is not None):
        raise OptionError("--tolerance and --max-bytes apply to --lookup", "--lookup")
    if tolerance is not None:
        parse_tolerance(tolerance)
    if max_bytes is not None and max_bytes < 16:
        raise OptionError(f"--max-bytes {max_bytes}: give at least 16 bytes", "--max-bytes")


def _check_term_tolerance(value: str | float, integer: bool) -> None:
    from fuzzyctl.escape import CodegenError
    from fuzzyctl.ir.builders.fixed_smooth import parse_term_tolerance

    if not integer:
        raise OptionError(
            "--term-tolerance applies to --arith int16 and int32 (without --lookup)", "--term-tolerance"
        )
    try:
        parse_term_tolerance(value)
    except CodegenError as exc:
        raise OptionError(str(exc), "--term-tolerance") from None


def _check_fmu_options(lang: str, fmi: int | None, other: bool) -> None:
    from fuzzyctl.codegen.fmu.description import FMI_VERSIONS

    if fmi is not None and fmi not in FMI_VERSIONS:
        raise OptionError(f"FMI version {fmi}: give 2 or 3", "--fmi")
    if other:
        raise OptionError(
            f"--dialect, --lreal, --float and --testbench do not apply to --lang {lang} "
            "(it computes in double)",
            "--lang",
        )


def emit(
    model: Document | str | Path,
    lang: str,
    output: Path | None = None,
    *,
    dialect: str | None = None,
    lreal: bool = False,
    single: bool = False,
    testbench: int = 0,
    block: str | None = None,
    default: str | None = None,
    strict: bool = False,
    force: bool = False,
    hint: str = READ_ONLY_HINT,
    format: str | None = None,
    fmi: int | None = None,
    binary: bool = True,
    arith: str = arith_kinds.DEFAULT,
    lookup: bool = False,
    tolerance: str | float | None = None,
    max_bytes: int | None = None,
    int_output: str | None = None,
    samples: int | None = None,
    term_tolerance: str | float | None = None,
) -> Emitted:
    """Generate ``lang`` for ``model`` (a document, or a file read as ``format``; the options
        are checked first) and write it: ``st`` and ``plcopen`` to the file
        ``output`` (None: the text is returned), ``c`` into the directory ``output`` (default: the
        current one), every file checked writable before any is replaced; ``fmu`` one block
    (``block``, default the first) as an FMI ``fmi`` (2 or 3, default 3) co-simulation FMU in the
    file ``output`` (default ``NAME.fmu``), with this platform's binary unless not ``binary``;
    ``samples``: the output sample count of a type-2 system (refused for a type-1 one)."""
    import fuzzyctl
    from fuzzyctl.type2 import check_samples

    check_options(
        lang,
        dialect=dialect,
        lreal=lreal,
        single=single,
        default=default,
        testbench=testbench,
        fmi=fmi,
        binary=binary,
        arith=arith,
        lookup=lookup,
        tolerance=tolerance,
        max_bytes=max_bytes,
        int_output=int_output,
        term_tolerance=term_tolerance,
    )
    check_samples(samples)
    document = model if isinstance(model, Document) else fuzzyctl.load(model, strict=strict, format=format)
    caps = targets.cli_target(lang)
    refuse_type2(document, "codegen", caps.type2)  # (any block: --block errors come later)
    if samples is not None:
        try:
            chosen_block = document if block is None else document.block(block)
        except KeyError:  # an unknown --block is reported below, by the generators
            chosen_block = document
        check_samples(samples, chosen_block)
    if "fmi" in caps.cli_options:
        return _fmu(document, output, fmi or 3, block, strict, default, force, binary, hint)
    emitted = Emitted(lang)
    kwargs: dict[str, Any] = {"block": block, "strict": strict, "default": default}
    chosen = {
        "dialect": dialect or DEFAULT_DIALECT,
        "lreal": lreal,
        "single": single,
        "testbench": testbench,
        "arith": arith,
    }
    for option, keyword in (
        ("arith", "arith"),
        ("dialect", "dialect"),
        ("lreal", "lreal"),
        ("float", "single"),
        ("testbench", "testbench"),
    ):
        if option in caps.cli_options:
            kwargs[keyword] = chosen[keyword]
    if lookup:  # the table generators: codegen/lookup_st.py, lookup_c.py
        from fuzzyctl.codegen.lookup import lookup_options

        kwargs.update(lookup_options(tolerance, max_bytes))
    if int_output is not None:  # the integer generators: codegen/fixed.py
        kwargs["int_output"] = int_output
    if samples is not None:  # the type-2 generators: codegen/type2.py
        kwargs["samples"] = samples
    if term_tolerance is not None:  # smooth input terms in the integer generators
        kwargs["term_tolerance"] = term_tolerance
    if caps.report:
        kwargs["report"] = emitted.blocks
    result = generator_of(caps)(document, **kwargs)
    if isinstance(result, str):  # one text: printed, or written to ``output``
        return _text_or_file(emitted, result, output, force, hint)
    emitted.written = _write_files(result, output or Path("."), force, hint)
    return emitted


def _text_or_file(emitted: Emitted, text: str, output: Path | None, force: bool, hint: str) -> Emitted:
    from fuzzyctl.files import write_atomic

    if output is None:
        emitted.text = text
    else:
        write_atomic(output, text, force=force, hint=hint)
        emitted.written = [output]
    return emitted


def _write_files(files: dict[str, str], out_dir: Path, force: bool, hint: str) -> list[Path]:
    from fuzzyctl.files import check_writable, write_atomic

    if out_dir.exists() and not out_dir.is_dir():
        raise OptionError(f"{out_dir} is not a directory", "-o")
    out_dir.mkdir(parents=True, exist_ok=True)
    if not force:  # every file checked before any is written: no half-replaced set
        for name in files:
            check_writable(out_dir / name, hint=hint)
    for name, text in files.items():
        write_atomic(out_dir / name, text, force=force, hint=hint)
    return [out_dir / name for name in files]


def _fmu(
    document: Document,
    output: Path | None,
    fmi: int,
    block: str | None,
    strict: bool,
    default: str | None,
    force: bool,
    binary: bool,
    hint: str,
) -> Emitted:
    from fuzzyctl.codegen.fmu import generate_fmu
    from fuzzyctl.files import check_writable

    if output is not None and output.is_dir():
        raise OptionError(f"{output} is a directory: give the .fmu file to write", "-o")
    if output is not None and not force:
        check_writable(output, hint=hint)
    result = generate_fmu(
        document, output, block=block, fmi=fmi, binary=binary, default=default, strict=strict, force=force
    )
    return Emitted("fmu", fmu=result, fmi=fmi, written=[Path(result.path)])
