"""Changed layers are linted in the stage roots that use them (config ``roots``)."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.config import Settings
from usdrender_lint.model import (
    INTERNAL_ERROR_CODE,
    FileResult,
    Finding,
    Location,
    Report,
    Severity,
)
from usdrender_lint.running.pipeline import make_linter
from usdrender_lint.running.roots import (
    ContextPlan,
    dependencies,
    file_key,
    find_roots,
    plan_from_settings,
    plan_in_context,
)
from usdrender_lint.running.workers import lint_paths

pytestmark = pytest.mark.heavy(seconds=11)

LAYOUT = """#usda 1.0
def Xform "World"
{
    def Camera "cam"
    {
    }
}
"""

#: Points the settings at a camera that only the layout layer defines, and
#: authors a real defect (an inverted data window, SE003).
LIGHTING = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        rel camera = </World/cam>
        uniform float4 dataWindowNDC = (0.8, 0, 0.2, 1)
    }
}
"""

#: A defect authored in the layout layer (SE007) on the lighting layer's prim.
LAYOUT_WITH_DEFECT = (
    LAYOUT
    + """
over "Render"
{
    over "Settings"
    {
        uniform bool instantaneousShutter = 1
    }
}
"""
)

SHOT = """#usda 1.0
(
    renderSettingsPrimPath = "/Render/Settings"
    subLayers = [@./lighting.usda@, @./layout.usda@]
)
"""


def _write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture
def shot(tmp_path: Path) -> Path:
    """A three-layer shot: shots/010/shot.usda sublayers lighting and layout."""
    folder = tmp_path / "shots" / "010"
    _write(folder / "layout.usda", LAYOUT_WITH_DEFECT)
    _write(folder / "lighting.usda", LIGHTING)
    _write(folder / "shot.usda", SHOT)
    _write(tmp_path / ".usdrender-lint.toml", 'roots = ["shots/*/shot.usda"]\n')
    return folder


#: The rules these fixtures are about; rules added later cannot change the outcome.
SELECT = "CA003,SE003,SE007,ST001"


def _check(*args: str) -> tuple[int, dict]:
    result = CliRunner().invoke(cli, ["check", "--format", "json", "--select", SELECT, *args])
    assert result.exit_code in (0, 1), result.output
    return result.exit_code, json.loads(result.stdout)


def _codes(report: dict) -> list[tuple[str, str]]:
    """(code, layer file name) of every finding."""
    return sorted(
        (f["code"], os.path.basename(f["layer"] or ""))
        for entry in report["files"]
        for f in entry["findings"]
    )


def test_changed_lighting_layer_alone_reports_the_layout_camera_missing(shot: Path) -> None:
    _code, report = _check("--no-roots", str(shot / "lighting.usda"))
    assert ("CA003", "lighting.usda") in _codes(report)


def test_changed_lighting_layer_is_linted_in_its_shot(shot: Path) -> None:
    code, report = _check(str(shot / "lighting.usda"))
    # The camera resolves through the layout layer; the real defect authored in
    # the lighting layer is reported; the layout layer's own defect (SE007) is not.
    assert _codes(report) == [("SE003", "lighting.usda")]
    assert code == 1
    [entry] = report["files"]
    assert Path(entry["file"]).resolve() == (shot / "shot.usda").resolve()
    [finding] = entry["findings"]
    assert finding["path"] == "/Render/Settings.dataWindowNDC"
    assert finding["line"] == 7


def test_findings_of_every_changed_layer_are_reported(shot: Path) -> None:
    _code, report = _check(str(shot / "lighting.usda"), str(shot / "layout.usda"))
    assert _codes(report) == [("SE003", "lighting.usda"), ("SE007", "layout.usda")]


def test_a_clean_changed_layer_passes_in_context(shot: Path) -> None:
    _write(shot / "lighting.usda", LIGHTING.replace("(0.8, 0, 0.2, 1)", "(0, 0, 1, 1)"))
    code, report = _check(str(shot / "lighting.usda"))
    assert (code, _codes(report)) == (0, [])


def test_a_changed_file_no_root_uses_is_linted_on_its_own(shot: Path, tmp_path: Path) -> None:
    lone = _write(tmp_path / "props" / "lamp.usda", LIGHTING)
    _code, report = _check(str(lone), str(shot / "lighting.usda"))
    by_file = {os.path.basename(e["file"]): e for e in report["files"]}
    assert sorted(by_file) == ["lamp.usda", "shot.usda"]
    lamp_codes = sorted(f["code"] for f in by_file["lamp.usda"]["findings"])
    assert lamp_codes == ["CA003", "SE003"]


def test_a_layer_shared_by_two_shots_reports_each_finding_once(shot: Path) -> None:
    other = shot.parent / "020"
    _write(other / "layout.usda", LAYOUT)
    _write(other / "shot.usda", SHOT.replace("./lighting.usda", "../010/lighting.usda"))
    _code, report = _check(str(shot / "lighting.usda"))
    assert len(report["files"]) == 2
    assert _codes(report) == [("SE003", "lighting.usda")]


def test_an_unreadable_changed_layer_is_linted_on_its_own(shot: Path) -> None:
    # Its root would only warn and skip the sublayer, hiding the syntax error.
    _write(shot / "lighting.usda", '#usda 1.0\ndef Scope "Render" {\n  oops\n')
    code, report = _check(str(shot / "lighting.usda"))
    assert code == 1
    [entry] = report["files"]
    assert os.path.basename(entry["file"]) == "lighting.usda"
    assert [(f["code"], f["line"]) for f in entry["findings"]] == [("ST001", 3)]


def test_a_missing_sublayer_a_changed_layer_lists_is_reported_in_context(shot: Path) -> None:
    # USD reports it at </> of the shot: ST002 names the layer that lists it,
    # not the root layer, whose findings a lint of the changed layer leaves out.
    header = "#usda 1.0\n(\n    subLayers = [@./lighting_typo.usda@]\n)\n"
    _write(shot / "lighting.usda", LIGHTING.replace("#usda 1.0\n", header, 1))
    result = CliRunner().invoke(
        cli, ["check", "--format", "json", "--select", "ST002", str(shot / "lighting.usda")]
    )
    assert result.exit_code == 1, result.output
    [entry] = json.loads(result.stdout)["files"]
    assert os.path.basename(entry["file"]) == "shot.usda"
    [finding] = entry["findings"]
    assert "lighting_typo.usda@ of layer" in finding["message"]
    assert os.path.basename(finding["layer"]) == "lighting.usda"


def test_tool_problems_in_a_root_are_never_narrowed_away(tmp_path: Path) -> None:
    root, changed = str(tmp_path / "shot.usda"), str(tmp_path / "lighting.usda")
    elsewhere = str(tmp_path / "layout.usda")

    def finding(code: str, layer: str | None) -> Finding:
        return Finding(code, "x", Severity.ERROR, code, Location(root, "/A", layer))

    report = Report(
        (
            FileResult(
                root,
                findings=(
                    finding(INTERNAL_ERROR_CODE, None),
                    finding("ST001", root),
                    finding("SE003", None),
                    finding("SE003", elsewhere),
                    finding("SE007", changed),
                ),
            ),
        )
    )
    plan = ContextPlan({root: frozenset({file_key(changed)})})
    kept = [f.code for f in plan.narrow(report).findings]
    assert kept == [INTERNAL_ERROR_CODE, "ST001", "SE007"]


def test_without_roots_in_config_the_paths_are_linted_alone(shot: Path, tmp_path: Path) -> None:
    (tmp_path / ".usdrender-lint.toml").write_text("", encoding="utf-8")
    _code, report = _check(str(shot / "lighting.usda"))
    assert ("CA003", "lighting.usda") in _codes(report)


def test_roots_globs_are_relative_to_the_config_folder(
    shot: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    settings = Settings(roots=("shots/*/shot.usda",), source=str(tmp_path / ".usdrender-lint.toml"))
    plan = plan_from_settings([str(shot / "lighting.usda")], settings)
    assert plan is not None
    assert [Path(r).resolve() for r in plan.roots] == [(shot / "shot.usda").resolve()]
    assert plan.alone == ()
    assert plan_from_settings([str(shot / "lighting.usda")], Settings()) is None


def test_find_roots_recurses_dedupes_and_skips_folders(shot: Path, tmp_path: Path) -> None:
    (tmp_path / "shots" / "dir.usda").mkdir()
    found = find_roots(["**/shot.usda", "shots/010/shot.usda", "shots/*.usda"], str(tmp_path))
    assert [Path(p).resolve() for p in found] == [(shot / "shot.usda").resolve()]


def test_roots_are_named_relative_to_the_working_directory(
    shot: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path / "shots")
    assert find_roots(["shots/*/shot.usda"], str(tmp_path)) == [os.path.join("010", "shot.usda")]
    (tmp_path / "elsewhere").mkdir()
    monkeypatch.chdir(tmp_path / "elsewhere")
    [outside] = find_roots(["shots/*/shot.usda"], str(tmp_path))
    assert Path(outside).is_absolute()
    assert Path(outside).resolve() == (shot / "shot.usda").resolve()


def test_dependencies_cover_the_layer_stack_and_references(shot: Path) -> None:
    _write(shot / "asset.usda", LAYOUT)
    _write(
        shot / "shot.usda",
        SHOT + 'def "Asset" ( prepend references = @./asset.usda@ ) {}\n',
    )
    names = {os.path.basename(p) for p in dependencies(str(shot / "shot.usda"))}
    assert names == {"shot.usda", "lighting.usda", "layout.usda", "asset.usda"}


def test_dependencies_survive_a_broken_layer_in_an_unselected_variant(shot: Path) -> None:
    # UsdUtils.ComputeAllDependencies raises for the whole root here, although
    # the stage opens fine (the variant is not selected).
    _write(shot / "broken.usda", '#usda 1.0\ndef "X" {\n  oops\n')
    _write(
        shot / "shot.usda",
        SHOT
        + """
def "Asset" (
    variants = {
        string v = "a"
    }
    prepend variantSets = "v"
)
{
    variantSet "v" = {
        "a" {}
        "b" ( prepend references = @./broken.usda@ ) {}
    }
}
""",
    )
    names = {os.path.basename(p) for p in dependencies(str(shot / "shot.usda"))}
    assert names == {"shot.usda", "lighting.usda", "layout.usda", "broken.usda"}
    _code, report = _check(str(shot / "lighting.usda"))
    assert _codes(report) == [("SE003", "lighting.usda")]


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_dependencies_walk_past_a_named_pipe_without_opening_it(shot: Path) -> None:
    """USD's walk would wait on the pipe forever: ours names it and goes on to the
    other layers, a reference inside a package included."""
    import zipfile

    os.mkfifo(shot / "pipe.usda")
    with zipfile.ZipFile(shot / "asset.usdz", "w", zipfile.ZIP_STORED) as package:
        # An absolute path out of the package: found only by opening its layer.
        package.writestr(
            "asset.usda", f"#usda 1.0\n(\n    subLayers = [@{shot / 'deeper.usda'}@]\n)\n"
        )
    _write(shot / "deeper.usda", LAYOUT)
    _write(
        shot / "shot.usda",
        SHOT.replace("subLayers = [", "subLayers = [@./pipe.usda@, ", 1)
        + 'def "Asset" ( prepend references = @./asset.usdz[asset.usda]@ ) {}\n',
    )
    found = dependencies(str(shot / "shot.usda"))
    names = {os.path.basename(p) for p in found}
    assert names == {
        "shot.usda",
        "pipe.usda",
        "lighting.usda",
        "layout.usda",
        "asset.usdz",
        "deeper.usda",
    }


def test_the_plan_narrows_a_report_to_the_changed_layers(shot: Path) -> None:
    lighting, root = str(shot / "lighting.usda"), str(shot / "shot.usda")
    plan = plan_in_context([lighting], [root])
    assert plan.files == [root]
    full = Report(
        lint_paths(plan.files, linter=make_linter(Settings(select=tuple(SELECT.split(",")))))
    )
    assert {f.code for f in full.findings} >= {"SE003", "SE007"}
    narrowed = plan.narrow(full)
    assert [(f.code, f.location.file) for f in narrowed.findings] == [("SE003", root)]


def test_file_key_maps_a_packaged_layer_to_its_package(tmp_path: Path) -> None:
    package = tmp_path / "asset.usdz"
    assert file_key(f"{package}[inner/layer.usda]") == file_key(str(package))
    assert file_key(str(tmp_path / "a" / ".." / "b.usda")) == file_key(str(tmp_path / "b.usda"))


def test_a_folder_reports_every_layer_of_its_shots_once(shot: Path, tmp_path: Path) -> None:
    # Deleting the camera in layout.usda breaks the lighting layer's relationship:
    # a run on the layout change alone cannot see it, a run on the folder does.
    _write(shot / "layout.usda", LAYOUT_WITH_DEFECT.replace('"cam"', '"renamedCam"'))
    _code, alone = _check(str(shot / "layout.usda"))
    assert _codes(alone) == [("SE007", "layout.usda")]
    _code, report = _check(str(tmp_path))
    [entry] = report["files"]
    assert os.path.basename(entry["file"]) == "shot.usda"
    assert _codes(report) == [
        ("CA003", "lighting.usda"),
        ("SE003", "lighting.usda"),
        ("SE007", "layout.usda"),
    ]


def test_a_real_shot_from_the_corpus(shared_dir: Path) -> None:
    # arnold-usd's test_1814: the root authors RenderSettings and camera and
    # sublayers ./sublayers/{animation,asset}.usda.
    data = shared_dir / "corpus" / "files" / "Autodesk__arnold-usd" / "testsuite" / "test_1814"
    root = data / "data" / "test.usda"
    if not root.is_file():
        pytest.skip(f"{root} is not in the corpus")
    asset = root.parent / "sublayers" / "asset.usda"
    assert {file_key(str(asset)), file_key(str(root))} <= dependencies(str(root))

    linter = make_linter(Settings())
    full = Report(lint_paths([str(root)], linter=linter))
    in_root = {f for f in full.findings if file_key(f.location.layer or "") == file_key(str(root))}
    assert in_root  # the root layer authors findings of its own

    plan = plan_in_context([str(asset)], [str(root)])
    assert (plan.files, plan.alone) == ([str(root)], ())
    assert plan.narrow(Report(lint_paths(plan.files, linter=linter))).findings == ()

    plan = plan_in_context([str(root), str(asset)], [str(root)])
    changed = {file_key(str(root)), file_key(str(asset))}
    expected = {f for f in full.findings if file_key(f.location.layer or "") in changed}
    assert (
        set(plan.narrow(Report(lint_paths(plan.files, linter=linter))).findings)
        == expected
        >= in_root
    )


LAYOUT_SHOT = """#usda 1.0
(
    renderSettingsPrimPath = "/Render/S"
    subLayers = [@../../seq/lighting.usda@]
)
over "Render"
{
    over "S"
    {
        uniform bool instantaneousShutter = false
    }
}
"""
LIGHTING_LAYER = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "S"
    {
        uniform token aspectRatioConformPolicy = "expandaperture"
        uniform int2 resolution = (1920, 1080)
    }
}
"""


@pytest.mark.parametrize("timeout", ["0", "60"], ids=["in-process", "in-a-worker"])
def test_fix_with_roots_fixes_only_what_it_reports(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, timeout: str
) -> None:
    """A pre-commit fix of a changed layer: its own findings are fixed, the shot
    that uses it (not given) is not touched, whatever it holds."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / ".usdrender-lint.toml").write_text('roots = ["shots/*/shot.usda"]\n')
    shot = _write(tmp_path / "shots/010/shot.usda", LAYOUT_SHOT)
    lighting = _write(tmp_path / "seq/lighting.usda", LIGHTING_LAYER)
    args = ["check", "--no-cache", "--timeout", timeout, "--select", "SE006,SE007"]
    before = CliRunner().invoke(cli, [*args, "--format", "json", "seq/lighting.usda"])
    reported = json.loads(before.stdout)["files"][0]["findings"]
    assert [(f["code"], f["layer"]) for f in reported] == [("SE006", "seq/lighting.usda")]
    result = CliRunner().invoke(cli, [*args, "--fix", "seq/lighting.usda"])
    assert result.exit_code == 0, result.output
    assert "1 fix applied" in result.stdout
    assert shot.read_text() == LAYOUT_SHOT
    assert '"expandAperture"' in lighting.read_text()
    # The shot's own finding, which the check of the layer did not report, stays.
    alone = CliRunner().invoke(cli, [*args, "--format", "json", "shots/010/shot.usda"])
    assert "SE007" in {f["code"] for f in json.loads(alone.stdout)["files"][0]["findings"]}


def test_a_roots_glob_that_matches_no_file_is_noted(shot: Path, tmp_path: Path) -> None:
    """Before, a mistyped root ("shots/*/shots.usda", or the folder "shots/") said
    nothing, and every changed layer was linted out of its stage."""
    config = _write(
        tmp_path / ".usdrender-lint.toml", 'roots = ["shots/*/shot.usda", "shots/", "x/*.usda"]\n'
    )
    result = CliRunner().invoke(cli, ["check", "--select", SELECT, str(shot / "lighting.usda")])
    assert result.exit_code == 1, result.output
    notes = [line for line in result.stderr.splitlines() if "matches no file" in line]
    assert notes == [
        f"usdrender-lint: note: {config}: roots: {pattern!r} matches no file below {tmp_path}: "
        "changed layers no root uses are linted on their own"
        for pattern in ("shots/", "x/*.usda")
    ]
