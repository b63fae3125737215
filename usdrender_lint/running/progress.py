"""The progress bar of a long run: on stderr, and only when it is a terminal."""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager

#: A progress bar is worth drawing only for runs longer than this many files.
PROGRESS_MIN_FILES = 20


def want_progress(count: int, asked: bool | None = None) -> bool:
    """``asked``, or when not asked: only a real terminal (never a CI log) and more
    than :data:`PROGRESS_MIN_FILES` files."""
    if asked is not None:
        return asked
    return count > PROGRESS_MIN_FILES and sys.stderr.isatty()


@contextmanager
def progress_bar(total: int, show: bool) -> Iterator[Callable[[], None]]:
    """Yield the function that advances the bar by one file (a no-op unless ``show``)."""
    if not show:
        yield lambda: None
        return
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeRemainingColumn

    columns = ("linting", BarColumn(), MofNCompleteColumn(), TimeRemainingColumn())
    with Progress(*columns, console=Console(stderr=True), transient=True) as bar:
        task = bar.add_task("lint", total=total)
        yield lambda: bar.advance(task)
