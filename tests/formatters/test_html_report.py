"""``--format html``: one self-contained page (tests/formatters/test_html_browser.py
looks at it in a real browser)."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from html_support import strict_problems

pytestmark = pytest.mark.heavy(seconds=46)

REPO = Path(__file__).parents[2]
BIN = Path(sys.executable).parent / "usdrender-lint"


def _run(*args: str, cwd: Path = REPO) -> subprocess.CompletedProcess:
    return subprocess.run([str(BIN), *args], capture_output=True, text=True, cwd=cwd, check=False)


@pytest.fixture(scope="module")
def examples_page() -> str:
    run = _run("check", "--format", "html", "examples")
    assert run.returncode == 1, run.stderr
    return run.stdout


def test_the_page_is_well_formed_and_fetches_nothing(examples_page: str) -> None:
    problems, fetches = strict_problems(examples_page)
    assert problems == []
    assert fetches == []
    assert "default-src 'none'" in examples_page  # the browser may not fetch either
    assert not re.search(r"(?i)(src|href)\s*=\s*[\"']?(https?:)?//", examples_page)


def test_findings_carry_source_lines_fix_diffs_and_profile(examples_page: str) -> None:
    # CA004 at shot.usda:32, with the lines around it and the line itself marked.
    ca004 = examples_page[examples_page.index('data-code="CA004"') :]
    ca004 = ca004[: ca004.index("</li>")]
    assert '<span class="hit"><i>32</i>        rel camera = &lt;/World/camRig&gt;</span>' in ca004
    assert "<i>29</i>" in ca004 and "<i>35</i>" in ca004
    # Its fix as a diff: --fix's edit.
    assert '<span class="d-del">-        rel camera = &lt;/World/camRig&gt;</span>' in ca004
    assert '<span class="d-add">+        rel camera = &lt;/World/camRig/shotCam&gt;</span>' in ca004
    assert "profile generic" in ca004
    # An unsafe fix is shown as such, with its diff too.
    se003 = examples_page[examples_page.index('data-code="SE003"') :]
    assert "unsafe fix (--unsafe-fixes)" in se003[: se003.index("</li>")]
    # The profile and why, once per RenderSettings.
    assert 'profile <b>generic</b> <span class="dim">(auto: no renderer' in examples_page
    # A file USD cannot open: its ST001, no picture.
    assert "lighting_wip.usda" in examples_page and 'data-code="ST001"' in examples_page


def test_every_product_has_its_framing_picture_and_findings_beside_it(examples_page: str) -> None:
    spec = json.loads(_run("spec", "--format", "json", "examples").stdout)
    products = sum(
        max(1, len(s["products"]))
        for f in spec["files"]
        if f["status"] == "computed"
        for s in f["settings"]
    )
    assert examples_page.count('<figure class="product" id=') == products
    assert examples_page.count("<svg ") == products
    crop = examples_page[examples_page.index("<h3>/Render/Products/crop</h3>") :]
    crop = crop[: crop.index("</figure>")]
    assert {"CA003", "SE003", "SE007"} <= set(re.findall(r"<b>([A-Z]{2}\d{3})</b>", crop))
    assert 'href="#f' in crop  # each links to the finding below


def test_filters_list_the_codes_and_profiles_present(examples_page: str) -> None:
    codes = set(re.findall(r'<option value="([A-Z]{2}\d{3})">', examples_page))
    assert codes == set(
        re.findall(r'<li class="finding"[^>]* data-code="([A-Z]{2}\d{3})"', examples_page)
    )
    assert '<option value="generic">' in examples_page
    for severity in ("error", "warning", "info"):
        assert f'name="severity" value="{severity}" checked' in examples_page


def test_merge_html_of_shard_reports(tmp_path: Path) -> None:
    shards = []
    for k in (1, 2):
        run = _run("check", "--format", "json", "--shard", f"{k}/2", "examples")
        assert run.returncode in (0, 1), run.stderr
        shard = tmp_path / f"shard{k}.json"
        shard.write_text(run.stdout)
        shards.append(str(shard))
    here = _run("merge", "--format", "html", *shards)
    assert here.returncode == 1, here.stderr
    whole = _run("check", "--format", "html", "examples").stdout
    assert here.stdout.count('class="finding"') == whole.count('class="finding"')
    assert here.stdout.count("<svg ") == whole.count("<svg ")  # the files are here: read them
    # Elsewhere (the files are not there): the findings, and a note on what is missing.
    away = _run("merge", "--format", "html", *shards, cwd=tmp_path)
    assert away.returncode == 1, away.stderr
    assert away.stdout.count('class="finding"') == whole.count('class="finding"')
    assert "<svg " not in away.stdout and 'class="diff"' not in away.stdout
    assert "are not on disk here" in away.stdout
    assert strict_problems(away.stdout) == ([], [])


def test_the_report_shows_the_fixes_of_a_read_only_file(tmp_path: Path) -> None:
    """The report writes nothing, so a read-only file's fixes are shown as diffs
    (--diff, a preview of --fix, says --fix would refuse to write it)."""
    work = tmp_path / "shot.usda"
    shutil.copy(REPO / "examples" / "broken_shot" / "shot.usda", work)
    os.chmod(work, 0o444)
    page = _run("check", "--format", "html", "shot.usda", cwd=tmp_path).stdout
    assert page.count('class="diff"') == 3
    assert '<span class="d-add">+        rel camera = &lt;/World/camRig/shotCam&gt;</span>' in page
    assert work.read_text() == (REPO / "examples" / "broken_shot" / "shot.usda").read_text()
    assert "read-only" in _run("check", "--diff", "shot.usda", cwd=tmp_path).stderr


def test_a_file_name_that_is_not_utf8_gives_a_valid_page(tmp_path: Path) -> None:
    name = os.fsencode(tmp_path) + b"/sh\xffot.usda"
    shutil.copy(REPO / "examples" / "broken_shot" / "shot.usda", name)
    run = subprocess.run(
        [str(BIN), "check", "--format", "html", "."],
        capture_output=True,
        cwd=tmp_path,
        check=False,
    )
    assert run.returncode == 1, run.stderr
    page = run.stdout.decode("utf-8")  # strict: valid UTF-8
    assert '<span class="path">sh\\xffot.usda</span>' in page
    assert page.count('class="finding"') == 5


def _profiles_shown(page: str) -> set[str]:
    return set(
        re.findall(r'class="profile">RenderSettings <code>[^<]*</code>: profile <b>(\w+)</b>', page)
    )


@pytest.fixture
def configured_show(tmp_path: Path) -> Path:
    """A show whose own configuration sets a profile and ignores the fixable CA004."""
    show = tmp_path / "show"
    show.mkdir()
    shutil.copy(REPO / "examples" / "broken_shot" / "shot.usda", show / "shot.usda")
    (show / ".usdrender-lint.toml").write_text('profile = "karma"\nignore = ["CA004"]\n')
    (tmp_path / "other.toml").write_text('profile = "arnold"\n')
    return show


CA004_DIFF = '<span class="d-add">+        rel camera = &lt;/World/camRig/shotCam&gt;</span>'


def test_the_pictures_and_diffs_read_the_files_with_the_runs_configuration(
    configured_show: Path,
) -> None:
    """The page's profiles and fix diffs come from the configuration that linted
    the files: the nearest one, or --config, --isolated and the flags when given."""
    nearest = _run("check", "--format", "html", "show", cwd=configured_show.parent).stdout
    assert _profiles_shown(nearest) == {"karma"}
    assert 'data-code="CA004"' not in nearest
    isolated = _run("check", "--isolated", "--format", "html", "show", cwd=configured_show.parent)
    assert _profiles_shown(isolated.stdout) == {"generic"}
    assert 'data-code="CA004"' in isolated.stdout and CA004_DIFF in isolated.stdout
    other = _run(
        "check", "--config", "other.toml", "--format", "html", "show", cwd=configured_show.parent
    )
    assert _profiles_shown(other.stdout) == {"arnold"}
    assert CA004_DIFF in other.stdout
    flag = _run(
        "check", "--profile", "renderman", "--format", "html", "show", cwd=configured_show.parent
    )
    assert _profiles_shown(flag.stdout) == {"renderman"}
    assert 'data-code="CA004"' not in flag.stdout


def test_merge_html_reads_the_files_with_the_configuration_asked_for(configured_show: Path) -> None:
    cwd = configured_show.parent
    shard = cwd / "shard.json"
    shard.write_text(_run("check", "--isolated", "--format", "json", "show", cwd=cwd).stdout)
    isolated = _run("merge", "--isolated", "--format", "html", str(shard), cwd=cwd).stdout
    assert _profiles_shown(isolated) == {"generic"}
    assert CA004_DIFF in isolated
    other = _run("merge", "--config", "other.toml", "--format", "html", str(shard), cwd=cwd).stdout
    assert _profiles_shown(other) == {"arnold"}
    # Without either, each file's nearest configuration, as check would lint it, with
    # the inline settings given laid over it.
    nearest = _run("merge", "--format", "html", str(shard), cwd=cwd).stdout
    assert _profiles_shown(nearest) == {"karma"}
    inline = ("--config", 'severity.SE003 = "info"')
    page = _run("merge", *inline, "--format", "html", str(shard), cwd=cwd).stdout
    assert _profiles_shown(page) == {"karma"}


def test_a_split_runs_page_shows_each_file_under_its_own_configuration(
    configured_show: Path,
) -> None:
    second = configured_show.parent / "second"
    second.mkdir()
    shutil.copy(configured_show / "shot.usda", second / "shot.usda")
    (second / ".usdrender-lint.toml").write_text('profile = "arnold"\n')
    page = _run("check", "--format", "html", ".", cwd=configured_show.parent).stdout
    sections = page.split('<section class="file"')[1:]
    assert len(sections) == 2
    shown = {
        re.search(r'<span class="path">(\w+)/shot.usda</span>', section)[1]: _profiles_shown(
            section
        )
        for section in sections
    }
    assert shown == {"second": {"arnold"}, "show": {"karma"}}
    assert page.count(CA004_DIFF) == 1  # the show ignores CA004; the second folder does not


#: SE012 quotes the token: an ESC that would colour a terminal.
ESCAPING = r"""#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        token renderingColorSpace = "lin\x1b[31m\x7f"
    }
}
"""


def test_names_and_messages_show_their_controls_escaped(tmp_path: Path) -> None:
    """As the text report prints them: a bidirectional control or a newline in
    a file name (headings, labels, pictures) and an ESC in a message."""
    name = "sh\u202eot\nx.usda"
    shutil.copy(REPO / "examples" / "framing_shot" / "shot.usda", tmp_path / name)
    (tmp_path / "colour.usda").write_text(ESCAPING)
    run = _run("check", "--isolated", "--format", "html", ".", cwd=tmp_path)
    assert run.returncode == 0, run.stderr  # SE012 is a warning
    page = run.stdout
    assert strict_problems(page) == ([], [])
    assert not re.search("[\x00-\x08\x0b-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]", page)
    assert '<span class="path">sh\\u202eot\\nx.usda</span>' in page
    assert 'aria-label="sh\\u202eot\\nx.usda"' in page
    assert "lin\\x1b[31m\\x7f" in page
    assert page.count('<figure class="product"') >= 1


def test_fix_diffs_stop_at_a_bounded_cost_on_a_large_stage(tmp_path: Path, monkeypatch) -> None:
    """Each diff lints its whole stage twice: a large stage with many fixes is
    shown with the diffs that fit MAX_DIFF_PRIMS, and a note, not after minutes."""
    from usdrender_lint.report_json import report_from_dict
    from usdrender_lint.running import report_views

    settings = "\n".join(
        f'    def RenderSettings "S{i}"\n    {{\n'
        "        uniform float4 dataWindowNDC = (1, 0, 0, 1)\n    }"
        for i in range(30)
    )
    (tmp_path / "big.usda").write_text(f'#usda 1.0\ndef Scope "Render"\n{{\n{settings}\n}}\n')
    run = _run(
        "check", "--isolated", "--select", "SE003", "--format", "json", "big.usda", cwd=tmp_path
    )
    report = report_from_dict(json.loads(run.stdout))
    fixable = [f for f in report.findings if f.fix]
    assert len(fixable) == 30
    monkeypatch.chdir(tmp_path)
    # The stage has 31 prims: 100 prims linted is 3 diffs.
    monkeypatch.setattr(report_views, "MAX_DIFF_PRIMS", 100)
    views = report_views.gather(report)
    assert len(views.files["big.usda"].diffs) == 3
    # One note, with the number of diffs the page shows.
    (note,) = [n for n in views.notes if "diffs" in n]
    assert note.startswith("30 findings have fixes: 3 are shown as diffs") and "--diff" in note
    assert report_views.gather(report).files["big.usda"].diffs == views.files["big.usda"].diffs
    # Both limits at once: two notes had said "the first 2 are shown" and
    # "N not shown" of a page that showed fewer.
    monkeypatch.setattr(report_views, "MAX_DIFFS", 5)
    views = report_views.gather(report)
    assert len(views.files["big.usda"].diffs) == 3
    (note,) = [n for n in views.notes if "diffs" in n]
    assert note.startswith("30 findings have fixes: 3 are shown as diffs")
    assert "the first 5 fixes at most, and no more than 100 prims linted" in note


def _many_settings(folder: Path, count: int):
    """The report of a stage of ``count`` RenderSettings judged alike, each with
    an inverted data window, and the working directory to render it from."""
    from usdrender_lint.report_json import report_from_dict

    settings = "\n".join(
        f'    def RenderSettings "S{i}"\n    {{\n'
        "        uniform float4 dataWindowNDC = (1, 0, 0, 1)\n    }"
        for i in range(count)
    )
    (folder / "big.usda").write_text(f'#usda 1.0\ndef Scope "Render"\n{{\n{settings}\n}}\n')
    run = _run("check", "--isolated", "--format", "json", "big.usda", cwd=folder)
    return report_from_dict(json.loads(run.stdout))


def _page_of(report, monkeypatch, folder: Path) -> str:
    from usdrender_lint.formatters import FormatOptions
    from usdrender_lint.formatters.html import render_page
    from usdrender_lint.running import report_views

    monkeypatch.chdir(folder)
    monkeypatch.setattr(report_views, "MAX_DIFFS", 0)  # no diffs: not what is tested here
    return render_page(report, report_views.gather(report), FormatOptions())


def test_settings_judged_alike_share_one_profile_line(tmp_path: Path, monkeypatch) -> None:
    """A stage of 1,500 RenderSettings had 1,500 identical profile lines above
    its first finding: settings with the same profile and reason share one."""
    page = _page_of(_many_settings(tmp_path, 8), monkeypatch, tmp_path)
    lines = re.findall(r'<p class="profile">(.*?)</p>', page)
    assert len(lines) == 1
    names = ", ".join(f"<code>/Render/S{i}</code>" for i in range(5))
    assert lines[0].startswith(f"8 RenderSettings, {names} and 3 more: profile <b>generic</b>")
    few = _page_of(_many_settings(tmp_path, 2), monkeypatch, tmp_path)
    (line,) = re.findall(r'<p class="profile">(.*?)</p>', few)
    assert line.startswith(
        "RenderSettings <code>/Render/S0</code>, <code>/Render/S1</code>: profile <b>generic</b>"
    )


def test_framing_pictures_stop_at_a_bounded_size(tmp_path: Path, monkeypatch) -> None:
    """A picture is some 4 kB of SVG: a stage of 1,500 RenderSettings drew 1,500
    of them, 6 MB of a 10 MB page. The page draws MAX_PICTURES, and says so."""
    from usdrender_lint.running import report_views

    report = _many_settings(tmp_path, 8)
    monkeypatch.setattr(report_views, "MAX_PICTURES", 3, raising=False)
    page = _page_of(report, monkeypatch, tmp_path)
    assert page.count('<figure class="product"') == 3
    notes = [n for n in re.findall(r'<p class="note">(.*?)</p>', page) if "picture" in n]
    assert notes == [
        "5 framing picture(s) not drawn: the page draws the first 3; "
        "`usdrender-lint spec --format svg --output FOLDER FILE` draws them all"
    ]
    # Every finding is still there, the profiles too.
    assert page.count('<li class="finding"') == len(report.findings)
    monkeypatch.setattr(report_views, "MAX_PICTURES", 8)
    whole = _page_of(report, monkeypatch, tmp_path)
    assert whole.count('<figure class="product"') == 8 and "not drawn" not in whole


_SUBLAYERED_SHOT = """#usda 1.0
(
    subLayers = [@./lighting.usda@]
)
"""

_EXCLUDED_LIGHTING = """#usda 1.0

def Scope "Render"
{
    def RenderSettings "Settings"
    {
        uniform float4 dataWindowNDC = (1, 0, 0, 1)
    }
}
"""


def test_fix_diffs_leave_alone_a_layer_the_configuration_excludes(tmp_path: Path) -> None:
    """The page showed diffs editing a sublayer `extend-exclude` names, which
    check --fix and --diff leave alone ("left out of linting by the
    configuration"). Same files and configuration through --diff: the page's
    diffs edit the layers --diff edits."""
    (tmp_path / "shot.usda").write_text(_SUBLAYERED_SHOT)
    (tmp_path / "lighting.usda").write_text(_EXCLUDED_LIGHTING)
    (tmp_path / ".usdrender-lint.toml").write_text('extend-exclude = ["lighting.usda"]\n')
    diff = _run("check", "--no-cache", "--diff", "--unsafe-fixes", "shot.usda", cwd=tmp_path)
    assert "lighting.usda is left out of linting" in diff.stderr
    edited = {line.split()[1] for line in diff.stdout.splitlines() if line.startswith("--- ")}
    page = _run("check", "--no-cache", "--format", "html", "shot.usda", cwd=tmp_path).stdout
    assert 'data-code="SE003"' in page  # its finding is reported, with its fix
    shown = set(re.findall(r'<span class="d-name">--- a/([^<]*)</span>', page))
    assert shown == edited == {"shot.usda"}
