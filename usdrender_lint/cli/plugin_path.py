"""``usdrender-lint plugin-path``: the UsdValidation plugin's folder."""

from __future__ import annotations

import sys
from typing import TextIO

import click

from .loading import registry
from .output import EXIT_FINDINGS, ToolError, note
from .views import emit, view


@view("plugin-path", "text")
def _text(folder: object, stream: TextIO) -> None:
    stream.write(f"{folder}\n")


@click.command("plugin-path")
@click.option(
    "--write",
    is_flag=True,
    help="(Re)generate plugInfo.json from the registered rules (plugins included).",
)
@click.option(
    "--check", "check_only", is_flag=True, help="Exit 1 when plugInfo.json is out of date."
)
@click.option(
    "--dir",
    "directory",
    type=click.Path(file_okay=False),
    help="Plugin directory to write or check  [default: the one shipped in the package].",
)
def plugin_path(write: bool, check_only: bool, directory: str | None) -> None:
    """Print the UsdValidation plugin directory (for PXR_PLUGINPATH_NAME)."""
    from pathlib import Path

    rules = registry().rules  # USD, with a Ctrl-C during its imports deferred
    from ..usdplugin import (
        PLUG_INFO,
        DeclarationError,
        declared_validators,
        plugin_dir,
        undeclared_rules,
        write_plug_info,
    )

    folder = Path(directory).resolve() if directory else plugin_dir()
    if write:
        try:
            write_plug_info(rules, folder)
        except (OSError, DeclarationError) as exc:
            # The OS's words, as every other write error: the path is named already.
            why = (exc.strerror or exc) if isinstance(exc, OSError) else exc
            raise ToolError(f"{folder}: cannot write plugInfo.json: {why}") from None
    stale = undeclared_rules(rules, folder)
    emit("plugin-path", "text", folder)
    if stale:
        # Say why: a missing or unreadable file is not a list of stale rules.
        if not (folder / PLUG_INFO).is_file():
            why = f"{folder} has no {PLUG_INFO}"
        elif declared_validators(folder) is None:
            why = f"{folder}/{PLUG_INFO} is not JSON declaring the plugin's validators"
        else:
            why = (
                f"{folder}/{PLUG_INFO} does not declare {len(stale)} registered "
                f"rule(s) as they are now ({', '.join(stale)})"
            )
        note(
            f"{why}; run 'usdrender-lint plugin-path --write --dir DIR' and point "
            "PXR_PLUGINPATH_NAME at DIR"
        )
        if check_only:
            sys.exit(EXIT_FINDINGS)
