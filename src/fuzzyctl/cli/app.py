"""The typer application and the error boundary that keeps tracebacks away from users.

Exit codes: 0 success, 1 the input has errors, 2 usage error, 3 internal error (a bug)."""

from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.console import Console

from fuzzyctl import __version__, formats
from fuzzyctl.diagnostics import DiagnosticError, FuzzyctlError, OptionError

if TYPE_CHECKING:
    from rich.progress import Progress, ProgressColumn
    from rich.table import Table


def _plain_help() -> None:
    """typer 0.29 prints ``<bool>`` after every flag (as if it took a value) and required
    arguments as ``{file}`` in the usage line; our help shows flags bare and arguments as
    FILE, as click and every Unix tool do (tests/cli/test_help.py reads every --help)."""
    from typer import core

    def display_type_rich(self: Any, ctx: Any) -> str | None:
        if getattr(self, "is_flag", False) or getattr(self, "is_bool_flag", False):
            return None
        return original(self, ctx)

    def usage_name(self: Any) -> str:
        name = str(self.display_name_raw).upper()
        name = name if self.required else f"[{name}]"
        return name + ("..." if self.nargs != 1 else "")

    original = core.TyperOption.display_type_rich
    core.TyperOption.display_type_rich = display_type_rich  # type: ignore[method-assign]
    core.TyperArgument._usage_display_name = usage_name  # type: ignore[method-assign]


_plain_help()

app = typer.Typer(
    name="fuzzyctl",
    rich_markup_mode="markdown",  # paragraphs reflow: docstrings wrapped at 100 columns read as prose
    help="IEC 61131-7 fuzzy control: check, run, convert and generate code for FCL programs.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)

err_console = Console(stderr=True, highlight=False, soft_wrap=True)

EXIT_OK, EXIT_ERRORS, EXIT_USAGE, EXIT_INTERNAL = 0, 1, 2, 3
FORCE_HINT = "--force replaces it"
FromOpt = Annotated[
    str | None,
    typer.Option(
        "--from",
        help=f"Format of FILE: {formats.names_text()} (default: its extension).",
        show_default=False,
    ),
]
"""The option every command that reads a model takes to name its format."""
StrictOpt = Annotated[
    bool,
    typer.Option(
        "--strict",
        help="Refuse what a strict IEC 61131-7 reading refuses: an output without RANGE whose terms "
        "do not fall to 0, names that are reserved keywords.",
    ),
]
"""The option of the commands that compile a model: refuse what a strict reading refuses."""
"""How the commands that write files for the user override a read-only target."""


def stderr_progress(*columns: ProgressColumn | str, hidden: bool) -> Progress:
    """A progress bar on stderr that disappears when done (none with ``hidden``): the
    task's description, the bar, then ``columns``."""
    from rich.progress import BarColumn, Progress, TextColumn

    return Progress(
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        *columns,
        console=Console(stderr=True),
        transient=True,
        disable=hidden,
    )


def record_table(title: str, figures: dict[str, str], width: int) -> Table:
    """Named figures as one row with a column each when that fits ``width``, else as
    name/value rows: numbers are never cut short on a narrow terminal."""
    from rich.table import Table

    wide = sum(max(len(k), len(v)) + 3 for k, v in figures.items()) + 1
    table = Table(title=title)
    if wide <= width:
        for name in figures:
            table.add_column(name, justify="right", overflow="fold")
        table.add_row(*figures.values())
        return table
    table.add_column("figure", overflow="fold")
    table.add_column("value", justify="right", overflow="fold")
    for name, value in figures.items():
        table.add_row(name, value)
    return table


@contextmanager
def usage_errors() -> Iterator[None]:
    """A library's :class:`~fuzzyctl.diagnostics.OptionError` as the command's usage error
    (exit 2, the usage line, the option named), raised inside the command's context."""
    try:
        yield
    except OptionError as exc:
        raise typer.BadParameter(str(exc), param_hint=exc.option) from None


def split_names(values: list[str] | str | None) -> list[str]:
    """A list option's names: ``a,b``, ``'a b'`` and the option repeated all give [a, b]."""
    import re

    items = [values] if isinstance(values, str) else (values or [])
    return [n for v in items for n in re.split(r"[,\s]+", v) if n]


def _version(value: bool) -> None:
    if value:
        typer.echo(f"fuzzyctl {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool, typer.Option("--version", callback=_version, is_eager=True, help="Print the version.")
    ] = False,
) -> None:
    """fuzzyctl: fuzzy control the way PLC engineers practise it."""


def _register_commands() -> None:
    """Import every command module so that each attaches its commands to ``app``."""
    from fuzzyctl.cli import commands

    commands.import_all()


def command_for(args: list[str]) -> Any:
    """The click command that runs ``args``, with only what it needs imported: the module of
    the command ``args`` names, or - for ``fuzzyctl`` alone, ``--help`` and ``--version`` -
    none: the help lists every command from :data:`fuzzyctl.cli.commands.COMMANDS` (what
    importing them all and building their options cost ``--help`` about 100 ms)."""
    from fuzzyctl.cli import commands

    first = args[0] if args else None
    if first is not None and commands.import_for(first):
        return typer.main.get_command(app)
    if first is not None and first not in ("--help", "--version"):
        commands.import_all()  # an unknown command or option: the message names what exists
        return typer.main.get_command(app)
    from typer.core import TyperCommand

    group = typer.main.get_command(app)  # the commands imported so far, if any
    real = dict(getattr(group, "commands", {}))
    group.commands = {  # type: ignore[attr-defined]
        name: real.get(name) or TyperCommand(name, help=listed.summary, rich_markup_mode="markdown")
        for name, listed in commands.COMMANDS.items()
    } | real
    return group


def _given_twice(argv: list[str]) -> None:
    """learn and tune before -o/--output meant the file everywhere: ``--output COLUMN -o FILE``
    now gives the file twice, which click would take silently (the last wins)."""
    if not argv or argv[0] not in ("learn", "tune"):
        return
    given = [a for a in argv[1:] if a in ("-o", "--output") or a.startswith("--output=")]
    if len(given) > 1:
        from fuzzyctl.cli.tune import RENAMED

        raise typer.BadParameter(f"given {len(given)} times: {RENAMED}", param_hint="-o/--output")


#: the list options of each command that take several values after one flag (as argparse's
#: nargs="+"): ``--inputs a b`` is ``--inputs a --inputs b``
LIST_OPTIONS = {"learn": ("--inputs",), "tune": ("--target",)}


def spread_lists(argv: list[str]) -> list[str]:
    """``learn --inputs a b ...`` as click takes it (``--inputs a --inputs b``): the words after
    a list option up to the next option are its values, as argparse's ``nargs="+"`` reads
    them - except an existing file when the command's file argument has not come yet
    (``learn --inputs a b data.csv``)."""
    if not argv or argv[0] not in LIST_OPTIONS:
        return argv
    from pathlib import Path

    out, seen_positional, i = [argv[0]], False, 1
    while i < len(argv):
        a = argv[i]
        out.append(a)
        i += 1
        if a == "--":
            out.extend(argv[i:])
            break
        if a in LIST_OPTIONS[argv[0]] and i < len(argv):
            out.append(argv[i])  # the first value, whatever it looks like
            i += 1
            while i < len(argv) and not argv[i].startswith("-"):
                if not seen_positional and Path(argv[i]).is_file():
                    break
                out.extend([a, argv[i]])
                i += 1
        elif not a.startswith("-") and not _takes_value(out[-2]):
            seen_positional = True
    return out


def _takes_value(option: str) -> bool:
    """Whether the option before a word consumes it (every option of learn/tune but the
    flags does)."""
    return option.startswith("-") and "=" not in option and option not in _FLAGS


_FLAGS = frozenset({"--json", "--keep-zero", "--move-zero", "--help"})


def _renamed_hint(exc: Exception) -> None:
    """A missing --target of learn/tune is most often the old ``--output COLUMN``: say so."""
    # (typer vendors click: the class is matched by name, not imported from a private module)
    if not isinstance(exc, typer.BadParameter) or type(exc).__name__ != "MissingParameter":
        return
    if getattr(exc.param, "name", None) == "target":
        exc.message = "Name the column(s) with --target (-o/--output names the file written)"


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; never lets a Python traceback reach the user."""
    try:
        args = spread_lists(sys.argv[1:] if argv is None else argv)
        _given_twice(args)
        command = command_for(args)
        result = command.main(args=args, prog_name="fuzzyctl", standalone_mode=False)
    except typer.Exit as exc:
        return int(exc.exit_code or 0)
    except typer.Abort:
        err_console.print("aborted")
        return EXIT_ERRORS
    except typer.TyperException as exc:  # usage errors: bad option, missing argument, ...
        _renamed_hint(exc)
        show = getattr(exc, "show", None)
        if callable(show):
            show(file=sys.stderr)
        else:
            err_console.print(f"error: {exc.format_message()}", markup=False)
        return int(getattr(exc, "exit_code", EXIT_USAGE) or EXIT_USAGE)
    except DiagnosticError as exc:
        err_console.print(exc.render(), markup=False)
        return EXIT_ERRORS
    except FuzzyctlError as exc:
        err_console.print(f"error: {exc}", markup=False)
        return EXIT_ERRORS
    except OSError as exc:
        err_console.print(f"error: {exc.strerror or exc}: {exc.filename or ''}".rstrip(": "), markup=False)
        return EXIT_ERRORS
    except KeyboardInterrupt:
        err_console.print("interrupted")
        return 130
    except Exception as exc:
        err_console.print(
            f"internal error: {type(exc).__name__}: {exc}\n"
            "This is a bug in fuzzyctl; please report it with the command you ran.",
            markup=False,
        )
        return EXIT_INTERNAL
    # standalone_mode=False hands back the exit code of typer.Exit as the result.
    return result if isinstance(result, int) else EXIT_OK


def run() -> None:
    sys.exit(main())
