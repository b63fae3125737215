"""Where every command's output goes: stdout (its failures told apart: a
reader that went away is a quiet exit 2, a full disk a one-line error) or a
file written as a shell's ``>`` would, and one-line errors on stderr."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from ..paths import printable

#: The pipeline's exit codes (running/pipeline.py), repeated so that --help
#: and --version need no import of USD.
EXIT_OK, EXIT_FINDINGS, EXIT_TOOL_ERROR = 0, 1, 2


class ToolError(click.ClickException):
    """A one-line error on stderr and exit 2."""

    exit_code = EXIT_TOOL_ERROR

    def show(self, file=None) -> None:
        error(self.format_message())


class StdoutGone(Exception):
    """stdout is closed, or its reader went away (``check | head``): nobody
    reads the report, so the run ends with exit 2 and says nothing."""


def error(message: str) -> None:
    click.echo(f"usdrender-lint: error: {printable(message)}", err=True)


def note(message: str) -> None:
    click.echo(f"usdrender-lint: {printable(message)}", err=True)


class Stdout:
    """sys.stdout, with its failures told apart: a closed or broken pipe is
    :class:`StdoutGone`, any other (a full disk) a ToolError."""

    def write(self, text: str) -> int:
        return self._do(lambda stream: stream.write(text))

    def flush(self) -> None:
        self._do(lambda stream: stream.flush())

    def isatty(self) -> bool:
        return bool(sys.stdout is not None and sys.stdout.isatty())

    @staticmethod
    def _do(action):
        if sys.stdout is None:  # fd 1 was closed when Python started
            raise StdoutGone
        try:
            return action(sys.stdout)
        except BrokenPipeError:
            raise StdoutGone from None
        except OSError as exc:
            raise ToolError(f"cannot write the report: {exc.strerror or exc}") from None


def write(text: str) -> None:
    """Write ``text`` to stdout and flush it, so that a failure is known now."""
    stdout = Stdout()
    stdout.write(text)
    stdout.flush()


def write_file(path: str | Path, text: str, what: str) -> None:
    """Write ``text`` to ``path`` as a shell's ``>`` would, atomically where
    that can be (atomic.write_output); a failure is one line, exit 2."""
    from ..atomic import write_output

    try:
        write_output(path, text)
    except OSError as exc:
        raise ToolError(f"{path}: cannot write {what}: {exc.strerror or exc}") from None
