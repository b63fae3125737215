"""A parse error's column counts characters, as editors and reports mark them:
USD's parser counts bytes, which past an "é" or an emoji are more."""

from __future__ import annotations

import json
from pathlib import Path

from tests.cli_support import invoke_in
from usdrender_lint.running.documents import Documents

#: "]" is character 33 of line 2, byte 35 (two "é" of two bytes each before it).
BROKEN = '#usda 1.0\ndef Scope "Rénder" ( kind = "é" ] )\n{\n}\n'
#: ")" is character 42, byte 46 (an "é" of two bytes, a "🎬" of four).
BROKEN_EMOJI = '#usda 1.0\ndef Scope "R" { custom string a = "é🎬" ; ) }\n'


def _columns(folder: Path, name: str, *options: str) -> list[tuple[int, int]]:
    result = invoke_in(folder, "check", "--isolated", "--no-cache", "--format", "json", name)
    findings = json.loads(result.output)["files"][0]["findings"]
    return [(f["line"], f["column"]) for f in findings]


def test_the_column_counts_characters_in_every_format(tmp_path: Path) -> None:
    (tmp_path / "b.usda").write_text(BROKEN)
    (tmp_path / "e.usda").write_text(BROKEN_EMOJI)
    assert _columns(tmp_path, "b.usda") == [(2, 33)]
    assert _columns(tmp_path, "e.usda") == [(2, 42)]
    text = invoke_in(tmp_path, "check", "--isolated", "--no-cache", "b.usda").output
    assert text.startswith("b.usda:2:33: error ST001")
    full = invoke_in(tmp_path, "check", "--isolated", "--no-cache", "--format", "full", "b.usda")
    source, marks = full.output.splitlines()[2:4]  # one column a character on this line
    assert source[marks.index("^")] == "]"
    options = ("--isolated", "--no-cache", "--format", "sarif")
    sarif = json.loads(invoke_in(tmp_path, "check", *options, "e.usda").output)
    [run] = sarif["runs"]
    assert run["columnKind"] == "unicodeCodePoints"
    assert run["results"][0]["locations"][0]["physicalLocation"]["region"]["startColumn"] == 42


def test_an_editor_s_unsaved_text_is_counted_in_its_own_characters(tmp_path: Path) -> None:
    path = tmp_path / "b.usda"
    path.write_text("#usda 1.0\n")  # the file on disk holds no error
    documents = Documents()
    documents.update({str(path): BROKEN_EMOJI})
    [finding] = documents.lint(str(path)).findings
    assert (finding.location.line, finding.location.column) == (2, 42)
