"""A layer USD opens only when a value is read (a value clip's manifest) that
does not parse is the file's problem (ST001, as a corrupt crate value is), not
an internal error of whichever rule read a value first; every path says so."""

from __future__ import annotations

import json
from pathlib import Path

from cli_support import invoke_in

import usdrender_lint

SHOT = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings" (
        clips = {
            dictionary default = {
                asset[] assetPaths = [@./clip.usda@]
                asset manifestAssetPath = @./manifest.usda@
                double2[] active = [(0, 0)]
                double2[] times = [(0, 0)]
                string primPath = "/Render/Settings"
            }
        }
    )
    {
    }
}
"""
CLIP = '#usda 1.0\ndef Scope "Render"\n{\n    def RenderSettings "Settings"\n    {\n    }\n}\n'
#: The usda parser wants a new line between a prim's braces and its properties.
BROKEN_MANIFEST = '#usda 1.0\ndef Scope "Render" { def RenderSettings "Settings" { float x } }\n'


def _shot(folder: Path) -> Path:
    (folder / "shot.usda").write_text(SHOT)
    (folder / "clip.usda").write_text(CLIP)
    (folder / "manifest.usda").write_text(BROKEN_MANIFEST)
    return folder / "shot.usda"


def _assert_on_every_path(tmp_path: Path, expected: list[tuple[str, str]]) -> None:
    """The shot's findings from the Python API and three ways of ``check``."""
    api = usdrender_lint.lint_file(tmp_path / "shot.usda")
    assert [(f.code, f.message.replace(f"{tmp_path}/", "")) for f in api.findings] == expected
    for options in (["--jobs", "1", "--timeout", "0"], ["--jobs", "2"], ["--full-composition"]):
        result = invoke_in(
            tmp_path, "check", "--isolated", "--format", "json", *options, "shot.usda", "clip.usda"
        )
        assert result.exit_code == 1, result.output
        document = json.loads(result.stdout)
        (entry,) = [e for e in document["files"] if e["file"] == "shot.usda"]
        found = [(f["code"], f["message"]) for f in entry["findings"]]
        assert found == expected, options


def test_a_clip_manifest_that_does_not_parse_is_st001_on_every_path(tmp_path: Path) -> None:
    _shot(tmp_path)
    expected = [
        (
            "ST001",
            "a layer USD reads for a value does not parse: manifest.usda:2:54: Expected } at "
            "'float x } }' in </Render/Settings>",
        )
    ]
    _assert_on_every_path(tmp_path, expected)


def test_a_clip_manifest_usd_cannot_open_is_st001_on_every_path(tmp_path: Path) -> None:
    # A manifest that is no layer at all (a file of no USD format, a folder)
    # fails in SdfLayer's open, not in a parser: still the file's problem.
    (tmp_path / "shot.usda").write_text(SHOT.replace("manifest.usda", "manifest.txt"))
    (tmp_path / "clip.usda").write_text(CLIP)
    (tmp_path / "manifest.txt").write_text("not a layer\n")
    expected = [
        (
            "ST001",
            "a layer USD reads for a value cannot be opened: "
            "Cannot determine file format for @manifest.txt@",
        )
    ]
    _assert_on_every_path(tmp_path, expected)


#: The shot with a variant set on its render scope, so that --variants lints
#: it once per variant.
VARIANT_SHOT = SHOT.replace(
    'def Scope "Render"\n{',
    'def Scope "Render" (\n    variantSets = "look"\n    variants = { string look = "a" }\n)\n{'
    '\n    variantSet "look" = {\n        "a" {\n        }\n        "b" {\n        }\n    }',
)


def test_a_lazy_layer_error_is_st001_when_a_stage_is_linted_open(tmp_path: Path) -> None:
    # --variants, standard input and lint_stage lint an open stage (run_stage),
    # not a path: they said "internal error: CorruptValue" (exit 2).
    shot = _shot(tmp_path)
    shot.write_text(VARIANT_SHOT)
    expected = [
        (
            "ST001",
            "a layer USD reads for a value does not parse: manifest.usda:2:54: Expected } at "
            "'float x } }' in </Render/Settings>",
        )
    ]
    runs = {
        "variants": invoke_in(
            tmp_path, "check", "--isolated", "--format", "json", "--variants", "shot.usda"
        ),
        "stdin": invoke_in(
            tmp_path,
            "check",
            "--isolated",
            "--format",
            "json",
            "-",
            "--stdin-filename",
            "shot.usda",
            input=VARIANT_SHOT,
        ),
    }
    for how, result in runs.items():
        assert result.exit_code == 1, (how, result.output)
        (entry,) = json.loads(result.stdout)["files"]
        found = [(f["code"], f["message"].replace(f"{tmp_path}/", "")) for f in entry["findings"]]
        assert found == expected, how
    from pxr import Usd

    report = usdrender_lint.lint_stage(Usd.Stage.Open(str(shot)))
    assert [(f.code, f.message.replace(f"{tmp_path}/", "")) for f in report.findings] == expected
