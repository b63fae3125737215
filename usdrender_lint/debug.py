"""``USDRENDER_LINT_DEBUG=1``: the traceback of every internal error on stderr.

An internal error is reported as one line (a file's error, a rule's UL000, a
fix not applied) and the run goes on; with the variable set, its traceback is
printed too, wherever it happened: in this process, in the supervised child,
or in a worker process, whose own stderr is a log read for crash messages
(:func:`keep_stderr` keeps a copy of the real one before that)."""

from __future__ import annotations

import os
import sys

ENV = "USDRENDER_LINT_DEBUG"

#: In a worker process: the stderr it was started with.
_stderr_fd: int | None = None


def enabled() -> bool:
    return bool(os.environ.get(ENV))


def keep_stderr() -> None:
    """In a worker, before its fd 2 is pointed elsewhere: keep the real one."""
    global _stderr_fd
    if enabled() and _stderr_fd is None:
        _stderr_fd = os.dup(2)


def show(exc: BaseException, what: str) -> None:
    """With the variable set, print ``exc``'s traceback, saying what it cost."""
    if not enabled():
        return
    # Imported only to print one: traceback imports textwrap, and a run
    # without the variable (or without an error) needs neither.
    import traceback

    from .atomic import write_all

    text = f"usdrender-lint: debug: {what}\n" + "".join(traceback.format_exception(exc))
    try:
        if _stderr_fd is None and sys.stderr is not None:
            sys.stderr.flush()
        write_all(2 if _stderr_fd is None else _stderr_fd, text.encode("utf-8", "replace"))
    except OSError:
        pass  # stderr is gone: nothing to print on
