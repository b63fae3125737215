"""Report formatters: one protocol, registered through the
``usdrender_lint.formatters`` entry point group like third-party ones."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path
from typing import Protocol, TextIO

from ..model import Report

ENTRY_POINT_GROUP = "usdrender_lint.formatters"


@dataclass(frozen=True)
class FormatOptions:
    show_info: bool = False
    tool_name: str = "usdrender-lint"
    tool_version: str = "0"


class Formatter(Protocol):
    def render(self, report: Report, stream: TextIO, options: FormatOptions) -> None:
        """Write the whole report to ``stream``."""


def available_formatters() -> Mapping[str, metadata.EntryPoint]:
    return {ep.name: ep for ep in metadata.entry_points(group=ENTRY_POINT_GROUP)}


def load_formatter(name: str) -> Formatter:
    """Import only the chosen formatter (rich is loaded only for text)."""
    entry_points = available_formatters()
    if name not in entry_points:
        raise KeyError(name)
    return entry_points[name].load()()


def display_path(path: str | None) -> str:
    """A path relative to the working directory when it is below it."""
    if not path:
        return ""
    try:
        return str(Path(path).resolve().relative_to(Path.cwd().resolve()))
    except (ValueError, OSError):
        return path
