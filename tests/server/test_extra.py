"""The server is an optional extra: the command line never imports it, and
without pygls ``usdrender-lint server`` says what to install."""

from __future__ import annotations

import subprocess
import sys

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
        "usdrender-lint: the language server needs the [server] extra: "
        "pip install 'usdrender-lint[server]'"
    )


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
