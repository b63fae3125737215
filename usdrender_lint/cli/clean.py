"""``usdrender-lint clean``: remove the result caches a check of PATHS uses."""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING, TextIO

import click

from ..paths import display_path, printable
from .options import config_option, isolated_option, setting_options
from .output import EXIT_TOOL_ERROR, ToolError, error, note
from .views import emit, view

if TYPE_CHECKING:
    from ..running.cleaning import Cleaning


@view("clean", "text")
def _text(cleaning: Cleaning, stream: TextIO) -> None:
    if not cleaning.cleared:
        stream.write("No result cache to remove.\n")
    for done in cleaning.cleared:
        what = f"{done.entries} {'entry' if done.entries == 1 else 'entries'}, {_size(done.size)}"
        folder = printable(display_path(str(done.folder)))
        if done.failed:
            stream.write(f"Cleared {folder} ({what}) in part: see the errors below\n")
        elif done.written and not done.kept:
            written = f"{done.written} new {'entry' if done.written == 1 else 'entries'}"
            stream.write(
                f"Cleared {folder} ({what}); kept the folder: a check running meanwhile "
                f"wrote {written} into it\n"
            )
        elif done.kept:
            shown = ", ".join(printable(name) for name in done.kept[:3])
            shown += ", ..." if len(done.kept) > 3 else ""
            stream.write(
                f"Cleared {folder} ({what}); kept the folder: it holds {len(done.kept)} "
                f"other file(s): {shown}\n"
            )
        else:
            stream.write(f"Removed {folder} ({what})\n")


def _size(size: int) -> str:
    if size < 1024:
        return f"{size} bytes"
    return f"{size / 1024:.1f} KiB" if size < 1 << 20 else f"{size / (1 << 20):.1f} MiB"


@click.command("clean")
@click.argument("paths", nargs=-1)
@setting_options("clean")
@config_option("Find the cache as a check with this configuration file would.")
@isolated_option
def clean(
    paths: tuple[str, ...],
    cache_dir: str | None,
    config: tuple[str | None, tuple[str, ...]],
    isolated: bool,
) -> None:
    """Remove the result caches a check of PATHS uses (default: the working
    directory): the project's, and every one below PATHS. Only the cache's own
    files are removed."""
    from ..config import ConfigError
    from ..running.interrupts import deferred

    with deferred():  # USD's imports (not the rules'): a Ctrl-C during them arrives after
        from ..running.cleaning import clean as clean_caches
        from ..running.result_cache import ForeignFolder

    config_file, overrides = config
    try:
        cleaning = clean_caches(
            paths or (".",),
            cache_dir=cache_dir,
            config=config_file,
            config_overrides=overrides,
            isolated=isolated,
        )
    except (ConfigError, ForeignFolder) as exc:
        raise ToolError(str(exc)) from None
    emit("clean", "text", cleaning)
    for line in cleaning.notes:
        note(line)
    for path in cleaning.missing:
        error(f"{path}: no such file or folder")
    failed = [(done.folder, why) for done in cleaning.cleared for why in done.failed]
    for folder, why in failed:
        error(f"{display_path(str(folder))}: cannot remove {why}")
    if cleaning.missing or failed:
        sys.exit(EXIT_TOOL_ERROR)
