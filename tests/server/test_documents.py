"""The server's linting in-process (running/documents.py): the same findings as
the Python API on real files, text ``.usd`` documents, and config ``variants``."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from usdrender_lint import lint_file
from usdrender_lint.running.documents import Documents

pytestmark = pytest.mark.heavy(seconds=11)

VARIANT_SHOT = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "S" (
        variants = {
            string quality = "low"
        }
        prepend variantSets = "quality"
    )
    {
        variantSet "quality" = {
            "high" {
                uniform int2 resolution = (0, 10)
            }
            "low" {
                uniform int2 resolution = (640, 360)
            }
        }
    }
}
"""


def _keys(findings) -> set[tuple]:
    return {(f.code, f.location.path, f.location.line, f.message) for f in findings}


def test_real_files_get_the_findings_of_the_python_api(shared_dir: Path):
    """Every small .usda of the shared corpus, opened as saved: the server's
    findings are the API's (which check's are: tests/running's differential
    test), line for line."""
    files = sorted(
        p for p in (shared_dir / "corpus").rglob("*.usda") if p.stat().st_size < 200_000
    )[:60]
    assert files
    documents = Documents()
    for path in files:
        text = path.read_text(encoding="utf-8", errors="replace")
        documents.update({str(path): text})
        linted = documents.lint(str(path))
        expected = _api_findings(path)
        assert linted.error is None, path
        assert _keys(linted.findings) == expected, path
        documents.update({str(path): None})


def _api_findings(path: Path) -> set[tuple]:
    from usdrender_lint.running.pipeline import Request, prepare

    prepared = prepare(Request((str(path),), jobs=1, timeout=None, progress=False))
    report = lint_file(path, config=prepared.settings)
    return _keys(report.findings)


def test_a_text_usd_document_is_linted_with_its_lines(tmp_path: Path):
    path = str(tmp_path / "shot.usd")  # never saved
    text = '#usda 1.0\ndef RenderSettings "S"\n{\n    uniform int2 resolution = (0, 10)\n}\n'
    documents = Documents()
    documents.update({path: text})
    (finding,) = [f for f in documents.lint(path).findings if f.code == "SE001"]
    assert finding.location.line == 4


def test_config_variants_lints_other_selections_like_check(tmp_path: Path):
    (tmp_path / ".usdrender-lint.toml").write_text("variants = true\n")
    path = tmp_path / "shot.usda"
    path.write_text(VARIANT_SHOT)
    documents = Documents()
    documents.update({str(path): VARIANT_SHOT})
    found = [f for f in documents.lint(str(path)).findings if f.code == "SE001"]
    assert len(found) == 1
    assert "[variant selection: /Render/S{quality=high}]" in found[0].message
    assert found[0].location.line == 13  # the line in the variant
    expected = lint_file(path, config=str(tmp_path / ".usdrender-lint.toml"))
    assert {f.message for f in expected.findings if f.code == "SE001"} == {found[0].message}


@pytest.mark.parametrize("saved", [True, False])
def test_an_edit_is_linted_from_the_buffer(tmp_path: Path, saved: bool):
    path = tmp_path / "shot.usda"
    text = '#usda 1.0\ndef RenderSettings "S"\n{\n    uniform int2 resolution = (0, 10)\n}\n'
    if saved:
        path.write_text(text)
    documents = Documents()
    documents.update({str(path): text})
    assert "SE001" in {f.code for f in documents.lint(str(path)).findings}
    documents.update({str(path): text.replace("(0, 10)", "(10, 10)")})
    assert "SE001" not in {f.code for f in documents.lint(str(path)).findings}
    # Closed: the file (if any) is what other stages see again.
    documents.update({str(path): None})
    assert documents.texts == {}


def test_per_path_ignores_apply_as_in_check(tmp_path: Path):
    (tmp_path / ".usdrender-lint.toml").write_text(
        '[per-path-ignores]\n"shots/*.usda" = ["SE001"]\n'
    )
    (tmp_path / "shots").mkdir()
    text = '#usda 1.0\ndef RenderSettings "S"\n{\n    uniform int2 resolution = (0, 10)\n}\n'
    documents = Documents()
    ignored, kept = str(tmp_path / "shots" / "a.usda"), str(tmp_path / "b.usda")
    documents.update({ignored: text, kept: text})
    assert "SE001" not in {f.code for f in documents.lint(ignored).findings}
    assert "SE001" in {f.code for f in documents.lint(kept).findings}


def test_a_referenced_file_changed_on_disk_is_read_again(tmp_path: Path):
    cams = tmp_path / "cams.usda"
    cams.write_text('#usda 1.0\ndef Xform "rig"\n{\n    def Camera "cam"\n    {\n    }\n}\n')
    text = (
        '#usda 1.0\ndef Xform "World" (\n    references = @./cams.usda@</rig>\n)\n{\n}\n'
        'def RenderSettings "S"\n{\n    rel camera = </World/cam>\n}\n'
    )
    path = str(tmp_path / "shot.usda")
    documents = Documents()
    documents.update({path: text})
    assert "CA003" not in {f.code for f in documents.lint(path).findings}
    before = cams.stat().st_mtime
    cams.write_text('#usda 1.0\ndef Xform "rig"\n{\n}\n')  # the camera is gone
    os.utime(cams, (before + 5, before + 5))  # a later time, whatever the clock's grain
    assert "CA003" in {f.code for f in documents.lint(path).findings}


@pytest.mark.parametrize("arc", ["sublayer", "reference"])
def test_a_composed_file_deleted_renamed_or_created_is_seen_as_check_sees_it(
    tmp_path: Path, arc: str
):
    """The document's stage kept the layer USD had read: a sublayer (or a
    reference) deleted or renamed on disk still gave its findings, where check
    reports it missing (ST002); one created after the stage opened stayed
    missing."""
    layer = tmp_path / "layer.usda"
    layer.write_text(
        '#usda 1.0\nover "Render"\n{\n    over "rs"\n    {\n'
        "        uniform bool instantaneousShutter = 1\n    }\n}\n"
    )
    arcs = {
        "sublayer": ("(\n    subLayers = [@./layer.usda@]\n)\n", ""),
        "reference": ("", " (\n    references = @./layer.usda@</Render>\n)"),
    }
    head, render = arcs[arc]
    text = (
        f'#usda 1.0\n{head}def Scope "Render"{render}\n{{\n'
        '    def RenderSettings "rs"\n    {\n    }\n}\n'
    )
    path = str(tmp_path / "shot.usda")
    Path(path).write_text(text)
    documents = Documents()
    documents.update({path: text})

    def codes() -> set[str]:
        found = {f.code for f in documents.lint(path).findings}
        assert found == {f.code for f in lint_file(path).findings}  # check's
        return found

    assert "SE007" in codes()
    layer.rename(tmp_path / "renamed.usda")
    assert {"ST002"} <= codes() and "SE007" not in codes()
    (tmp_path / "renamed.usda").rename(layer)
    assert "SE007" in codes() and "ST002" not in codes()


def test_a_configuration_file_created_while_open_is_read_by_the_next_lint(tmp_path: Path):
    """Neovim's client watches no files: a .usdrender-lint.toml created while
    the server ran was never read (the defaults stayed until a restart)."""
    text = '#usda 1.0\ndef RenderSettings "S"\n{\n    uniform int2 resolution = (0, 10)\n}\n'
    (tmp_path / "shots").mkdir()
    path = str(tmp_path / "shots" / "shot.usda")
    documents = Documents()
    documents.update({path: text})
    assert "SE001" in {f.code for f in documents.lint(path).findings}
    (tmp_path / ".usdrender-lint.toml").write_text('ignore = ["SE001"]\n')  # a folder above
    assert "SE001" not in {f.code for f in documents.lint(path).findings}


def test_suppress_names_only_registered_rules(tmp_path: Path):
    path = str(tmp_path / "shot.usda")
    text = '#usda 1.0\ndef RenderSettings "S"\n{\n    uniform int2 resolution = (0, 10)\n}\n'
    documents = Documents()
    documents.update({path: text})
    documents.lint(path)
    suppressed = documents.suppress(path, "SE001", "/S.resolution")
    assert suppressed is not None and '"SE001"' in suppressed
    documents.update({path: suppressed})
    assert "SE001" not in {f.code for f in documents.lint(path).findings}
    # A rule that raised (UL000) cannot be silenced in customData.
    assert documents.suppress(path, "UL000", "/S") is None


def test_a_document_nesting_too_deep_for_usd_is_one_finding_then_linted_again(tmp_path: Path):
    """USD's parser overflows its stack on such a text: it is never handed to
    USD (nor the file holding it), and the next text is linted as usual."""
    path = tmp_path / "deep.usda"
    deep = "#usda 1.0\n" + 'def "A" {\n' * 12_000 + "}\n" * 12_000
    path.write_text(deep)  # as saved: the file would be opened instead of the text
    documents = Documents()
    documents.update({str(path): deep})
    [finding] = documents.lint(str(path)).findings
    assert finding.code == "ST001" and "nests 12,000 levels deep" in finding.message
    documents.update({str(path): '#usda 1.0\ndef RenderSettings "S"\n{\n}\n'})
    assert "ST001" not in {f.code for f in documents.lint(str(path)).findings}


def test_config_force_exclude_leaves_a_skipped_document_alone(tmp_path: Path):
    """With ``force-exclude``, a document ``check .`` would skip gets no finding
    and no fix, as ``check --force-exclude -`` of its text."""
    (tmp_path / ".usdrender-lint.toml").write_text(
        'extend-exclude = ["reference/"]\nforce-exclude = true\n'
    )
    text = '#usda 1.0\ndef RenderSettings "S"\n{\n    uniform int2 resolution = (0, 10)\n}\n'
    skipped, kept = str(tmp_path / "reference" / "a.usda"), str(tmp_path / "shots" / "a.usda")
    documents = Documents()
    documents.update({skipped: text, kept: text})
    assert documents.lint(skipped).findings == ()
    run, changed = documents.fix(skipped, None, unsafe=True)
    assert (run.outcomes, changed) == ([], {})
    assert "SE001" in {f.code for f in documents.lint(kept).findings}
    assert documents.fix(kept, None, unsafe=True)[1]  # the same text, kept: fixed
    (tmp_path / ".usdrender-lint.toml").write_text('extend-exclude = ["reference/"]\n')
    documents.forget_configuration()
    assert "SE001" in {f.code for f in documents.lint(skipped).findings}


@pytest.mark.parametrize(
    "arc",
    [
        "(\n    subLayers = [@./broken.usda@]\n)\n",
        '\ndef RenderSettings "W" (\n    references = @./broken.usda@</A>\n)\n{\n}\n',
    ],
    ids=["sublayer", "reference"],
)
def test_an_open_document_usd_cannot_parse_does_not_hide_its_users_errors(tmp_path: Path, arc: str):
    """The wrapper's ST002 (the layer it names does not parse) whether or not that
    layer is open too, as check says it."""
    broken = tmp_path / "broken.usda"
    broken.write_text('#usda 1.0\ndef Scope "A" {\n    int x = \n}\n')
    wrapper = tmp_path / "wrapper.usda"
    wrapper.write_text("#usda 1.0\n" + arc)
    expected = sorted((f.code, f.message) for f in lint_file(wrapper).findings)
    assert "ST002" in {code for code, _ in expected}
    documents = Documents()
    documents.update({str(wrapper): wrapper.read_text(), str(broken): broken.read_text()})
    assert [f.code for f in documents.lint(str(broken)).findings] == ["ST001"]
    for _ in range(2):  # and after the broken document's own lint
        found = sorted((f.code, f.message) for f in documents.lint(str(wrapper)).findings)
        assert found == expected


def test_fix_all_leaves_a_layer_the_configuration_excludes_alone(tmp_path: Path):
    """As ``check --fix``: a sublayer the configuration leaves out of linting is
    not edited through the document that composes it."""
    (tmp_path / ".usdrender-lint.toml").write_text('extend-exclude = ["vendor/"]\n')
    (tmp_path / "vendor").mkdir()
    base = tmp_path / "vendor" / "base.usda"
    base.write_text(
        '#usda 1.0\ndef RenderSettings "S"\n{\n    uniform token aspectRatioConformPolicy'
        ' = "cropaperture"\n}\n'
    )
    shot = str(tmp_path / "shot.usda")
    documents = Documents()
    documents.update({shot: "#usda 1.0\n(\n    subLayers = [@./vendor/base.usda@]\n)\n"})
    assert "SE006" in {f.code for f in documents.lint(shot).findings}
    run, changed = documents.fix(shot, None, unsafe=True)
    assert str(base) not in changed and shot in changed  # the shot's own fix (ST003) is made
    reasons = {o.reason for o in run.outcomes if not o.applied}
    assert any("vendor/base.usda is left out of linting" in (r or "") for r in reasons)


def test_config_variants_makes_no_fix_as_check_fix_refuses(tmp_path: Path):
    """The editor made the fixes check --fix refuses under `variants = true`
    (and the validation plugins do not offer): made under the current variant
    selections only. Same file and configuration through check --fix."""
    import subprocess
    import sys

    repo = Path(__file__).resolve().parents[2]
    for name in ("shot.usda", "lighting_wip.usda"):
        (tmp_path / name).write_text((repo / "examples" / "broken_shot" / name).read_text())
    (tmp_path / ".usdrender-lint.toml").write_text("variants = true\n")
    path = str(tmp_path / "shot.usda")
    refused = subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "check", "--no-cache", "--fix", path],
        capture_output=True,
        text=True,
    )
    assert refused.returncode == 2 and "variants" in refused.stderr
    documents = Documents()
    documents.update({path: (tmp_path / "shot.usda").read_text()})
    linted = documents.lint(path)
    assert linted.findings and all(f.fix is None for f in linted.findings)  # as check reports
    assert documents.fixes(path, None, False) == {}
    assert documents.fixes(path, None, True) == {}
    assert linted.fixes is False  # the server offers no fix-all on it


def test_a_document_closed_unsaved_is_its_file_again_in_the_stages_that_compose_it(
    tmp_path: Path,
):
    """A layer first seen as an unsaved text that its file does not hold is a
    layer USD does not reload from the file: once it was closed, the shot that
    composes it went on showing the findings of the closed document's unsaved
    text, not of its file (seen in the server's stress test)."""
    shot, layer = str(tmp_path / "shot.usda"), tmp_path / "layer.usda"
    layer.write_text(
        '#usda 1.0\ndef RenderSettings "L"\n{\n    uniform int2 resolution = (0, 480)\n}\n'
    )
    unsaved = layer.read_text().replace("(0, 480)", "(640, 480)")
    documents = Documents()
    documents.update(
        {str(layer): unsaved, shot: "#usda 1.0\n(\n    subLayers = [@./layer.usda@]\n)\n"}
    )
    assert not [f for f in documents.lint(shot).findings if f.code == "SE001"]
    documents.update({str(layer): None})
    (found,) = [f for f in documents.lint(shot).findings if f.code == "SE001"]
    assert "(0, 480)" in found.message and found.location.layer == str(layer)


@pytest.mark.parametrize("through_the_link", ["shot", "layer"])
def test_a_layer_s_text_across_a_link_composes_until_it_closes(
    tmp_path: Path, through_the_link: str
) -> None:
    """The layer's unsaved text reaches the shot that composes it by the path on
    the other side of a symlink, follows its edits, and once the document
    closes the shot composes the file again (not the last unsaved text)."""
    real, link = tmp_path / "resolved", tmp_path / "link"
    real.mkdir()
    link.symlink_to(real, target_is_directory=True)
    (real / "shot.usda").write_text(
        '#usda 1.0\n(\n    subLayers = [@./layer.usda@]\n)\ndef Scope "Render"\n{\n'
        '    def RenderSettings "rs"\n    {\n    }\n}\n'
    )
    saved = (
        '#usda 1.0\nover "Render"\n{\n    over "rs"\n    {\n'
        '        uniform token[] materialBindingPurposes = ["full", "preview"]\n    }\n}\n'
    )
    (real / "layer.usda").write_text(saved)
    shot_folder, layer_folder = (link, real) if through_the_link == "shot" else (real, link)
    shot, layer = str(shot_folder / "shot.usda"), str(layer_folder / "layer.usda")

    def se011() -> list[str]:
        return [f.message for f in documents.lint(shot).findings if f.code == "SE011"]

    documents = Documents()
    documents.update({shot: (real / "shot.usda").read_text(), layer: saved})
    assert se011() == []
    documents.update({layer: saved.replace('"preview"', '"bogus"')})
    assert len(se011()) == 1 and "bogus" in se011()[0]
    documents.update({layer: saved.replace('"preview"', '"other"')})
    assert len(se011()) == 1 and "other" in se011()[0]
    documents.update({layer: None})
    assert se011() == []
    assert (real / "layer.usda").read_text() == saved
