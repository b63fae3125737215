"""The result cache never serves an answer another run would not give: what
decides a profile is in its key (``--profile`` given, the configuration's file
and folder), and so are the USD plugins; a layer or asset removed, or a search
path's file made, while a file was linted keeps that result out of the cache;
an entry whose clip pattern no template makes is a miss, never a regular
expression run; a lookup that fails is a miss. Each case compares the cached
run with ``--no-cache``."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest
from cli_support import invoke_in
from pxr import Ar, Tf

from usdrender_lint.engine import Linter, LintRun
from usdrender_lint.running import result_cache
from usdrender_lint.running.pipeline import Request, make_linter, resolve_settings
from usdrender_lint.running.result_cache import (
    CachingLinter,
    ResultCache,
    lint_start_ns,
    run_key,
)

#: A karma-only finding: KA002, a productName without a frame token in a frame range.
FRAME_RANGE_SHOT = """#usda 1.0
(
    startTimeCode = 1001
    endTimeCode = 1100
)
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        rel products = </Render/Beauty>
    }
    def RenderProduct "Beauty"
    {
        token productName = "beauty.exr"
    }
}
"""


#: The coarse clock's tick, in seconds.
TICK = time.clock_getres(result_cache.COARSE_CLOCK) if result_cache.COARSE_CLOCK else 0.004


@pytest.fixture(autouse=True)
def _cache_on(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("USDRENDER_LINT_NO_CACHE", raising=False)
    monkeypatch.delenv("USDRENDER_LINT_CACHE_DIR", raising=False)
    # The clock users' lints start on (conftest gives other tests the precise one):
    # a folder's change time from the coarse clock can be a tick behind time.time_ns().
    monkeypatch.setattr(result_cache, "lint_start_ns", lint_start_ns)


def _json(folder: Path, *args: str) -> dict:
    result = invoke_in(folder, "check", "--format", "json", *args)
    assert result.exit_code in (0, 1), result.output
    return json.loads(result.stdout)


def _answers(document: dict) -> list[tuple]:
    return sorted(
        (f["code"], f["path"], f["profile"], f["profile_reason"])
        for entry in document["files"]
        for f in entry["findings"]
    )


def _agree(folder: Path, *args: str) -> list[tuple]:
    """The cached run's findings, checked against --no-cache's (the files were
    written before the lint's clock tick, so that its result can be stored)."""
    time.sleep(2 * TICK)
    cached = _answers(_json(folder, *args))
    assert cached == _answers(_json(folder, "--no-cache", *args))
    return cached


def test_profile_given_on_the_command_line_is_in_the_key(tmp_path: Path) -> None:
    (tmp_path / "shots").mkdir()
    (tmp_path / "shots/a.usda").write_text(FRAME_RANGE_SHOT)
    (tmp_path / "pyproject.toml").write_text(
        '[tool.usdrender-lint]\nper-path-profiles = { "shots/*.usda" = "karma" }\n'
    )
    assert "KA002" in {a[0] for a in _agree(tmp_path, "shots/a.usda")}
    # --profile auto (the default value) wins over per-path-profiles: no karma.
    assert "KA002" not in {a[0] for a in _agree(tmp_path, "--profile", "auto", "shots/a.usda")}


def test_the_configuration_s_file_and_folder_are_in_the_key(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("USDRENDER_LINT_CACHE_DIR", str(tmp_path / "shared-cache"))
    (tmp_path / "shots").mkdir()
    (tmp_path / "shots/a.usda").write_text(FRAME_RANGE_SHOT)
    config = '[tool.usdrender-lint]\nper-path-profiles = { "shots/*.usda" = "karma" }\n'
    (tmp_path / "pyproject.toml").write_text(config)
    assert "KA002" in {a[0] for a in _agree(tmp_path, "shots/a.usda")}
    # The same text one folder down: its glob is read from there and matches nothing.
    (tmp_path / "pyproject.toml").rename(tmp_path / "shots/pyproject.toml")
    assert "KA002" not in {a[0] for a in _agree(tmp_path, "shots/a.usda")}
    # The same setting in another file of the same folder: the reason names that file.
    (tmp_path / "shots/pyproject.toml").unlink()
    (tmp_path / "pyproject.toml").write_text('[tool.usdrender-lint]\nprofile = "karma"\n')
    reasons = {a[3] for a in _agree(tmp_path, "shots/a.usda")}
    (tmp_path / "pyproject.toml").unlink()
    (tmp_path / ".usdrender-lint.toml").write_text('profile = "karma"\n')
    again = {a[3] for a in _agree(tmp_path, "shots/a.usda")}
    assert any("pyproject.toml" in r for r in reasons)
    assert any(".usdrender-lint.toml" in r for r in again) and not any(
        "pyproject.toml" in r for r in again
    )


def test_a_usd_plugin_installed_or_edited_changes_the_key(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    plugins = tmp_path / "plugins"
    plugins.mkdir()
    monkeypatch.setenv("PXR_PLUGINPATH_NAME", f"{tmp_path / 'elsewhere'}{os.pathsep}{plugins}/*/")
    request = Request(("x.usda",), isolated=True)
    settings = resolve_settings(request)
    linter = make_linter(settings)
    before = run_key(linter, settings)
    (plugins / "studio").mkdir()
    info = plugins / "studio" / "plugInfo.json"
    info.write_text('{"Plugins": []}\n')
    installed = run_key(linter, settings)
    assert installed != before
    info.write_text('{"Plugins": [ ]}\n')
    assert run_key(linter, settings) not in (before, installed)


def test_a_usd_plugin_a_plugin_info_includes_from_elsewhere_changes_the_key(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """USD also reads the plugInfo.json files a plugInfo.json's ``Includes``
    globs match, and a plugin's resources and library, wherever they are: a
    schema installed or edited there changes what USD composes (an ST010 on
    its type comes and goes), so it changes the key too."""
    top = tmp_path / "top"
    top.mkdir()
    # A linked plugInfo.json (a package manager's tree of links) is read as USD reads it.
    (tmp_path / "studio.json").write_text(
        '# the studio\'s plugins\n{"Includes": ["../schemas/*/resources/"]}\n'
    )
    (top / "plugInfo.json").symlink_to(tmp_path / "studio.json")
    monkeypatch.setenv("PXR_PLUGINPATH_NAME", str(top))
    request = Request(("x.usda",), isolated=True)
    settings = resolve_settings(request)
    linter = make_linter(settings)
    before = run_key(linter, settings)
    assert run_key(linter, settings) == before
    resources = tmp_path / "schemas" / "studio" / "resources"
    resources.mkdir(parents=True)
    (resources / "plugInfo.json").write_text(
        '{"Plugins": [{"Name": "studio", "Type": "resource", "Root": "..", '
        '"ResourcePath": "resources", "LibraryPath": "../lib/libstudio.so", "Info": {}}]}\n'
    )
    installed = run_key(linter, settings)
    assert installed != before
    (resources / "generatedSchema.usda").write_text("#usda 1.0\n")
    with_schema = run_key(linter, settings)
    assert with_schema not in (before, installed)
    (tmp_path / "schemas" / "lib").mkdir()
    (tmp_path / "schemas" / "lib" / "libstudio.so").write_bytes(b"\0")
    assert run_key(linter, settings) not in (before, installed, with_schema)


@pytest.mark.skipif(not os.path.isdir("/proc/self/task"), reason="Linux's /proc")
def test_the_key_starts_no_usd_thread(tmp_path: Path) -> None:
    """Asking USD's plugin registry starts its threads, and a process with more
    than one thread forks no workers (a forkserver costs 0.2 s): the key reads
    the plugin folders from the file system."""
    script = (
        "import os\n"
        "from usdrender_lint.running.pipeline import Request, make_linter, resolve_settings\n"
        "from usdrender_lint.running.result_cache import run_key\n"
        "settings = resolve_settings(Request(('x.usda',), isolated=True))\n"
        "run_key(make_linter(settings), settings)\n"
        "print(len(os.listdir('/proc/self/task')))\n"
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert done.stdout == "1\n", done.stderr


class _Meddling:
    """A linter that changes the files after each lint, before the cache stores
    its result: as another process would while a long lint ran."""

    def __init__(self, linter: Linter, meddle: Callable[[], None]) -> None:
        self.linter, self.meddle = linter, meddle
        self.raise_errors = True

    def run_path(self, path: str, **options: object) -> LintRun:
        run = self.linter.run_path(path, **options)  # type: ignore[arg-type]
        self.meddle()
        return run


def _store_while(tmp_path: Path, shot: Path, meddle: Callable[[], None]) -> ResultCache:
    time.sleep(2 * TICK)  # the files were written before the lint's tick
    settings = resolve_settings(Request((str(shot),), isolated=True))
    linter = make_linter(settings)
    cache = ResultCache(tmp_path / "cache", run_key(linter, settings))
    assert cache.prepare() is None
    CachingLinter(_Meddling(linter, meddle), cache).lint_path(str(shot))  # type: ignore[arg-type]
    return cache


SUBLAYER_SHOT = """#usda 1.0
(
    subLayers = [@./sub.usda@]
)
"""
BAD_RESOLUTION = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        uniform int2 resolution = (1920, 0)
    }
}
"""


def test_a_layer_removed_while_the_file_was_linted_keeps_the_result_out(tmp_path: Path) -> None:
    shot = tmp_path / "shot.usda"
    shot.write_text(SUBLAYER_SHOT)
    (tmp_path / "sub.usda").write_text(BAD_RESOLUTION)
    cache = _store_while(tmp_path, shot, (tmp_path / "sub.usda").unlink)
    assert cache.stored == 0
    assert cache.lookup(str(shot)) is None
    # Left alone, the same lint is stored (the test above is not vacuous).
    (tmp_path / "sub.usda").write_text(BAD_RESOLUTION)
    assert _store_while(tmp_path, shot, lambda: None).stored == 1


PASS_SHOT = """#usda 1.0
def Scope "Render"
{
    def RenderPass "comp"
    {
        token passType = "nuke"
        asset fileName = @./comp/final.nk@
    }
}
"""


def test_an_asset_removed_while_the_file_was_linted_keeps_the_result_out(tmp_path: Path) -> None:
    shot = tmp_path / "shot.usda"
    shot.write_text(PASS_SHOT)
    (tmp_path / "comp").mkdir()
    (tmp_path / "comp/final.nk").write_text("# nuke\n")
    cache = _store_while(tmp_path, shot, (tmp_path / "comp/final.nk").unlink)
    assert cache.stored == 0
    (tmp_path / "comp/final.nk").write_text("# nuke\n")
    assert _store_while(tmp_path, shot, lambda: None).stored == 1


def test_a_search_path_s_file_made_while_the_file_was_linted_keeps_the_result_out(
    tmp_path: Path,
) -> None:
    first, second = tmp_path / "sp1", tmp_path / "sp2"
    (first / "assets").mkdir(parents=True)
    (second / "assets").mkdir(parents=True)
    with_default = BAD_RESOLUTION.replace(
        "#usda 1.0", '#usda 1.0\n(\n    defaultPrim = "Render"\n)'
    )
    (second / "assets/rs.usda").write_text(with_default)
    shot = tmp_path / "shots/shot.usda"
    shot.parent.mkdir()
    shot.write_text('#usda 1.0\ndef Scope "Render" (references = @assets/rs.usda@) {}\n')
    Ar.DefaultResolver.SetDefaultSearchPath([str(first), str(second)])
    try:
        made = lambda: shutil.copy(second / "assets/rs.usda", first / "assets/rs.usda")  # noqa: E731
        assert _store_while(tmp_path, shot, made).stored == 0
        (first / "assets/rs.usda").unlink()
        assert _store_while(tmp_path, shot, lambda: None).stored == 1
    finally:
        Ar.DefaultResolver.SetDefaultSearchPath([])


PUBLISHED_SHOT = """#usda 1.0
(
    subLayers = [@./published/sub.usda@]
)
"""


def test_a_folder_published_while_the_file_was_linted_keeps_the_result_out(
    tmp_path: Path,
) -> None:
    """A publish renames a folder prepared earlier into place: the files in it
    keep their change times from before the lint, only the renamed folder
    changes. The lint may have read the old folder's layer, or found none."""
    shot = tmp_path / "shot.usda"
    shot.write_text(PUBLISHED_SHOT)
    staged = tmp_path / "staging"
    staged.mkdir()
    (staged / "sub.usda").write_text(BAD_RESOLUTION)

    def publish() -> None:
        if (tmp_path / "published").exists():
            os.rename(tmp_path / "published", tmp_path / "old")
        os.rename(staged, tmp_path / "published")

    # Found none: the sublayer appeared while the file was linted.
    assert _store_while(tmp_path, shot, publish).stored == 0
    # Read the old one: another folder of the same name replaced it.
    staged.mkdir()
    (staged / "sub.usda").write_text(BAD_RESOLUTION.replace("0)", "1080)"))
    assert _store_while(tmp_path, shot, publish).stored == 0
    # Left alone, the same lint is stored (the tests above are not vacuous).
    assert _store_while(tmp_path, shot, lambda: None).stored == 1


def test_a_change_in_the_tick_the_lint_began_counts_as_during_the_lint(tmp_path: Path) -> None:
    layer = tmp_path / "a.usda"
    layer.write_text("#usda 1.0\n")
    stamp = os.stat(layer).st_ctime_ns
    assert result_cache._changed_since(str(layer), stamp)
    assert not result_cache._changed_since(str(layer), stamp + 1)
    if result_cache.COARSE_CLOCK is not None:
        # The kernel stamps change times from the coarse clock: the start is read from it.
        start = lint_start_ns()
        layer.write_text("#usda 1.0\n# edited\n")
        assert os.stat(layer).st_ctime_ns >= start


def _entry(cache_folder: Path) -> Path:
    (entry,) = (cache_folder / result_cache.ENTRIES_DIR).glob("*.json")
    return entry


@pytest.mark.parametrize("pattern", ["(", "(a+)+$", "zz(z|y)*"])
def test_an_entry_whose_clip_pattern_no_template_makes_is_a_miss(
    tmp_path: Path, pattern: str
) -> None:
    (tmp_path / "a.usda").write_text(BAD_RESOLUTION)
    first = _agree(tmp_path, "a.usda")
    entry = _entry(tmp_path / result_cache.CACHE_DIR_NAME)
    data = json.loads(entry.read_text())
    data["clips"] = [[str(tmp_path), pattern, []]]
    entry.write_text(json.dumps(data))
    result = invoke_in(tmp_path, "check", "--format", "json", "a.usda")
    assert result.exit_code == 1, result.output
    assert _answers(json.loads(result.stdout)) == first
    # Linted again and stored anew: the entry no longer holds the pattern.
    assert json.loads(_entry(tmp_path / result_cache.CACHE_DIR_NAME).read_text())["clips"] == []


def test_a_lookup_that_fails_is_a_miss_not_a_lost_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "a.usda").write_text(BAD_RESOLUTION)
    first = _agree(tmp_path, "a.usda")

    def failing(*_args: object) -> object:
        raise Tf.ErrorException("the resolver could not be made")

    monkeypatch.setattr(result_cache, "_resolver_state", failing)
    result = invoke_in(tmp_path, "check", "--format", "json", "--timeout", "0", "a.usda")
    assert result.exit_code == 1, result.output
    assert _answers(json.loads(result.stdout)) == first
