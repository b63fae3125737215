"""Every asset path a stage can name, through the result cache: each is keyed
exactly or makes the result uncacheable, and never turns a lint into an error
(issue 24, item 1: an internal reference in a stage with a composition error
made the default, cached run an internal error while ``--no-cache`` worked).

The stages are ``fixtures/hostile_composition``: each composes with an error
somewhere (a missing layer), which is what makes the engine list every arc's
asset path, and names one kind of hostile asset path."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner
from pxr import Sdf

from usdrender_lint.cli import cli
from usdrender_lint.engine.assets import Reads, Unkeyable, arc_target
from usdrender_lint.model import INTERNAL_ERROR_CODE
from usdrender_lint.running import result_cache

FIXTURES = Path(__file__).parent / "fixtures" / "hostile_composition"

#: The stages whose results are keyed exactly (stored), and those whose asset
#: paths name no file the cache can check (never stored, always linted).
KEYED = {
    "internal_reference.usda",
    "internal_payload.usda",
    "empty_sublayer.usda",
    "missing_inside_payload.usda",
    "nested_internal_reference.usda",
    "search_path_missing.usda",
    "package_member_missing.usda",
    "format_arguments.usda",
}
UNCACHEABLE = {
    "anonymous_layer.usda",
    "omniverse_uri.usda",
    "https_uri.usda",
    "expression_variables.usda",
}


@pytest.fixture
def stages(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.delenv("USDRENDER_LINT_NO_CACHE", raising=False)
    monkeypatch.delenv("PXR_AR_DEFAULT_SEARCH_PATH", raising=False)
    shutil.copytree(FIXTURES, tmp_path / "stages")
    monkeypatch.chdir(tmp_path)
    return tmp_path / "stages"


def lint(*options: str) -> dict[str, list[dict]]:
    """Each stage's findings from one run of the command (all stages at once)."""
    args = ["check", "--isolated", "--format", "json", "--fail-on", "never", "--jobs", "1"]
    result = CliRunner().invoke(cli, [*args, *options, "stages"])
    assert result.exit_code == 0, result.output
    files = json.loads(result.stdout)["files"]
    assert all(f["status"] == "linted" for f in files), files
    return {Path(f["file"]).relative_to("stages").as_posix(): f["findings"] for f in files}


def test_the_fixture_set_names_every_kind_of_hostile_asset_path() -> None:
    assert {p.name for p in FIXTURES.glob("*.usda")} == KEYED | UNCACHEABLE


def test_cold_warm_and_uncached_runs_give_the_same_findings(stages: Path) -> None:
    cold = lint("--cache-dir", "cache")
    warm = lint("--cache-dir", "cache")
    uncached = lint("--no-cache")
    assert set(uncached) >= KEYED | UNCACHEABLE  # and the assets they name
    for name, findings in uncached.items():
        assert findings or name.startswith("assets/"), f"{name}: its settings have findings"
        assert not any(f["code"] == INTERNAL_ERROR_CODE for f in findings), findings
        assert cold[name] == findings, f"{name}: the cold cached run differs from --no-cache"
        assert warm[name] == findings, f"{name}: the warm cached run differs from --no-cache"
    stored = {
        Path(json.loads(entry.read_text())["file"]).relative_to("stages").as_posix()
        for entry in (Path("cache") / result_cache.ENTRIES_DIR).glob("*.json")
    }
    assert stored >= KEYED and not UNCACHEABLE & stored


def test_every_asset_path_is_a_file_none_or_unkeyable(tmp_path: Path) -> None:
    anchor = Sdf.Layer.CreateNew(str(tmp_path / "anchor.usda"))
    assert arc_target(anchor, "") is None  # an internal reference or payload
    assert arc_target(anchor, "./a.usda") == str(tmp_path / "a.usda")
    assert arc_target(anchor, "./p.usdz[x.usda]") == f"{tmp_path / 'p.usdz'}[x.usda]"
    assert arc_target(anchor, "./a.usda:SDF_FORMAT_ARGS:x=y") == str(tmp_path / "a.usda")
    for hostile in (
        "omniverse://localhost/a.usd",
        "https://example.com/a.usda",
        "anon:0x1:a.usda",
        '`"./{X}.usda"`',
    ):
        with pytest.raises(Unkeyable):
            arc_target(anchor, hostile)
    reads = Reads()
    reads.add_target(anchor, "")
    assert reads.targets == [] and reads.complete
    reads.add_target(anchor, "omniverse://localhost/a.usd")
    assert not reads.complete
