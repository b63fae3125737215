"""The result cache never serves a stale or foreign answer, never writes into
or prunes a folder that is not its own, and never blocks or crashes on what it
finds in its folder (issue 31, items 2, 3, 5 and 6).

Each staleness test lints a stage with the cache (the entry is stored), makes
one kind of change the cache must see, and requires the cached answer to equal
``--no-cache``'s: a symbolic link retargeted, a file appearing earlier on the
search path, a clip a template matches appearing, a file a rule checks deleted,
a layer changed or replaced by an older copy while it is linted, a crafted
entry."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.engine import Linter
from usdrender_lint.model import Finding
from usdrender_lint.running import result_cache
from usdrender_lint.running.pipeline import Request, run

BAD = "(1, 1, 0, 0)"  # an inverted dataWindowNDC: SE003
GOOD = "(0, 0, 1, 1)"

SHOT = """#usda 1.0
(
    subLayers = [@./common.usda@]
)
def Scope "Render"
{
    def RenderSettings "Settings"
    {
    }
}
"""


def settings_layer(window: str) -> str:
    return f"""#usda 1.0
over "Render"
{{
    over "Settings"
    {{
        uniform float4 dataWindowNDC = {window}
    }}
}}
"""


@pytest.fixture(autouse=True)
def _in_tmp(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.delenv("USDRENDER_LINT_NO_CACHE", raising=False)
    monkeypatch.chdir(tmp_path)


def lint(path: Path | str, *, cache: bool = True, cache_dir: str = "cache") -> tuple[Finding, ...]:
    """The findings of one file, linted in this process with or without the cache."""
    request = Request(
        (str(path),),
        isolated=True,
        jobs=1,
        timeout=None,
        progress=False,
        cache=cache,
        cache_dir=cache_dir if cache else None,
    )
    report = run(request).report
    assert not report.errored_files, report
    return tuple(report.findings)


def entries(folder: str = "cache") -> list[Path]:
    return sorted(Path(folder).glob("v*/*.json"))


def stored(path: Path | str) -> tuple[Finding, ...]:
    """Lint with the cache and require the result stored (else the test proves nothing)."""
    before = len(entries())
    findings = lint(path)
    assert len(entries()) == before + 1, "the result must be stored"
    return findings


def agrees(path: Path | str) -> None:
    """The cached answer equals --no-cache's (and a second cached run too)."""
    fresh = lint(path, cache=False)
    assert lint(path) == fresh
    assert lint(path) == fresh


def codes(findings: tuple[Finding, ...]) -> set[str]:
    return {f.code for f in findings}


# -- what resolution depends on -----------------------------------------------------------


def test_a_sublayer_that_is_a_symbolic_link_retargeted(tmp_path: Path) -> None:
    (tmp_path / "bad.usda").write_text(settings_layer(BAD))
    (tmp_path / "good.usda").write_text(settings_layer(GOOD))
    (tmp_path / "common.usda").symlink_to("bad.usda")
    (tmp_path / "shot.usda").write_text(SHOT)
    assert "SE003" in codes(stored("shot.usda"))
    (tmp_path / "common.usda").unlink()
    (tmp_path / "common.usda").symlink_to("good.usda")
    agrees("shot.usda")
    assert "SE003" not in codes(lint("shot.usda"))


def test_a_folder_on_the_way_retargeted(tmp_path: Path) -> None:
    for name, window in (("v1", BAD), ("v2", GOOD)):
        (tmp_path / name).mkdir()
        (tmp_path / name / "common.usda").write_text(settings_layer(window))
    (tmp_path / "current").symlink_to("v1")
    (tmp_path / "shot.usda").write_text(SHOT.replace("./common.usda", "./current/common.usda"))
    assert "SE003" in codes(stored("shot.usda"))
    (tmp_path / "current").unlink()
    (tmp_path / "current").symlink_to("v2")
    agrees("shot.usda")


REFERENCING_A_SEARCH_PATH = """#usda 1.0
def Scope "Render" (
    references = @render/settings.usda@
)
{
}
"""


#: A settings asset to reference (its default prim), with a data window.
ROOT_SETTINGS = """#usda 1.0
(
    defaultPrim = "Root"
)
def Scope "Root"
{
    def RenderSettings "Settings"
    {
        uniform float4 dataWindowNDC = %s
    }
}
"""


def _search_path_run(shot: Path, env: dict[str, str], *options: str) -> list[dict]:
    command = [sys.executable, "-m", "usdrender_lint", "check", "--isolated", "--format", "json"]
    result = subprocess.run(
        [*command, "--fail-on", "never", "--cache-dir", "cache", *options, shot.name],
        cwd=shot.parent,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)["files"][0]["findings"]


def test_a_file_appearing_earlier_on_the_search_path(tmp_path: Path) -> None:
    """PXR_AR_DEFAULT_SEARCH_PATH is read once per process: commands of their own."""
    early, late = tmp_path / "early", tmp_path / "late"
    for folder in (early, late):
        (folder / "render").mkdir(parents=True)
    (late / "render" / "settings.usda").write_text(ROOT_SETTINGS % BAD)
    shot = tmp_path / "shot" / "shot.usda"
    shot.parent.mkdir()
    shot.write_text(REFERENCING_A_SEARCH_PATH)
    env = {k: v for k, v in os.environ.items() if k != "USDRENDER_LINT_NO_CACHE"}
    env["PXR_AR_DEFAULT_SEARCH_PATH"] = f"{early}{os.pathsep}{late}"
    first = _search_path_run(shot, env)
    assert "SE003" in {f["code"] for f in first}
    assert entries(str(shot.parent / "cache")), "the result must be stored"
    (early / "render" / "settings.usda").write_text(ROOT_SETTINGS % GOOD)
    fresh = _search_path_run(shot, env, "--no-cache")
    assert "SE003" not in {f["code"] for f in fresh}
    assert _search_path_run(shot, env) == fresh


@pytest.mark.parametrize("appears", ["next-to-the-layer", "in-the-working-directory"])
def test_a_search_path_found_through_the_resolver_context_then_earlier(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, appears: str
) -> None:
    """A layer in ``layers/`` names ``render/settings.usda``: not next to it,
    the resolver finds it through the stage's context (the root layer's
    folder). A file appearing where Sdf or the resolver looks first (next to
    the naming layer, or in the working directory) is found instead."""
    shots = tmp_path / "shots"
    (shots / "render").mkdir(parents=True)
    (shots / "layers").mkdir()
    (shots / "render" / "settings.usda").write_text(ROOT_SETTINGS % BAD)
    (shots / "layers" / "layout.usda").write_text(REFERENCING_A_SEARCH_PATH)
    shot = shots / "shot.usda"
    shot.write_text("#usda 1.0\n(\n    subLayers = [@./layers/layout.usda@]\n)\n")
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    assert "SE003" in codes(stored(shot))
    earlier = shots / "layers" if appears == "next-to-the-layer" else work
    (earlier / "render").mkdir()
    (earlier / "render" / "settings.usda").write_text(ROOT_SETTINGS % GOOD)
    agrees(shot)
    assert "SE003" not in codes(lint(shot))


TEMPLATE_CLIPS = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        rel products = </Render/Beauty>
    }

    def RenderProduct "Beauty" (
        clips = {
            dictionary default = {
                string primPath = "/Render/Beauty"
                string templateAssetPath = "./clips/beauty.###.usda"
                double templateEndTime = 3
                double templateStartTime = 1
                double templateStride = 1
            }
        }
    )
    {
        token productName
    }
}
"""
EMPTY_CLIP = '#usda 1.0\nover "Render"\n{\n}\n'
SAMPLED_CLIP = """#usda 1.0
over "Render"
{
    over "Beauty"
    {
        token productName.timeSamples = {
            2: "beauty.0002.exr",
        }
    }
}
"""


def test_a_clip_the_template_matches_appearing(tmp_path: Path) -> None:
    (tmp_path / "clips").mkdir()
    (tmp_path / "clips" / "beauty.001.usda").write_text(EMPTY_CLIP)
    (tmp_path / "shot.usda").write_text(TEMPLATE_CLIPS)
    assert "SE017" not in codes(stored("shot.usda"))
    (tmp_path / "clips" / "beauty.002.usda").write_text(SAMPLED_CLIP)
    agrees("shot.usda")
    assert "SE017" in codes(lint("shot.usda"))


RENDER_PASS = """#usda 1.0
def Scope "Render"
{
    def RenderPass "composite"
    {
        uniform token passType = "nuke"
        uniform asset fileName = @./comp/final.nk@
        uniform string[] command = ["nuke", "-x", "{fileName}"]
    }
}
"""


@pytest.mark.parametrize("exists_first", [True, False], ids=["deleted", "created"])
def test_a_render_pass_file_name_deleted_or_created(tmp_path: Path, exists_first: bool) -> None:
    (tmp_path / "comp").mkdir()
    nk = tmp_path / "comp" / "final.nk"
    if exists_first:
        nk.write_text("# nuke\n")
    (tmp_path / "shot.usda").write_text(RENDER_PASS)
    assert ("PA004" in codes(stored("shot.usda"))) is not exists_first
    if exists_first:
        nk.unlink()
    else:
        nk.write_text("# nuke\n")
    agrees("shot.usda")
    assert ("PA004" in codes(lint("shot.usda"))) is exists_first


# -- changes while a file is linted -------------------------------------------------------


def _during_the_lint(monkeypatch: pytest.MonkeyPatch, change: Callable[[], None]) -> None:
    """Run ``change`` once, right after the engine has linted a file (before the
    result is stored)."""
    original = Linter.run_path
    pending = [change]

    def run_path(linter: Linter, path: str, **options: Any):  # type: ignore[no-untyped-def]
        run = original(linter, path, **options)
        while pending:
            pending.pop()()
        return run

    monkeypatch.setattr(Linter, "run_path", run_path)


def _same_size_same_times(path: Path, text: str) -> None:
    """Rewrite ``path`` keeping its size and times (only its content and change time tell)."""
    before = path.stat()
    assert len(text) == before.st_size
    path.write_text(text)
    os.utime(path, ns=(before.st_atime_ns, before.st_mtime_ns))


def test_a_layer_edited_while_it_is_linted_is_not_stored(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "common.usda").write_text(settings_layer(BAD))
    (tmp_path / "shot.usda").write_text(SHOT)
    with monkeypatch.context() as patched:
        edit = lambda: _same_size_same_times(tmp_path / "common.usda", settings_layer(GOOD))  # noqa: E731
        _during_the_lint(patched, edit)
        assert "SE003" in codes(lint("shot.usda"))  # what was read before the edit
    agrees("shot.usda")
    assert "SE003" not in codes(lint("shot.usda"))


def test_a_layer_replaced_by_an_older_copy_while_it_is_linted_is_not_stored(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``cp -p`` / ``rsync -t``: the copy keeps an older modification time."""
    (tmp_path / "common.usda").write_text(settings_layer(BAD))
    (tmp_path / "old_copy.usda").write_text(settings_layer(GOOD))
    os.utime(tmp_path / "old_copy.usda", (1_000_000_000, 1_000_000_000))
    (tmp_path / "shot.usda").write_text(SHOT)

    def copy_keeping_times() -> None:
        shutil.copy2(tmp_path / "old_copy.usda", tmp_path / "incoming.tmp")
        os.replace(tmp_path / "incoming.tmp", tmp_path / "common.usda")

    with monkeypatch.context() as patched:
        _during_the_lint(patched, copy_keeping_times)
        assert "SE003" in codes(lint("shot.usda"))
    agrees("shot.usda")


# -- entries ------------------------------------------------------------------------------


def _entry_of(path: str) -> Path:
    before = set(entries())
    lint(path)
    [entry] = set(entries()) - before
    return entry


def test_a_crafted_entry_for_another_file_is_not_served(tmp_path: Path) -> None:
    (tmp_path / "common.usda").write_text(settings_layer(BAD))
    (tmp_path / "bad.usda").write_text(SHOT)
    (tmp_path / "good.usda").write_text(SHOT.replace("./common.usda", "./nothing.usda"))
    bad, good = _entry_of("bad.usda"), _entry_of("good.usda")
    crafted = json.loads(bad.read_text())
    crafted["file"] = "good.usda"
    for finding in crafted["findings"]:
        finding["file"] = "good.usda"
    good.write_text(json.dumps(crafted))
    assert lint("good.usda") == lint("good.usda", cache=False)
    assert "SE003" not in codes(lint("good.usda"))


def _run_in_a_thread(action: Callable[[], object], seconds: float = 60) -> None:
    """Run ``action``; fail (instead of hanging the suite) when it blocks."""
    errors: list[BaseException] = []

    def target() -> None:
        try:
            action()
        except BaseException as exc:  # noqa: BLE001 - handed to the test
            errors.append(exc)

    thread = threading.Thread(target=target, daemon=True)
    thread.start()
    thread.join(seconds)
    assert not thread.is_alive(), "blocked"
    if errors:
        raise errors[0]


def test_a_fifo_at_an_entry_s_path_does_not_block(tmp_path: Path) -> None:
    (tmp_path / "common.usda").write_text(settings_layer(BAD))
    (tmp_path / "shot.usda").write_text(SHOT)
    entry = _entry_of("shot.usda")
    expected = lint("shot.usda", cache=False)
    entry.unlink()
    os.mkfifo(entry)
    _run_in_a_thread(lambda: lint("shot.usda"))
    assert lint("shot.usda") == expected


@pytest.mark.parametrize("kind", ["nested", "folder", "link", "huge"])
def test_a_hostile_entry_is_ignored_now_and_later(tmp_path: Path, kind: str) -> None:
    (tmp_path / "common.usda").write_text(settings_layer(BAD))
    (tmp_path / "shot.usda").write_text(SHOT)
    entry = _entry_of("shot.usda")
    expected = lint("shot.usda", cache=False)
    entry.unlink()
    if kind == "nested":
        entry.write_text("[" * 200_000 + "]" * 200_000)
    elif kind == "folder":
        entry.mkdir()
    elif kind == "link":
        (tmp_path / "elsewhere.json").write_text(json.dumps({"findings": []}))
        entry.symlink_to(tmp_path / "elsewhere.json")
    else:
        entry.write_bytes(b" " * (result_cache.MAX_ENTRY_BYTES + 1))
    for _ in range(3):  # now, and on the runs after
        assert lint("shot.usda") == expected


# -- the cache's folder ---------------------------------------------------------------------


def _check(*args: str) -> tuple[int, str]:
    result = CliRunner().invoke(cli, ["check", "--isolated", "--format", "json", *args])
    return result.exit_code, result.output


def test_a_folder_of_the_user_s_is_refused_and_left_alone(tmp_path: Path) -> None:
    (tmp_path / "shot.usda").write_text(SHOT.replace("./common.usda", "./nothing.usda"))
    assets = tmp_path / "assets"
    (assets / f"v{result_cache.FORMAT}").mkdir(parents=True)
    for i in range(3):
        (assets / f"v{result_cache.FORMAT}" / f"plate.{i}.exr").write_bytes(b"\0" * 1000)
    (assets / "texture.exr").write_bytes(b"\0" * 1000)
    before = sorted(p.relative_to(assets) for p in assets.rglob("*"))
    code, output = _check("--cache-dir", "assets", "shot.usda")
    assert code == 2
    [line] = [x for x in output.splitlines() if "assets" in x]
    assert "not a usdrender-lint cache folder" in line
    assert sorted(p.relative_to(assets) for p in assets.rglob("*")) == before


def test_only_a_folder_the_tool_created_gets_a_gitignore(tmp_path: Path) -> None:
    (tmp_path / "shot.usda").write_text(SHOT.replace("./common.usda", "./nothing.usda"))
    (tmp_path / "empty").mkdir()
    for folder in ("new", "empty"):
        assert _check("--fail-on", "never", "--cache-dir", folder, "shot.usda")[0] == 0
        assert (tmp_path / folder / "CACHEDIR.TAG").is_file()
        assert entries(folder)
    assert (tmp_path / "new" / ".gitignore").read_text().strip().endswith("*")
    assert not (tmp_path / "empty" / ".gitignore").exists()
    (tmp_path / "new" / ".gitignore").unlink()  # the user's choice: not written again
    assert _check("--fail-on", "never", "--cache-dir", "new", "shot.usda")[0] == 0
    assert not (tmp_path / "new" / ".gitignore").exists()


def test_pruning_removes_only_the_cache_s_own_entries(tmp_path: Path) -> None:
    cache = result_cache.ResultCache(tmp_path / "cache", "key")
    assert cache.prepare() is None
    own = [cache.entries / f"{i:040x}.json" for i in range(4)]
    foreign = [cache.entries / "plate.exr", cache.entries / "notes.json"]
    for path in (*own, *foreign):
        path.write_bytes(b"x" * 1000)
        os.utime(path, (1, 1))
    older = tmp_path / "cache" / f"v{result_cache.FORMAT - 1}"
    older.mkdir()
    (older / f"{0:040x}.json").write_bytes(b"x" * 1000)  # an older format's: never read
    (older / "keep.txt").write_bytes(b"x")
    os.utime(own[0], (0, 0))  # the least recently used of this format
    assert cache.prune(max_bytes=4_900, keep_bytes=3_500) == 2
    assert sorted(older.iterdir()) == [older / "keep.txt"]
    assert not own[0].exists() and all(p.exists() for p in own[1:])
    assert cache.prune(max_bytes=100, keep_bytes=0) == 3
    assert sorted(cache.entries.iterdir()) == sorted(foreign)
    # A folder whose tag is gone is not the cache's any more: nothing is pruned.
    for path in own:
        path.write_bytes(b"x" * 1000)
    (tmp_path / "cache" / "CACHEDIR.TAG").unlink()
    assert cache.prune(max_bytes=100, keep_bytes=0) == 0
