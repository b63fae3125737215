"""A text layer named ``.usd`` (USD reads it with the "usd" format, which holds
text or a crate) gets the lines of its findings as a ``.usda`` does, on every
path: the file, the Python API, standard input and the editor's documents."""

from __future__ import annotations

import json
from pathlib import Path

from cli_support import invoke_in

import usdrender_lint
from usdrender_lint.running.documents import Documents

SHOT = """#usda 1.0

def Scope "Render"
{
    def RenderSettings "Settings"
    {
        int2 resolution = (0, 0)
    }
}
"""
#: SE015 on the settings' line, SE001 on the attribute's; ST003 has no line.
LINES = [("SE001", 7), ("SE015", 5), ("ST003", None)]


def _lines(findings) -> list[tuple[str, int | None]]:
    return sorted(((f.code, f.location.line) for f in findings), key=repr)


def test_a_text_usd_file_has_lines_on_every_path(tmp_path: Path) -> None:
    shot = tmp_path / "shot.usd"
    shot.write_text(SHOT)
    assert _lines(usdrender_lint.lint_file(shot).findings) == LINES
    (tmp_path / "shot.usda").write_text(SHOT)
    assert _lines(usdrender_lint.lint_file(tmp_path / "shot.usda").findings) == LINES
    for args in (["shot.usd"], ["--stdin-filename", "shot.usd", "-"]):
        result = invoke_in(tmp_path, "check", "--isolated", "--format", "json", *args, input=SHOT)
        document = json.loads(result.stdout)
        found = [(f["code"], f["line"]) for f in document["files"][0]["findings"]]
        assert sorted(found, key=repr) == LINES, args
    documents = Documents()
    documents.update({str(shot): SHOT})
    assert _lines(documents.lint(str(shot)).findings) == LINES
