"""The server is an optional extra: the command line never imports it, and
without pygls ``usdrender-lint server`` says what to install."""

from __future__ import annotations

import os
import subprocess
import sys
import tomllib

from conftest import REPO

from usdrender_lint.server import MISSING, NO_STDOUT
from usdrender_lint.server.ranges import apply_edits, statement_span, text_edits


def test_the_command_line_does_not_import_the_server():
    code = (
        "import sys\n"
        "from usdrender_lint.cli import cli\n"
        "from click.testing import CliRunner\n"
        "CliRunner().invoke(cli, ['rules'])\n"
        "loaded = [m for m in sys.modules if m.split('.')[0] in ('pygls', 'lsprotocol')\n"
        "          or m.startswith('usdrender_lint.server')]\n"
        "print(loaded)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_without_the_extra_the_server_says_what_to_install():
    code = (
        "import sys\n"
        "sys.modules['pygls'] = None  # as if not installed\n"
        "from usdrender_lint.cli import main\n"
        "main(['server'])\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 2
    assert out.stderr.strip() == (
        "usdrender-lint: error: the language server needs its [server] extra: "
        "pip install 'pygls>=2.0' 'lsprotocol>=2025.0.0'"
    )


def test_the_packages_named_are_the_extra_s() -> None:
    """What the message says to install is what pyproject.toml's extra requires."""
    extra = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    wanted = extra["optional-dependencies"]["server"]
    assert MISSING.endswith(" ".join(f"'{requirement}'" for requirement in wanted))


def test_a_closed_stdout_is_one_line_and_exit_2() -> None:
    out = subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "server"],
        stdin=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        timeout=60,
        preexec_fn=lambda: os.close(1),  # noqa: PLW1509 - the child only closes a descriptor
    )
    assert (out.returncode, out.stderr) == (2, NO_STDOUT + "\n")


def test_text_edits_are_minimal_and_give_the_new_text():
    old = 'def "A"\n{\n    rel camera = </World/rig>\n}\nend'
    new = 'def "A"\n{\n    rel camera = </World/rig/cam>\n    int x = 1\n}\nend'
    edits = text_edits(old, new)
    assert apply_edits(old, edits) == new
    # One edit, of the characters that differ only (not the whole line).
    assert [(e.span.start, e.span.end, e.text) for e in edits] == [
        ((2, 28), (2, 29), "/cam>\n    int x = 1")
    ]
    # A change at the very end of a text without a final line end.
    assert apply_edits("a\nb", text_edits("a\nb", "a\nc")) == "a\nc"


def test_a_statement_span_is_its_words_on_its_line():
    text = '#usda 1.0\n    def RenderSettings "S" (\n        rel camera = </C>   \n'
    assert statement_span(text, 2).start == (1, 4)
    assert statement_span(text, 2).end == (1, len('    def RenderSettings "S"'))
    assert statement_span(text, 3).end == (2, len("        rel camera = </C>"))
    assert statement_span(text, None).start == (0, 0)
    # An error's column (1-based) starts the span.
    assert statement_span(text, 3, 14).start == (2, 13)
    # A finding's column counts characters (the engine converts USD's bytes:
    # tests/engine/test_parse_error_columns.py): "bogus" is character 36 of this line.
    line = 'def Scope "abcdefg" ( doc = "é🎥相机" bogus = 1 )'
    start = statement_span(f"#usda 1.0\n{line}\n", 2, 36).start
    assert start == (1, line.index("bogus"))


def test_editor_lines_end_where_the_protocol_ends_them():
    from usdrender_lint.server.ranges import editor_lines

    text = "a\r\nb\rc\x0c\u2028\x85d\ne"
    assert editor_lines(text) == ["a\r\n", "b\r", "c\x0c\u2028\x85d\n", "e"]
    assert editor_lines("") == [""]
    # Without those characters too (split another way, for speed).
    assert editor_lines("a\r\nb\rc\n") == ["a\r\n", "b\r", "c\n", ""]
    assert "".join(editor_lines(text)) == text
