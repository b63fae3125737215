"""The result cache (running/result_cache.py): a re-run reuses results, and any
change to anything a result depends on is seen on the next run, for every kind
of dependency: the root layer, a sublayer (shared by many files), a reference, a
payload, a value clip, a layer only the fast path scanned, a package member, a
target that did not exist, the configuration, the tool."""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import shutil
import subprocess
import sys
import zipfile
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from click.testing import CliRunner
from pxr import Usd

import usdrender_lint
from usdrender_lint import config as config_module
from usdrender_lint.cli import cli
from usdrender_lint.config import Settings
from usdrender_lint.engine import Linter, LintRun
from usdrender_lint.engine.assets import Reads
from usdrender_lint.engine.variants import VariantExplorer
from usdrender_lint.running import result_cache
from usdrender_lint.running.pipeline import Request, make_linter, run
from usdrender_lint.running.result_cache import ResultCache, run_key, settings_key

pytestmark = pytest.mark.heavy(seconds=13)

BAD = "(1, 1, 0, 0)"  # an inverted dataWindowNDC: SE003
GOOD = "(0, 0, 1, 1)"


def settings_layer(window: str = BAD) -> str:
    return f"""#usda 1.0
over "Render"
{{
    over "Settings"
    {{
        uniform float4 dataWindowNDC = {window}
    }}
}}
"""


SHOT_WITH_SUBLAYER = """#usda 1.0
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


@pytest.fixture(autouse=True)
def _cache_on(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.delenv("USDRENDER_LINT_NO_CACHE", raising=False)
    monkeypatch.chdir(tmp_path)


class Spy:
    """Counts the files the engine actually lints (in this process)."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        self.linted: list[str] = []
        for cls in (Linter, VariantExplorer):
            monkeypatch.setattr(cls, "run_path", self._counting(cls.run_path))

    def _counting(self, original: Callable[..., LintRun]) -> Callable[..., LintRun]:
        def run_path(linter: object, path: str, **options: object) -> LintRun:
            self.linted.append(path)
            return original(linter, path, **options)

        return run_path


@pytest.fixture
def spy(monkeypatch: pytest.MonkeyPatch) -> Spy:
    return Spy(monkeypatch)


def check(*paths: Path | str, cache_dir: Path | None = None, **options: object):
    """The report of a cached check in this process (so Spy sees it)."""
    request = Request(
        tuple(str(p) for p in paths),
        isolated=True,
        jobs=1,
        timeout=None,
        progress=False,
        cache=True,
        cache_dir=str(cache_dir) if cache_dir else None,
        **options,  # type: ignore[arg-type]
    )
    return run(request).report


def codes(report) -> list[tuple[str, str | None]]:
    return sorted((f.code, f.location.path) for f in report.findings)


def uncached(*paths: Path) -> list[tuple[str, str | None]]:
    request = Request(tuple(str(p) for p in paths), isolated=True, jobs=1, timeout=None)
    return codes(run(request).report)


def write(folder: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_text(text)
    return folder / next(iter(files))


def bump(path: Path, text: str) -> None:
    """Rewrite ``path``; a same-size edit keeps its old times, so only its
    content tells (the cache must not trust sizes and modification times)."""
    before = path.stat()
    path.write_text(text)
    if path.stat().st_size == before.st_size:
        os.utime(path, ns=(before.st_atime_ns, before.st_mtime_ns))


# -- reuse ------------------------------------------------------------------------------


def test_a_second_run_reuses_every_result_and_reports_the_same(tmp_path: Path, spy: Spy) -> None:
    shot = write(tmp_path, {"shot.usda": SHOT_WITH_SUBLAYER, "common.usda": settings_layer()})
    first = check(shot)
    assert spy.linted == [str(shot)]
    assert ("SE003", "/Render/Settings.dataWindowNDC") in codes(first)
    second = check(shot)
    assert spy.linted == [str(shot)], "the second run must not lint again"
    assert second == first


def test_with_usdrender_lint_debug_every_file_is_linted(
    tmp_path: Path, spy: Spy, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A stored result holds no traceback: debugging an internal error lints anew."""
    shot = write(tmp_path, {"shot.usda": SHOT_WITH_SUBLAYER, "common.usda": settings_layer()})
    first = check(shot)
    monkeypatch.setenv("USDRENDER_LINT_DEBUG", "1")
    assert check(shot) == first
    assert spy.linted == [str(shot), str(shot)]
    monkeypatch.delenv("USDRENDER_LINT_DEBUG")
    check(shot)
    assert len(spy.linted) == 2  # and the cache serves it again without


def test_the_command_line_report_is_identical_from_the_cache(tmp_path: Path) -> None:
    shutil.copytree(Path(__file__).parents[2] / "examples", tmp_path / "examples")
    args = ["check", "--isolated", "--format", "json", "--jobs", "2", "examples"]
    runs = [CliRunner().invoke(cli, args) for _ in range(2)]
    fresh = CliRunner().invoke(cli, [*args, "--no-cache"])
    assert [r.exit_code for r in (*runs, fresh)] == [1, 1, 1]
    assert runs[0].stdout == runs[1].stdout == fresh.stdout
    entries = list((tmp_path / ".usdrender_lint_cache" / result_cache.ENTRIES_DIR).glob("*.json"))
    # A file that does not open (examples/broken_shot/lighting_wip.usda, ST001) is never stored.
    files = json.loads(fresh.stdout)["files"]
    opened = [f for f in files if not any(x["code"] == "ST001" for x in f["findings"])]
    assert len(opened) < len(files) and len(entries) == len(opened)


# -- every kind of dependency -------------------------------------------------------------


def _root(tmp_path: Path) -> tuple[Path, Callable[[], None]]:
    shot = write(tmp_path, {"shot.usda": SHOT_WITH_SUBLAYER, "common.usda": settings_layer()})
    stronger = f"{{\n        uniform float4 dataWindowNDC = {GOOD}\n    }}"
    return shot, lambda: bump(shot, SHOT_WITH_SUBLAYER.replace("{\n    }", stronger, 1))


def _sublayer(tmp_path: Path) -> tuple[Path, Callable[[], None]]:
    shot = write(tmp_path, {"shot.usda": SHOT_WITH_SUBLAYER, "common.usda": settings_layer()})
    return shot, lambda: bump(tmp_path / "common.usda", settings_layer(GOOD))


def _arc(kind: str) -> Callable[[Path], tuple[Path, Callable[[], None]]]:
    def make(tmp_path: Path) -> tuple[Path, Callable[[], None]]:
        shot = write(
            tmp_path,
            {
                "shot.usda": f"""#usda 1.0
def Scope "Render"
{{
    def RenderSettings "Settings" (
        {kind} = @./arc.usda@</Render/Settings>
    )
    {{
    }}
}}
""",
                "arc.usda": settings_layer().replace("over", "def", 1),
            },
        )
        return shot, lambda: bump(
            tmp_path / "arc.usda", settings_layer(GOOD).replace("over", "def", 1)
        )

    return make


def _clip(tmp_path: Path) -> tuple[Path, Callable[[], None]]:
    source = Path(__file__).parents[1] / "rules" / "SE017_time_samples_ignored"
    shutil.copy(source / "fail_from_value_clips.usda", tmp_path / "shot.usda")
    shutil.copy(source / "product_name_clip.usda", tmp_path / "product_name_clip.usda")
    # Without samples in the clip, SE017 has nothing to report.
    return tmp_path / "shot.usda", lambda: bump(
        tmp_path / "product_name_clip.usda", '#usda 1.0\nover "Render"\n{\n}\n'
    )


def _clip_appearing_later(tmp_path: Path) -> tuple[Path, Callable[[], None]]:
    """The clip starts without samples (so no rule makes USD open it) and
    gains them: the clip is a dependency although the lint never read it."""
    shot, _ = _clip(tmp_path)
    clip = tmp_path / "product_name_clip.usda"
    samples = clip.read_text()
    clip.write_text('#usda 1.0\nover "Render"\n{\n}\n')
    return shot, lambda: clip.write_text(samples)


def _missing_target_created(tmp_path: Path) -> tuple[Path, Callable[[], None]]:
    shot = write(tmp_path, {"shot.usda": SHOT_WITH_SUBLAYER})  # common.usda does not exist
    return shot, lambda: (tmp_path / "common.usda").write_text(settings_layer())


def _scanned_by_the_fast_path(tmp_path: Path) -> tuple[Path, Callable[[], None]]:
    """A referenced asset outside the render prims' mask: the fast path reads
    it (to prove no render prim comes from it) but never composes it."""
    shot = write(
        tmp_path,
        {
            "shot.usda": """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        uniform float4 dataWindowNDC = (0, 0, 1, 1)
    }
}
def Xform "World" (
    references = @./asset.usda@
)
{
}
""",
            "asset.usda": '#usda 1.0\n(\n    defaultPrim = "Asset"\n)\ndef Xform "Asset"\n{\n}\n',
        },
    )
    stage = make_linter(Settings())._open_partial(str(shot)).stage
    assert stage is not None, "the fast path must compose only the mask here"
    assert not any(layer.realPath.endswith("asset.usda") for layer in stage.GetUsedLayers())
    sneaky = (
        '#usda 1.0\n(\n    defaultPrim = "Asset"\n)\ndef Xform "Asset"\n{\n'
        f'    def RenderSettings "Sneaky"\n    {{\n        uniform float4 dataWindowNDC = {BAD}\n'
        "    }\n}\n"
    )
    return shot, lambda: (tmp_path / "asset.usda").write_text(sneaky)


def _package_member(tmp_path: Path) -> tuple[Path, Callable[[], None]]:
    def package(window: str) -> None:
        with zipfile.ZipFile(tmp_path / "settings.usdz", "w", zipfile.ZIP_STORED) as archive:
            archive.writestr("settings.usda", settings_layer(window))

    package(BAD)
    shot = write(
        tmp_path, {"shot.usda": SHOT_WITH_SUBLAYER.replace("./common.usda", "./settings.usdz")}
    )
    return shot, lambda: package(GOOD)


@pytest.mark.parametrize(
    "make",
    [
        _root,
        _sublayer,
        _arc("references"),
        _arc("payload"),
        _clip,
        _clip_appearing_later,
        _missing_target_created,
        _scanned_by_the_fast_path,
        _package_member,
    ],
    ids=[
        "root",
        "sublayer",
        "reference",
        "payload",
        "value-clip",
        "value-clip-not-read",
        "missing-target-created",
        "layer-the-fast-path-scanned",
        "package-member",
    ],
)
def test_a_change_to_any_dependency_is_seen(
    tmp_path: Path, spy: Spy, make: Callable[[Path], tuple[Path, Callable[[], None]]]
) -> None:
    shot, change = make(tmp_path)
    before = codes(check(shot))
    assert codes(check(shot)) == before and len(spy.linted) == 1, "unchanged: reused"
    change()
    after = codes(check(shot))
    assert len(spy.linted) == 2, "changed: linted again"
    assert after != before
    assert after == uncached(shot)


def test_editing_a_sublayer_4000_files_share_shows_up_in_all_of_them(
    tmp_path: Path, spy: Spy
) -> None:
    count = 200  # the property, at a size a test can afford
    write(tmp_path, {"common.usda": settings_layer()})
    shots = [write(tmp_path, {f"shot_{i:04d}.usda": SHOT_WITH_SUBLAYER}) for i in range(count)]
    first = check(*shots)
    assert sum(f.code == "SE003" for f in first.findings) == count
    check(*shots)
    assert len(spy.linted) == count
    bump(tmp_path / "common.usda", settings_layer(GOOD))
    after = check(*shots)
    assert len(spy.linted) == 2 * count
    assert not any(f.code == "SE003" for f in after.findings)
    assert [r.file for r in after.files] == [str(s) for s in shots]


# -- what else is in the key -------------------------------------------------------------


def test_configuration_changes_are_misses(tmp_path: Path, spy: Spy) -> None:
    shot = write(tmp_path, {"shot.usda": SHOT_WITH_SUBLAYER, "common.usda": settings_layer()})
    config = tmp_path / ".usdrender-lint.toml"
    variants = [
        "",
        'severity = { SE003 = "warning" }',
        'ignore = ["SE003"]',
        "time-sample-cap = 5",
        "[rules.resolution-non-positive]\nrequire-authored = true",
    ]
    severities = []
    for text in variants:
        config.write_text(text + "\n")
        report = run(
            Request((str(shot),), config=str(config), jobs=1, timeout=None, cache=True)
        ).report
        severities.append(sorted((f.code, f.severity.value) for f in report.findings))
    assert len(spy.linted) == len(variants), "each configuration is a new key"
    assert ("SE003", "warning") in severities[1] and "SE003" not in dict(severities[2])


def test_every_setting_that_can_change_a_finding_is_in_the_key() -> None:
    """Generic over Settings: a field added later (e.g. a profile) is in the key
    unless it is listed as one that cannot change a finding."""
    base = settings_key(Settings())
    changed = {
        "select": ("CA",),
        "ignore": ("SE003",),
        "extend_select": ("UL001",),
        "severity": {"SE003": config_module.Severity.WARNING},
        "per_path_ignores": {"*.usda": ("SE",)},
        "rule_options": {"SE001": {"require-authored": True}},
        "roots": ("shots/*.usda",),
        "time_sample_cap": 5,
        "variants": True,
        "max_variant_combinations": 3,
        "profile": "arnold",
        "per_path_profiles": {"*.usda": "arnold"},
        "selections_below": (config_module.RuleSelection(("CA",), (), (), {}),),
    }
    fields = {f.name for f in dataclasses.fields(Settings)}
    assert set(changed) == fields - result_cache.SETTINGS_NOT_IN_KEY, (
        "a new setting: add it here, or to SETTINGS_NOT_IN_KEY if it cannot change a finding"
    )
    for name, value in changed.items():
        assert settings_key(dataclasses.replace(Settings(), **{name: value})) != base, name


def test_the_key_follows_the_tool_the_rules_and_the_environment(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    linter = make_linter(Settings())
    key = run_key(linter, Settings())
    assert run_key(make_linter(Settings()), Settings()) == key
    monkeypatch.setattr(usdrender_lint, "__version__", "999")
    assert run_key(linter, Settings()) != key
    monkeypatch.undo()
    monkeypatch.setenv("PXR_PLUGINPATH_NAME", "/elsewhere")
    assert run_key(linter, Settings()) != key
    monkeypatch.undo()
    monkeypatch.setenv("USDRENDER_LINT_CACHE_DIR", "/elsewhere")  # where, not what
    assert run_key(linter, Settings()) == key
    assert run_key(make_linter(Settings(select=("CA",))), Settings()) != key
    assert run_key(linter, Settings(), variant_combinations=4) != key


@contextlib.contextmanager
def _touched(path: str) -> Iterator[None]:
    """The file's modification time one nanosecond later, then as it was."""
    stat = os.stat(path)
    try:
        os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns + 1))
        yield
    finally:
        os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns))


def test_an_edited_rule_module_changes_the_key(tmp_path: Path) -> None:
    linter = make_linter(Settings())
    key = run_key(linter, Settings())
    module = sys.modules[type(linter.rules[0]).__module__].__file__
    assert module is not None
    with _touched(module):
        assert run_key(linter, Settings()) != key


def test_another_build_of_usd_core_changes_the_key() -> None:
    """usd-core 25.5.1 says it is 0.25.5 as 25.5 does: a build installed in
    the place of another (its compiled module rewritten) composes by its own
    code, so it changes the key as a version would."""
    linter = make_linter(Settings())
    key = run_key(linter, Settings())
    module = sys.modules["pxr.Usd._usd"].__file__
    assert module is not None
    with _touched(module):
        assert run_key(linter, Settings()) != key
    assert run_key(linter, Settings()) == key


def test_a_path_given_differently_or_another_working_directory_is_another_entry(
    tmp_path: Path, spy: Spy, monkeypatch: pytest.MonkeyPatch
) -> None:
    shot = write(tmp_path, {"shot.usda": SHOT_WITH_SUBLAYER, "common.usda": settings_layer()})
    assert check("shot.usda").findings[0].location.file == "shot.usda"
    assert check(shot).findings[0].location.file == str(shot)  # named as given
    assert len(spy.linted) == 2


# -- what is never stored -----------------------------------------------------------------


def test_files_the_tool_could_not_read_fully_are_not_stored(tmp_path: Path, spy: Spy) -> None:
    write(tmp_path, {"broken.usda": '#usda 1.0\ndef Scope "X" {\n'})
    for _ in range(2):
        report = check(tmp_path / "broken.usda", tmp_path / "nope.usda")
    assert [f.code for f in report.findings] == ["ST001"]
    assert spy.linted.count(str(tmp_path / "broken.usda")) == 2
    assert not list((tmp_path / ".usdrender_lint_cache" / result_cache.ENTRIES_DIR).glob("*.json"))


@pytest.mark.parametrize("error", [ConnectionError, MemoryError])
def test_a_result_a_rule_raised_on_is_not_stored(
    tmp_path: Path, spy: Spy, monkeypatch: pytest.MonkeyPatch, error: type[Exception]
) -> None:
    """A rule that raised (UL000) lost its findings on the file: the result is
    incomplete, and what made it raise (a busy server a plugin asks) may be gone
    on the next run, which must lint the file again. Memory that ran out is the
    file's error (not a UL000), and that is not stored either."""
    from usdrender_lint.rules.settings.se003_data_window_malformed import DataWindowMalformed

    shot = write(tmp_path, {"shot.usda": SHOT_WITH_SUBLAYER, "common.usda": settings_layer()})
    healthy = DataWindowMalformed.check_stage

    def raising(self: DataWindowMalformed, ctx: object) -> None:
        raise error("gone for a moment")

    monkeypatch.setattr(DataWindowMalformed, "check_stage", raising)
    report = check(shot)
    if error is MemoryError:
        [result] = report.files
        assert result.status == "error" and "out of memory" in (result.error or "")
    else:
        assert "UL000" in [code for code, _ in codes(report)]
    monkeypatch.setattr(DataWindowMalformed, "check_stage", healthy)
    assert ("SE003", "/Render/Settings.dataWindowNDC") in codes(check(shot))
    assert spy.linted == [str(shot)] * 2


def test_a_result_is_not_stored_when_a_dependency_changed_while_it_was_linted(
    tmp_path: Path,
) -> None:
    shot = write(tmp_path, {"shot.usda": SHOT_WITH_SUBLAYER, "common.usda": settings_layer()})
    linter = make_linter(Settings())
    cache = ResultCache(tmp_path / "cache", run_key(linter, Settings()))
    assert cache.prepare() is None
    run = linter.run_path(str(shot), reads=True)
    result, reads = run.result, run.reads
    assert reads is not None
    found = result_cache.dependencies(reads, str(shot))
    assert found is not None and [Path(p).name for p in found.files] == ["common.usda"]
    started = (tmp_path / "common.usda").stat().st_ctime_ns - 1  # changed after the lint began
    assert not cache.store(str(shot), result, reads, started)
    assert cache.store(str(shot), result, reads, started + 10**12)
    assert cache.lookup(str(shot)) == result


def test_unsaved_edits_and_asset_expressions_are_not_cacheable() -> None:
    assert result_cache.dependencies(Reads(layers=[("/a.usda", "/a.usda", False, True)])) is None
    assert result_cache.dependencies(Reads(complete=False)) is None
    assert result_cache.dependencies(Reads(layers=[("x", "", False, False)])) is None
    anonymous_only = Reads(
        layers=[("anon:1", "", True, False), ("/a.usda", "/a.usda", False, False)]
    )
    found = result_cache.dependencies(anonymous_only)
    assert found is not None and found.files == ("/a.usda",)


# -- robustness -------------------------------------------------------------------------


def _one_entry(tmp_path: Path) -> tuple[Path, Path]:
    shot = write(tmp_path, {"shot.usda": SHOT_WITH_SUBLAYER, "common.usda": settings_layer()})
    check(shot)
    [entry] = (tmp_path / ".usdrender_lint_cache" / result_cache.ENTRIES_DIR).glob("*.json")
    return shot, entry


@pytest.mark.parametrize(
    "damage",
    [
        b"",
        b"\x00\xff garbage",
        b'{"usdrender_lint_cache": %d, "key": "other"}' % result_cache.FORMAT,
        b'{"usdrender_lint_cache": %d}' % (result_cache.FORMAT + 1),
        b"[1, 2, 3]",
    ],
    ids=["empty", "binary", "foreign-key", "future-format", "not-an-object"],
)
def test_a_corrupt_or_foreign_entry_is_ignored_and_replaced(
    tmp_path: Path, spy: Spy, damage: bytes
) -> None:
    shot, entry = _one_entry(tmp_path)
    expected = codes(check(shot))
    entry.write_bytes(damage)
    assert codes(check(shot)) == expected
    assert len(spy.linted) == 2
    assert (
        json.loads(entry.read_bytes())["usdrender_lint_cache"] == result_cache.FORMAT
    )  # stored again
    assert codes(check(shot)) == expected and len(spy.linted) == 2


def test_an_entry_with_a_tampered_result_shape_is_a_miss(tmp_path: Path, spy: Spy) -> None:
    shot, entry = _one_entry(tmp_path)
    data = json.loads(entry.read_bytes())
    data["findings"] = [{"code": 1}]
    entry.write_text(json.dumps(data))
    assert ("SE003", "/Render/Settings.dataWindowNDC") in codes(check(shot))
    assert len(spy.linted) == 2


def test_the_cache_is_bounded_and_keeps_the_recently_used(tmp_path: Path) -> None:
    cache = ResultCache(tmp_path / "cache", "key")
    assert cache.prepare() is None
    folder = cache.entries
    names = [f"{i:040x}.json" for i in range(10)]
    for i, name in enumerate(names):
        (folder / name).write_bytes(b"x" * 1000)
        os.utime(folder / name, ns=(i * 10**9, i * 10**9))
    assert cache.prune(max_bytes=20_000) == 0
    assert cache.prune(max_bytes=5_000, keep_bytes=3_000) == 7
    assert sorted(p.name for p in folder.iterdir()) == names[7:]


def test_a_run_whose_workers_stored_entries_prunes_the_cache(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Workers store into copies of the run's cache: the run prunes after
    linting with workers as after linting in its own process, and not after
    a run that linted nothing (every result from the cache)."""
    write(tmp_path, {"common.usda": settings_layer()})
    for i in range(4):
        write(tmp_path, {f"shot_{i}.usda": SHOT_WITH_SUBLAYER})
    shots = tuple(str(tmp_path / f"shot_{i}.usda") for i in range(4))
    pruned: list[Path] = []
    monkeypatch.setattr(ResultCache, "prune", lambda cache, *args: pruned.append(cache.folder))
    run(Request(shots, isolated=True, jobs=2, cache=True))
    assert pruned == [tmp_path / ".usdrender_lint_cache"]
    run(Request(shots, isolated=True, jobs=2, cache=True))
    assert pruned == [tmp_path / ".usdrender_lint_cache"]


def test_concurrent_runs_share_a_cache_without_corrupting_it(tmp_path: Path) -> None:
    write(tmp_path, {"common.usda": settings_layer()})
    for i in range(30):
        write(tmp_path, {f"shot_{i:02d}.usda": SHOT_WITH_SUBLAYER})
    command = [sys.executable, "-m", "usdrender_lint", "check", "--isolated", "--format", "json"]
    command += ["--jobs", "2", "shot_00.usda"] + [f"shot_{i:02d}.usda" for i in range(1, 30)]
    env = {k: v for k, v in os.environ.items() if k != "USDRENDER_LINT_NO_CACHE"}
    runs = [subprocess.Popen(command, stdout=subprocess.PIPE, env=env) for _ in range(3)]
    outputs = [process.communicate(timeout=300)[0] for process in runs]
    assert [process.returncode for process in runs] == [1, 1, 1]
    assert len({output for output in outputs}) == 1
    entries = list((tmp_path / ".usdrender_lint_cache" / result_cache.ENTRIES_DIR).glob("*.json"))
    assert len(entries) == 30
    for entry in entries:
        assert json.loads(entry.read_bytes())["usdrender_lint_cache"] == result_cache.FORMAT
    again = subprocess.run(command, stdout=subprocess.PIPE, env=env, check=False)
    assert again.stdout == outputs[0]


# -- where, and when not ------------------------------------------------------------------


def test_no_cache_reads_and_writes_nothing(tmp_path: Path) -> None:
    shot = write(tmp_path, {"shot.usda": SHOT_WITH_SUBLAYER, "common.usda": settings_layer()})
    result = CliRunner().invoke(cli, ["check", "--isolated", "--no-cache", str(shot)])
    assert result.exit_code == 1
    assert not (tmp_path / ".usdrender_lint_cache").exists()
    env_off = CliRunner().invoke(
        cli, ["check", "--isolated", str(shot)], env={"USDRENDER_LINT_NO_CACHE": "1"}
    )
    assert env_off.exit_code == 1 and not (tmp_path / ".usdrender_lint_cache").exists()


def test_the_cache_lives_at_the_project_root_or_where_it_is_told(tmp_path: Path) -> None:
    project = tmp_path / "project"
    shot = write(
        project / "shots", {"shot.usda": SHOT_WITH_SUBLAYER, "common.usda": settings_layer()}
    )
    (project / "pyproject.toml").write_text("[tool.usdrender-lint]\n")
    elsewhere = tmp_path / "work"
    elsewhere.mkdir()
    os.chdir(elsewhere)
    assert CliRunner().invoke(cli, ["check", str(shot)]).exit_code == 1
    assert (project / ".usdrender_lint_cache" / result_cache.ENTRIES_DIR).is_dir()
    assert (project / ".usdrender_lint_cache" / ".gitignore").read_text().endswith("*\n")
    assert (project / ".usdrender_lint_cache" / "CACHEDIR.TAG").is_file()
    (project / "pyproject.toml").write_text('[tool.usdrender-lint]\ncache-dir = "build/lint"\n')
    assert CliRunner().invoke(cli, ["check", str(shot)]).exit_code == 1
    assert list((project / "build" / "lint" / result_cache.ENTRIES_DIR).glob("*.json"))
    flag = tmp_path / "flag-cache"
    assert CliRunner().invoke(cli, ["check", "--cache-dir", str(flag), str(shot)]).exit_code == 1
    assert list((flag / result_cache.ENTRIES_DIR).glob("*.json"))
    assert (
        CliRunner()
        .invoke(
            cli, ["check", "--isolated", str(shot)], env={"USDRENDER_LINT_CACHE_DIR": "env-cache"}
        )
        .exit_code
        == 1
    )
    assert list((elsewhere / "env-cache" / result_cache.ENTRIES_DIR).glob("*.json"))


def test_a_cache_that_cannot_be_written_is_a_note_not_a_failure(tmp_path: Path) -> None:
    shot = write(tmp_path, {"shot.usda": SHOT_WITH_SUBLAYER, "common.usda": settings_layer()})
    (tmp_path / "blocked").write_text("a file where a folder would go")
    result = CliRunner().invoke(
        cli, ["check", "--isolated", "--cache-dir", str(tmp_path / "blocked" / "cache"), str(shot)]
    )
    assert result.exit_code == 1, result.stderr
    assert "SE003" in result.stdout
    assert "cannot write the result cache" in result.stderr
    assert result.stderr.count("\n") == 1


def test_workers_store_the_results_they_lint(tmp_path: Path) -> None:
    write(tmp_path, {"common.usda": settings_layer()})
    for i in range(4):
        write(tmp_path, {f"shot_{i}.usda": SHOT_WITH_SUBLAYER})
    shots = tuple(str(tmp_path / f"shot_{i}.usda") for i in range(4))
    first = run(Request(shots, isolated=True, jobs=2, cache=True)).report
    assert (
        len(list((tmp_path / ".usdrender_lint_cache" / result_cache.ENTRIES_DIR).glob("*.json")))
        == 4
    )
    assert run(Request(shots, isolated=True, jobs=2, cache=True)).report == first


def test_variant_exploration_depends_on_every_combination_s_layers(
    tmp_path: Path, spy: Spy
) -> None:
    shot = write(
        tmp_path,
        {
            "shot.usda": """#usda 1.0
def Scope "Render" (
    variants = { string quality = "draft" }
    prepend variantSets = "quality"
)
{
    def RenderSettings "Settings"
    {
    }
    variantSet "quality" = {
        "draft" {
        }
        "final" (
            prepend references = @./final.usda@</Render>
        ) {
        }
    }
}
""",
            "final.usda": settings_layer(GOOD).replace('over "Render"', 'def Scope "Render"'),
        },
    )
    before = codes(check(shot, variants=True))
    bump(
        tmp_path / "final.usda", settings_layer(BAD).replace('over "Render"', 'def Scope "Render"')
    )
    after = codes(check(shot, variants=True))
    assert len(spy.linted) == 2
    assert ("SE003", "/Render/Settings.dataWindowNDC") in after and after != before
    assert after == codes(
        run(Request((str(shot),), isolated=True, jobs=1, timeout=None, variants=True)).report
    )


def test_the_stage_read_by_the_engine_is_what_the_entry_lists(tmp_path: Path) -> None:
    shot = write(tmp_path, {"shot.usda": SHOT_WITH_SUBLAYER, "common.usda": settings_layer()})
    linter = make_linter(Settings())
    reads = linter.run_path(str(shot), reads=True).reads
    assert reads is not None
    stage = Usd.Stage.Open(str(shot))
    used = {layer.realPath for layer in stage.GetUsedLayers() if not layer.anonymous}
    found = result_cache.dependencies(reads, str(shot))
    assert found is not None and {str(shot), *found.files} == used


def test_the_note_of_combinations_the_variant_cap_skipped_survives_a_cache_hit(
    tmp_path: Path, spy: Spy
) -> None:
    shot = write(
        tmp_path,
        {
            "shot.usda": """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings" (
        prepend variantSets = ["quality", "camera"]
    )
    {
        variantSet "quality" = {
            "draft" {
            }
            "final" {
            }
        }
        variantSet "camera" = {
            "main" {
            }
            "none" {
            }
        }
    }
}
"""
        },
    )
    request = Request(
        (str(shot),),
        isolated=True,
        jobs=1,
        timeout=None,
        progress=False,
        cache=True,
        variants=True,
        max_variant_combinations=2,
    )
    first, second = run(request), run(request)
    assert spy.linted == [str(shot)], "the second run must not lint again"
    assert first.notes == second.notes
    assert any("more were skipped (raise --max-variant-combinations)" in n for n in first.notes)


def test_a_project_under_a_folder_whose_name_is_not_utf8_is_cached_silently(
    tmp_path: Path, spy: Spy, capfd: pytest.CaptureFixture[str]
) -> None:
    """USD's bindings cannot name its resolver context's search path: the key
    is read from the bytes, with nothing printed."""
    folder = tmp_path / os.fsdecode(b"p\xffroj")
    shot = write(folder, {"shot.usda": SHOT_WITH_SUBLAYER, "common.usda": settings_layer()})
    first = check(shot)
    assert ("SE003", "/Render/Settings.dataWindowNDC") in codes(first)
    assert capfd.readouterr().err == ""
    assert check(shot) == first
    assert spy.linted == [str(shot)], "the second run must not lint again"
