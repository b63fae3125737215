"""The ``usdrender-lint`` command: check, merge, spec, rules, explain, config,
plugin-path, server, clean; one module per command, every output through
:mod:`.views` (or, for reports, the registered formatters).

Exit codes: 0 nothing at or above ``--fail-on``; 1 findings at or above it;
2 the tool could not do its job (bad usage or config, a plugin that fails to
load, a path that does not exist, a file it could not lint).
"""

from __future__ import annotations

import errno
import io
import os
import sys
from collections.abc import Iterator, MutableMapping, Sequence
from contextlib import contextmanager
from importlib import import_module
from typing import TYPE_CHECKING, Any, NoReturn

import click

from .. import __version__
from ..entrypoints import read_once
from ..paths import printable
from ..running.interrupts import Stopped, stop_on_signals
from ..running.supervisor import Supervision, open_closed_standard_fds
from .loading import collection_paused
from .output import EXIT_TOOL_ERROR, StdoutGone, ToolError, error, say

if TYPE_CHECKING:
    from .rules import rules_text

#: Each command's module (in this package) and object: a command's module is
#: imported when it is asked for by name, so ``check`` imports no other
#: command's module and the options and types they build.
_COMMANDS = {
    "check": ("check", "check"),
    "clean": ("clean", "clean"),
    "config": ("config_keys", "config_command"),
    "explain": ("explain", "explain"),
    "merge": ("merge", "merge"),
    "plugin-path": ("plugin_path", "plugin_path"),
    "rules": ("rules", "list_rules"),
    "server": ("server", "server_command"),
    "spec": ("spec", "spec_command"),
}


class _Commands(MutableMapping[str, click.Command]):
    """The group's commands by name (``click.Group.commands``), each imported
    on first use."""

    def __init__(self) -> None:
        self._loaded: dict[str, click.Command] = {}

    def __getitem__(self, name: str) -> click.Command:
        if name not in self._loaded:
            if name not in _COMMANDS:
                raise KeyError(name)
            module, attr = _COMMANDS[name]
            with collection_paused():
                self._loaded[name] = getattr(import_module(f".{module}", __name__), attr)
        return self._loaded[name]

    def __setitem__(self, name: str, command: click.Command) -> None:
        self._loaded[name] = command

    def __delitem__(self, name: str) -> None:
        raise TypeError("the command line's commands are fixed")

    def __iter__(self) -> Iterator[str]:
        return iter(sorted({*_COMMANDS, *self._loaded}))

    def __len__(self) -> int:
        return len({*_COMMANDS, *self._loaded})


class _Group(click.Group):
    """click's usage errors (a bad option value, an unknown command or option)
    are one line, as the tool's other errors: click's own form is a usage line,
    a hint and the error over four."""

    def make_context(self, *args: Any, **kwargs: Any) -> click.Context:
        with _one_line_usage_errors():
            return super().make_context(*args, **kwargs)

    def invoke(self, ctx: click.Context) -> Any:
        # The formatters (--format) and the rule plugins are looked up in one
        # reading of the installed distributions' entry points.
        with _one_line_usage_errors(ctx), read_once():  # a subcommand's arguments are parsed here
            return super().invoke(ctx)


#: click 8.2's usage error for a group run without a command (its help).
_NO_ARGUMENTS: type[Exception] | tuple[()] = getattr(click.exceptions, "NoArgsIsHelpError", ())


#: ruff's options a ruff user types, and ours that do the same
#: (`ruff check --help`, https://docs.astral.sh/ruff/configuration/#full-command-line-interface).
_RUFF_OPTIONS = {
    "--exit-zero": "--fail-on never",
    "-e": "--fail-on never",
    "--output-format": "--format",
    "--output-file": "--output",
    "-o": "--output",
}


@contextmanager
def _one_line_usage_errors(group: click.Context | None = None) -> Iterator[None]:
    """``group``: the group's context while a subcommand runs, whose command
    names the help when click's parser gives an error no context (an option's
    missing value, a value given to a flag)."""
    try:
        yield
    except _NO_ARGUMENTS:
        raise  # a bare `usdrender-lint`: click shows the help
    except click.UsageError as exc:
        if exc.ctx is not None:
            where = exc.ctx.command_path
        elif group is not None and group.invoked_subcommand:
            where = f"{group.command_path} {group.invoked_subcommand}"
        else:
            where = "usdrender-lint"
        message = exc.format_message().removesuffix(".")
        ours = _ours_for_ruffs(exc)
        if ours is not None:
            message = f"No such option '{ours[0]}': use {ours[1]}, which does what ruff's does"
        raise ToolError(f"{message} (see '{where} --help')") from None


def _ours_for_ruffs(exc: click.UsageError) -> tuple[str, str] | None:
    """(ruff's option, this command's that does the same) for an unknown option
    of ruff's; None otherwise."""
    if not isinstance(exc, click.NoSuchOption) or exc.ctx is None:
        return None
    ours = _RUFF_OPTIONS.get(exc.option_name)
    known = {name for param in exc.ctx.command.params for name in param.opts}
    if ours is None or ours.split()[0] not in known:
        return None
    return exc.option_name, ours


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="usdrender-lint")
def cli() -> None:
    """Lint OpenUSD render settings (usdRender) before the render farm does."""


cli.commands = _Commands()


def main(argv: Sequence[str] | None = None, supervision: Supervision | None = None) -> None:
    """Console entry point: no traceback ever reaches the user. Ctrl-C exits
    130 and SIGTERM 143 (128 + the signal) after cleaning up; a closed or
    broken stdout exits 2 quietly. ``supervision``: how the supervisor
    (running/supervisor.py) ran this process, for the commands it supervises."""
    _open_closed_standard_streams()
    _refuse_completion_without_its_shell()
    try:
        with stop_on_signals():
            cli.main(args=argv, prog_name="usdrender-lint", standalone_mode=True, obj=supervision)
    except SystemExit as done:
        # click ends a broken pipe while it printed (help, the version) with
        # exit 1, its stdout wrapped to pacify the flush at exit: ours is 2.
        if done.code == 1 and type(sys.stdout).__name__.endswith("PacifyFlushWrapper"):
            sys.exit(EXIT_TOOL_ERROR)
        raise
    except Stopped as stopped:
        say(f"usdrender-lint: {stopped.reason}")
        sys.exit(stopped.exit_status)
    except StdoutGone:
        _silence_stdout()
        sys.exit(EXIT_TOOL_ERROR)
    except OSError as exc:
        if exc.errno == errno.ENOMEM:  # a listing or a map under ulimit -v
            _out_of_memory()
        if not _raised_by_echo(exc):
            _internal_error(exc)
        # click printing help, the version or usage: stdout is full or gone.
        _silence_stdout()
        if not isinstance(exc, BrokenPipeError):
            error(f"cannot write the output: {exc.strerror or exc}")
        sys.exit(EXIT_TOOL_ERROR)
    except MemoryError:  # at start-up, under ulimit -v: a file's own is its result
        _out_of_memory()
    except Exception as exc:
        _internal_error(exc)


def _out_of_memory() -> NoReturn:
    from ..running.address_space import out_of_memory

    error(out_of_memory())
    sys.exit(EXIT_TOOL_ERROR)


#: The variable the shell completion scripts set (click's ``_{PROG}_COMPLETE``).
COMPLETE_ENV = "_USDRENDER_LINT_COMPLETE"


def _refuse_completion_without_its_shell() -> None:
    """Completion (``bash_complete``, ``zsh_complete``, ``fish_complete``) is asked
    by the script a shell sources, which sets ``COMP_WORDS``; run by hand without
    it, click fails on the missing variable: one line instead."""
    if os.environ.get(COMPLETE_ENV, "").endswith("_complete") and "COMP_WORDS" not in os.environ:
        error(
            f"{COMPLETE_ENV} is for the shell's completion script, which sets COMP_WORDS; "
            f'install it with eval "$({COMPLETE_ENV}=bash_source usdrender-lint)" (or zsh, fish)'
        )
        sys.exit(EXIT_TOOL_ERROR)


def _raised_by_echo(exc: BaseException) -> bool:
    """Whether ``exc`` came out of ``click.echo`` (help, version, usage). The
    frames are read without the ``traceback`` module: its import can itself
    fail for want of memory, and that traceback reached the user."""
    utils = os.path.join("click", "utils.py")
    tb = exc.__traceback__
    while tb is not None:
        code = tb.tb_frame.f_code
        if code.co_name == "echo" and code.co_filename.endswith(utils):
            return True
        tb = tb.tb_next
    return False


def _internal_error(exc: Exception) -> None:
    if os.environ.get("USDRENDER_LINT_DEBUG"):
        raise exc
    say(
        f"usdrender-lint: internal error: {type(exc).__name__}: {printable(str(exc))} "
        "(set USDRENDER_LINT_DEBUG=1 for a traceback)"
    )
    sys.exit(EXIT_TOOL_ERROR)


def _open_closed_standard_streams() -> None:
    """/dev/null on a standard file descriptor that was closed when the command
    started (open_closed_standard_fds). Python made sys.stdout None for it, which
    click's printing (help, the version) takes for a stream to skip, exiting 0
    with nothing said: a stdout that is gone instead, as a pipe nobody reads. A
    closed stderr only loses what is said on it: a stream to /dev/null (code
    asking it, ``sys.stderr.isatty()``, raised AttributeError)."""
    open_closed_standard_fds()
    if sys.stdout is None:
        sys.stdout = _ClosedStdout()
    if sys.stderr is None:
        sys.stderr = open(2, "w", errors="backslashreplace", closefd=False)  # noqa: SIM115


class _ClosedStdout(io.TextIOBase):
    """The stdout of a command started with it closed: every write fails as a
    pipe's whose reader left (the report's writing ends quietly with exit 2)."""

    def write(self, text: str) -> int:
        raise BrokenPipeError(errno.EPIPE, os.strerror(errno.EPIPE))


def _silence_stdout() -> None:
    """Point fd 1 at /dev/null, so that flushing stdout at exit fails no more."""
    null = os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, 1)
    os.close(null)


def __getattr__(name: str) -> Any:
    if name == "rules_text":  # the rules listing's layout, for its tests
        from .rules import rules_text

        return rules_text
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["cli", "main", "rules_text"]
