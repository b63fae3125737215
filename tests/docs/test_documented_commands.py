"""Every ``usdrender-lint`` command line in the README's and the site's code
blocks parses with the real command line: its command, options and their
values exist (shell variables stand for a value such as 1)."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import click
import pytest

from usdrender_lint.cli import cli

REPO = Path(__file__).resolve().parents[2]
PAGES = [REPO / "README.md", *sorted((REPO / "docs").rglob("*.md"))]
_BLOCK = re.compile(r"^( *)```(\w*)[^\n]*\n(.*?)^\1```", re.DOTALL | re.MULTILINE)
_VARIABLE = re.compile(r"\$\{\{[^}]*\}\}|\$\{\w+\}|\$\w+")


def _command_lines() -> list[tuple[str, str]]:
    found = []
    for page in PAGES:
        for _indent, language, body in _BLOCK.findall(page.read_text(encoding="utf-8")):
            if language in ("text", "usda", "toml", "python", "json"):
                continue  # output, layers and code, not command lines
            body = body.replace("\\\n", " ")
            for line in body.splitlines():
                match = re.search(r"(\$\()?(?:^|(?<=[\s:(/-]))usdrender-lint ([a-z-]+)(.*)$", line)
                if match and match.group(2) in cli.commands:
                    rest = match.group(3).split(")")[0] if match.group(1) else match.group(3)
                    found.append((page.relative_to(REPO).as_posix(), match.group(2) + rest))
    return found


COMMANDS = _command_lines()


def test_the_docs_show_command_lines() -> None:
    pages = {page for page, _ in COMMANDS}
    assert {"README.md", "docs/guides/gitlab-ci.md", "docs/guides/render-farm.md"} <= pages


@pytest.mark.parametrize(("page", "line"), COMMANDS)
def test_the_command_line_parses(page: str, line: str) -> None:
    line = _VARIABLE.sub("1", line).split(" | ")[0].split(" > ")[0].split(" && ")[0]
    line = line.rstrip(")\"'")
    words = shlex.split(line, comments=True)
    command = cli.commands[words[0]]
    try:
        # Parses and checks every option and value; runs nothing.
        command.make_context(words[0], words[1:])
    except click.exceptions.Exit:
        pass  # --help
    except click.UsageError as exc:
        pytest.fail(f"{page}: usdrender-lint {line}: {exc.format_message()}")
