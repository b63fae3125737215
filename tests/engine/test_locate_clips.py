"""A finding on a value that only value clips hold names the clip's layer and,
in a text clip, the line of its spec (the clip's prim path, not the stage's)."""

from __future__ import annotations

from pathlib import Path

from pxr import Sdf

import usdrender_lint

SHOT = """#usda 1.0

def Scope "Render"
{
    def RenderSettings "Settings"
    {
        rel products = </Render/Beauty>
    }

    def RenderProduct "Beauty" (
        clips = {
            dictionary default = {
                double2[] active = [(1001, 0)]
                asset[] assetPaths = [@./CLIP@]
                string primPath = "/Cache"
                double2[] times = [(1001, 1001), (1002, 1002)]
            }
        }
    )
    {
        DECLARED
    }
}
"""
CLIP = """#usda 1.0

def "Cache"
{
    # the samples
    token productName.timeSamples = {
        1001: "beauty.1001.exr",
    }
}
"""


def _se017(tmp_path: Path, clip: str, declared: str = "") -> tuple[str | None, int | None]:
    text_clip = tmp_path / "clip.usda"
    text_clip.write_text(CLIP)
    if clip.endswith(".usdc"):
        Sdf.Layer.FindOrOpen(str(text_clip)).Export(str(tmp_path / clip))
    shot = tmp_path / "shot.usda"
    shot.write_text(SHOT.replace("CLIP", clip).replace("DECLARED", declared))
    result = usdrender_lint.lint_file(shot, select=["SE017"])
    (finding,) = result.findings
    return finding.location.layer, finding.location.line


def test_a_value_only_a_text_clip_holds_is_found_on_its_line(tmp_path: Path) -> None:
    assert _se017(tmp_path, "clip.usda") == (str(tmp_path / "clip.usda"), 6)


def test_a_declared_attribute_whose_samples_a_clip_holds_points_at_the_clip(
    tmp_path: Path,
) -> None:
    # The stage's declaration holds no value: the samples the finding is about
    # are the clip's.
    assert _se017(tmp_path, "clip.usda", "token productName") == (
        str(tmp_path / "clip.usda"),
        6,
    )


def test_a_crate_clip_is_named_without_a_line(tmp_path: Path) -> None:
    assert _se017(tmp_path, "clip.usdc") == (str(tmp_path / "clip.usdc"), None)


def test_an_authored_default_stays_where_it_is(tmp_path: Path) -> None:
    # A default in the stage outweighs the clip (clips are weaker than the layer
    # stack that names them): the finding on it stays on the stage's line.
    (tmp_path / "clip.usda").write_text(CLIP)
    shot = tmp_path / "shot.usda"
    shot.write_text(SHOT.replace("CLIP", "clip.usda").replace("DECLARED", 'token productName = ""'))
    result = usdrender_lint.lint_file(shot, select=["PR001"])
    (finding,) = result.findings
    assert (finding.location.layer, finding.location.line) == (str(shot), 21)
