"""Each file is linted with its nearest configuration (running/hierarchy.py):
a check of a tree whose shows keep their own settings gives each file what a
check of that show gives it, what the language server gives it and what the
Python API gives it with that configuration, on real shots."""

from __future__ import annotations

import json
import os
import re
import shutil
import tomllib
from pathlib import Path

import pytest
from cli_support import invoke_in
from click.testing import CliRunner

import usdrender_lint
from usdrender_lint.cli import cli
from usdrender_lint.running.documents import Documents

pytestmark = pytest.mark.heavy(seconds=28)

REPO = Path(__file__).resolve().parents[2]
BROKEN = REPO / "examples" / "broken_shot"
CLEAN = REPO / "examples" / "clean_shot" / "shot.usda"
FIXTURES = REPO / "tests" / "rules"

#: Three configurations and none: the root's, a show's (a dedicated file), a
#: show's pyproject.toml (excluding its wip/), and a folder with none above it.
ROOT = 'profile = "generic"\nfail-on = "warning"\n'
SHOW_A = 'ignore = ["CA"]\nunfixable = ["SE007"]\n'
SHOW_B = (
    '[tool.usdrender-lint]\nextend-exclude = ["wip/"]\nprofile = "karma"\n'
    '[tool.usdrender-lint.severity]\nSE003 = "info"\n'
)


def _tree(root: Path) -> None:
    for show in ("a", "b"):
        shutil.copytree(BROKEN, root / "shows" / show / "shots" / "010")
    shutil.copytree(BROKEN, root / "shows" / "b" / "wip")
    shutil.copy(CLEAN, root / "shows" / "c_clean.usda")
    for fixture in sorted((FIXTURES / "SE003_data_window_malformed").glob("fail_*.usda"))[:3]:
        shutil.copy(fixture, root / "shows" / "a" / fixture.name)
    (root / ".usdrender-lint.toml").write_text(ROOT)
    (root / "shows" / "a" / ".usdrender-lint.toml").write_text(SHOW_A)
    (root / "shows" / "b" / "pyproject.toml").write_text(SHOW_B)


@pytest.fixture
def tree(tmp_path: Path) -> Path:
    root = tmp_path / "repo"
    _tree(root)
    return root


def _check(cwd: Path, *args: str) -> tuple[int, dict]:
    result = invoke_in(cwd, "check", "--no-cache", "--jobs", "1", "--format", "json", *args)
    assert result.exit_code in (0, 1), result.output
    return result.exit_code, json.loads(result.stdout)


def _by_file(document: dict, root: Path) -> dict[str, list[tuple]]:
    return {
        str((root / entry["file"]).resolve()): sorted(
            (f["code"], f["severity"], f["path"], f["line"], f["message"], f["profile"])
            for f in entry["findings"]
        )
        for entry in document["files"]
    }


def test_each_file_gets_what_its_own_configuration_gives_it(tree: Path) -> None:
    status, whole = _check(tree, ".")
    found = _by_file(whole, tree)
    assert not any("/wip/" in name for name in found)  # show b's exclusion holds in the walk
    assert len(found) == 2 + 3 + 2 + 1  # a: a shot of 2 layers and 3 fixtures, b: a shot, c
    # The same as a check of each show alone (its configuration found from it) ...
    for show in ("a", "b"):
        _, alone = _check(tree, f"shows/{show}")
        for name, findings in _by_file(alone, tree).items():
            assert found[name] == findings, name

    # ... and as the language server and the Python API with that configuration
    # (which name files absolutely where check names them from the working directory).
    def keys(findings) -> list[tuple]:
        return sorted(
            (
                f.code,
                f.severity.value,
                f.location.path,
                f.location.line,
                f.message.replace(f"{tree}/", ""),
                f.profile,
            )
            for f in findings
        )

    documents = Documents()
    for name, findings in found.items():
        path = Path(name)
        documents.update({name: path.read_text(encoding="utf-8")})
        served = keys(documents.lint(name).findings)
        # Closed: an open document's layer is what USD gives this process for the file.
        documents.update({name: None})
        assert served == findings, name
        nearest = next(
            c
            for folder in path.parents
            for c in (folder / ".usdrender-lint.toml", folder / "pyproject.toml")
            if c.is_file()
        )
        assert keys(usdrender_lint.lint_file(path, config=nearest).findings) == findings, name
    codes = {name.split("/shows/")[1]: {f[0]: f[1] for f in fs} for name, fs in found.items()}
    assert "CA004" not in codes["a/shots/010/shot.usda"]  # show a ignores CA
    assert codes["b/shots/010/shot.usda"]["SE003"] == "info"  # show b's severity
    assert codes["b/shots/010/shot.usda"]["CA004"] == "error"
    # The worst part decides the exit: the root's fail-on warning.
    assert status == 1


def test_config_and_isolated_give_every_file_one_configuration(tree: Path) -> None:
    _, forced = _check(tree, "--config", str(tree / ".usdrender-lint.toml"), ".")
    _, isolated = _check(tree, "--isolated", ".")
    for document in (forced, isolated):
        names = [entry["file"] for entry in document["files"]]
        assert any("/wip/" in name for name in names)  # show b's exclusion does not apply
        codes = {f["code"] for e in document["files"] if "/a/" in e["file"] for f in e["findings"]}
        assert "CA004" in codes


def test_the_files_shown_are_the_files_reported(tree: Path) -> None:
    shown = invoke_in(tree, "check", "--show-files", ".")
    _, whole = _check(tree, ".")
    assert shown.stdout.splitlines() == [entry["file"] for entry in whole["files"]]


def test_shards_of_a_split_run_merge_into_the_whole(tree: Path, tmp_path: Path) -> None:
    reports = []
    for k in (1, 2, 3):
        _, shard = _check(tree, "--shard", f"{k}/3", ".")
        path = tmp_path / f"shard{k}.json"
        path.write_text(json.dumps(shard))
        reports.append(str(path))
    merged = CliRunner().invoke(cli, ["merge", "--format", "json", *reports])
    assert merged.exit_code == 1, merged.output
    _, whole = _check(tree, ".")
    assert _by_file(json.loads(merged.stdout), tree) == _by_file(whole, tree)
    assert json.loads(merged.stdout)["configuration"] == whole["configuration"]


def test_fix_and_baselines_take_each_files_configuration(tree: Path, tmp_path: Path) -> None:
    baseline = tmp_path / "baseline.json"
    written = invoke_in(tree, "check", "--no-cache", "--write-baseline", str(baseline), ".")
    assert written.exit_code == 0, written.output
    assert written.stderr.count("recorded") == 1
    again = invoke_in(tree, "check", "--no-cache", "--baseline", str(baseline), ".")
    assert again.exit_code == 0 and "0 findings" in again.stdout, again.output
    fixed = invoke_in(tree, "check", "--no-cache", "--fix", "shows")
    assert fixed.exit_code == 1, fixed.output
    shot = "shots/010/shot.usda"
    a = (tree / "shows" / "a" / shot).read_text()
    b = (tree / "shows" / "b" / shot).read_text()
    # SE007's fix is unfixable in show a only; CA004's is ignored there.
    assert "instantaneousShutter" in a and "instantaneousShutter" not in b
    assert "</World/camRig>" in a and "</World/camRig/shotCam>" in b
    assert (tree / "shows" / "b" / "wip" / "shot.usda").read_text() == (
        BROKEN / "shot.usda"
    ).read_text()  # excluded by show b: not fixed


def test_a_broken_nested_configuration_stops_the_run_naming_it(tree: Path) -> None:
    (tree / "shows" / "b" / "pyproject.toml").write_text("[tool.usdrender-lint]\nselct = 1\n")
    result = invoke_in(tree, "check", "--no-cache", ".")
    assert result.exit_code == 2
    assert result.stderr.splitlines() == [
        f"usdrender-lint: error: {tree / 'shows' / 'b' / 'pyproject.toml'}:2: unknown key "
        "'tool.usdrender-lint.selct' (did you mean 'select'?)"
    ]


def test_spec_gives_each_file_the_findings_of_its_configuration(tree: Path) -> None:
    def spec(*paths: str) -> dict[str, list]:
        result = invoke_in(tree, "spec", "--jobs", "1", "--format", "json", *paths)
        assert result.exit_code in (0, 2), result.output  # 2: the broken lighting_wip.usda
        return {
            str((tree / entry["file"]).resolve()): entry["findings"]
            for entry in json.loads(result.stdout)["files"]
        }

    whole = spec(".")
    alone = {**spec("shows/a"), **spec("shows/b"), **spec("shows/c_clean.usda")}
    assert whole == alone
    shot = str(tree / "shows" / "a" / "shots" / "010" / "shot.usda")
    assert not any("CA004" in json.dumps(finding) for finding in whole[shot])


def test_a_linked_file_takes_the_configuration_of_its_target(tree: Path) -> None:
    """As the configuration is found for one file (find_config_file resolves it),
    among files of its folder that share their lookup."""
    target = tree / "shows" / "b" / "shots" / "010" / "shot.usda"
    (tree / "shows" / "a" / "linked.usda").symlink_to(target)
    _, whole = _check(tree, "shows")
    found = {entry["file"]: entry["findings"] for entry in whole["files"]}
    linked = {f["code"]: f["severity"] for f in found["shows/a/linked.usda"]}
    assert linked["SE003"] == "info" and "CA004" in linked  # show b's settings
    own = {f["code"] for f in found["shows/a/shots/010/shot.usda"]}
    assert "CA004" not in own


def test_a_split_run_reads_each_parts_cache_as_it_wrote_it(
    tree: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each part keeps its result cache at its configuration's folder; a run
    again answers from it, the same as without the cache."""
    monkeypatch.delenv("USDRENDER_LINT_NO_CACHE", raising=False)

    def report(*args: str) -> dict:
        result = invoke_in(tree, "check", "--jobs", "1", "--format", "json", *args, ".")
        assert result.exit_code == 1, result.output
        return json.loads(result.stdout)

    cold = report()
    for folder in (tree, tree / "shows" / "a", tree / "shows" / "b"):
        assert list((folder / ".usdrender_lint_cache").rglob("*.json")), folder
    assert report() == cold == report("--no-cache")


def test_a_shows_force_exclude_holds_for_the_files_given_there(tree: Path) -> None:
    """pre-commit names every staged file: a show whose configuration sets
    force-exclude keeps its excluded files out, whatever the root's says."""
    forced = SHOW_B.replace("]\n", "]\nforce-exclude = true\n", 1)
    (tree / "shows" / "b" / "pyproject.toml").write_text(forced)
    # The first path's configuration (show a's) does not set it: show b's must.
    staged = ["shows/a/shots/010/shot.usda", "shows/b/wip/shot.usda", "shows/b/shots/010/shot.usda"]
    _, report = _check(tree, *staged)
    assert [entry["file"] for entry in report["files"]] == [staged[0], staged[2]]
    (tree / "shows" / "b" / "pyproject.toml").write_text(SHOW_B)
    _, report = _check(tree, *staged)
    assert [entry["file"] for entry in report["files"]] == staged


def test_one_set_of_workers_lints_every_configurations_files_alike(tree: Path) -> None:
    """A split run lints its parts' files together (each with its own linter):
    in this process, in one worker or in two, the report is the same."""
    _, pooled = _check(tree, ".")
    _, in_process = _check(tree, "--timeout", "0", ".")
    _, two = _check(tree, "--jobs", "2", ".")
    assert pooled == in_process == two
    codes = {os.path.normpath(e["file"]): {f["code"] for f in e["findings"]} for e in two["files"]}
    assert "CA004" not in codes["shows/a/shots/010/shot.usda"]
    assert "CA004" in codes["shows/b/shots/010/shot.usda"]


def test_a_parts_cache_it_cannot_write_is_said_once(
    tree: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("USDRENDER_LINT_NO_CACHE", raising=False)
    assert invoke_in(tree, "check", "--jobs", "1", ".").exit_code == 1  # the caches made
    entries = next((tree / "shows" / "a" / ".usdrender_lint_cache").glob("v*"))
    shutil.rmtree(entries)
    entries.write_text("a file where the entries go\n")  # unwritable, even for root
    result = invoke_in(tree, "check", "--jobs", "1", ".")
    assert result.exit_code == 1, result.output
    said = [line for line in result.stderr.splitlines() if "not cached" in line]
    assert len(said) == 1 and "shows/a/.usdrender_lint_cache" in said[0], result.stderr


def test_an_output_onto_a_linted_file_is_refused_before_any_lint(tree: Path) -> None:
    target = tree / "shows" / "b" / "shots" / "010" / "shot.usda"
    before = target.read_bytes()
    result = invoke_in(tree, "check", "--no-cache", "--output", str(target), ".")
    assert result.exit_code == 2
    assert target.read_bytes() == before


def test_show_settings_names_the_configurations_of_other_files(tree: Path) -> None:
    shown = invoke_in(tree, "check", "--show-settings", ".")
    assert shown.exit_code == 0, shown.output
    assert f"# configuration file: {tree / '.usdrender-lint.toml'}" in shown.stdout
    assert "# These files have a configuration of their own" in shown.stdout
    for config in ("a/.usdrender-lint.toml", "b/pyproject.toml"):
        assert f"#   {tree / 'shows' / config}: " in shown.stdout
    assert tomllib.loads(shown.stdout)["fail-on"] == "warning"  # still a configuration
    alone = invoke_in(tree, "check", "--show-settings", "shows/a")
    assert "of their own" not in alone.stdout


def test_below_a_configured_folder_only_its_own_exclusions_hold(tree: Path) -> None:
    """As ruff walks: what the walk meets below a folder with a configuration of its
    own is judged by that one's exclusions, not the run's; the folder itself by its
    parent's. So a root pattern neither skips a show's file that a check of the show
    lints, nor keeps a folder of its own from being skipped by name."""
    (tree / ".usdrender-lint.toml").write_text(
        ROOT + 'extend-exclude = ["*_wip.usda", "legacy/"]\n'
    )
    (tree / "shows" / "legacy").mkdir()
    for folder in ("shows/a", "shows/b/shots", "shows/legacy", "."):
        shutil.copy(BROKEN / "shot.usda", tree / folder / "lookdev_wip.usda")
    (tree / "shows" / "legacy" / ".usdrender-lint.toml").write_text('profile = "karma"\n')
    _, whole = _check(tree, ".")
    names = [os.path.normpath(entry["file"]) for entry in whole["files"]]
    assert "shows/a/lookdev_wip.usda" in names  # show a's own configuration excludes nothing
    assert "shows/b/shots/lookdev_wip.usda" in names
    assert "lookdev_wip.usda" not in names  # the root's own pattern, in its own folder
    assert not any(name.startswith("shows/legacy/") for name in names)  # judged by the root's
    assert not any("/wip/" in name for name in names)  # show b's own exclusion still holds
    for show in ("shows/a", "shows/b"):
        _, alone = _check(tree, show)
        below = str((tree / show).resolve()) + os.sep
        mine = {k: v for k, v in _by_file(whole, tree).items() if k.startswith(below)}
        assert mine == _by_file(alone, tree)
    shown = invoke_in(tree, "check", "--show-files", ".").stdout.splitlines()
    assert [os.path.normpath(name) for name in shown] == names
    spec = invoke_in(tree, "spec", "--jobs", "1", "--format", "json", ".")
    assert [os.path.normpath(e["file"]) for e in json.loads(spec.stdout)["files"]] == names
    # One configuration for the run: its patterns hold everywhere.
    _, forced = _check(tree, "--config", str(tree / ".usdrender-lint.toml"), ".")
    assert not any(entry["file"].endswith("_wip.usda") for entry in forced["files"])
    # Each file named, as a pre-commit hook names them, with force-exclude: the same files.
    given = [name for name in names if name.endswith(".usda")]
    given += ["lookdev_wip.usda", "shows/legacy/lookdev_wip.usda", "shows/b/wip/shot.usda"]
    for order in (given, given[::-1]):  # whichever path comes first (its configuration)
        _, named = _check(tree, "--force-exclude", *order)
        kept = [os.path.normpath(entry["file"]) for entry in named["files"]]
        assert sorted(kept) == sorted(name for name in names if name.endswith(".usda"))
    # The editor leaves alone what the walk skips, and lints what it lints.
    (tree / "shows" / "legacy" / ".usdrender-lint.toml").write_text(
        'profile = "karma"\nforce-exclude = true\n'
    )
    (tree / "shows" / "a" / ".usdrender-lint.toml").write_text(SHOW_A + "force-exclude = true\n")
    documents = Documents()
    for show, linted in (("legacy", False), ("a", True)):
        name = str(tree / "shows" / show / "lookdev_wip.usda")
        documents.update({name: Path(name).read_text(encoding="utf-8")})
        assert bool(documents.lint(name).findings) is linted
        documents.update({name: None})


def test_the_fixable_counts_are_each_files_own_configurations(tree: Path) -> None:
    """Show a marks SE007 unfixable and show b does not: the split run counts each
    file's fixes as its own show's run counts them."""

    def counts(*paths: str) -> tuple[int, int]:
        result = invoke_in(tree, "check", "--no-cache", "--jobs", "1", *paths)
        summary = result.stdout.strip().splitlines()[-1]
        safe = re.search(r"(\d+) fixable with --fix", summary)
        unsafe = re.search(r"(\d+) more with --unsafe-fixes", summary)
        return (int(safe[1]) if safe else 0, int(unsafe[1]) if unsafe else 0)

    alone = [counts(path) for path in ("shows/a", "shows/b", "shows/c_clean.usda")]
    assert alone[0] != alone[1]  # the two shows count SE007 differently
    assert counts(".") == tuple(map(sum, zip(*alone, strict=True)))


def test_a_folder_walked_below_a_show_is_judged_by_that_shows_configuration(tree: Path) -> None:
    """Whichever path comes first: a folder given below show b is walked with show
    b's exclusions, not those of the first path's configuration."""
    (tree / "shows" / "a" / ".usdrender-lint.toml").write_text(
        SHOW_A + 'extend-exclude = ["*_wip.usda"]\n'
    )
    for show in ("a", "b"):
        (tree / "shows" / show / "seq").mkdir()
        shutil.copy(BROKEN / "shot.usda", tree / "shows" / show / "seq" / "x_wip.usda")
    for order in (["shows/a/seq", "shows/b/seq"], ["shows/b/seq", "shows/a/seq"]):
        shown = invoke_in(tree, "check", "--show-files", *order).stdout.splitlines()
        assert shown == ["shows/b/seq/x_wip.usda"]


def test_the_counting_notes_of_a_split_run_are_its_totals(tmp_path: Path) -> None:
    """Each show's part had said its own count, and equal counts were merged
    into one: --diff said 2 fixes would be applied where 4 would."""
    for show in ("a", "b"):
        shutil.copytree(BROKEN, tmp_path / show)
        (tmp_path / show / ".usdrender-lint.toml").write_text('select = ["CA004", "SE007"]\n')
    result = invoke_in(tmp_path, "check", "--no-cache", "--jobs", "1", "--diff", ".")
    assert result.exit_code == 1, result.output
    assert result.stderr.splitlines() == ["usdrender-lint: --diff: 4 fixes would be applied"]


def _reads_of_configurations(monkeypatch: pytest.MonkeyPatch, root: Path) -> dict[str, int]:
    """How often each configuration file below ``root`` is opened (config.py
    opens them with os.open), by its path relative to ``root``."""
    counts: dict[str, int] = {}
    opened = os.open

    def counting(path, *args, **kwargs):
        name = os.fspath(path)
        if name.endswith(".toml") and name.startswith(str(root)):
            relative = os.path.relpath(name, root)
            counts[relative] = counts.get(relative, 0) + 1
        return opened(path, *args, **kwargs)

    monkeypatch.setattr(os, "open", counting)
    return counts


@pytest.mark.parametrize(
    "command",
    [
        ("check", "--no-cache", "--jobs", "1"),
        ("check", "--show-files"),
        ("check", "--show-settings"),
        ("spec", "--output", "-"),
    ],
)
def test_a_run_reads_each_configuration_file_once(
    tree: Path, monkeypatch: pytest.MonkeyPatch, command: tuple[str, ...]
) -> None:
    # The root's was read six times and each show's four in one check: the
    # search, each walked folder's exclusions and each part read them again.
    counts = _reads_of_configurations(monkeypatch, tree)
    # and parsed once: tomllib.loads of each file's text
    texts = {ROOT: ".usdrender-lint.toml", SHOW_A: "shows/a/.usdrender-lint.toml"}
    texts[SHOW_B] = "shows/b/pyproject.toml"
    parsed: dict[str, int] = {}
    loads = tomllib.loads

    def counting_loads(text: str, **kwargs):
        if text in texts:
            parsed[texts[text]] = parsed.get(texts[text], 0) + 1
        return loads(text, **kwargs)

    monkeypatch.setattr(tomllib, "loads", counting_loads)
    result = invoke_in(tree, *command, ".")
    # spec exits 2: the broken shots' lighting_wip.usda cannot be read.
    assert result.exit_code in (0, 1, 2) and "toml" not in result.stderr, result.output
    once = {
        ".usdrender-lint.toml": 1,
        "shows/a/.usdrender-lint.toml": 1,
        "shows/b/pyproject.toml": 1,
    }
    assert counts == once
    assert parsed == once


def test_the_json_report_names_each_files_configuration(tree: Path, tmp_path: Path) -> None:
    # A report of a tree of shows did not say which configuration judged a file.
    _status, report = _check(tree, ".")
    by_file = {entry["file"]: entry["config_file"] for entry in report["files"]}
    assert by_file["shows/a/shots/010/shot.usda"] == "shows/a/.usdrender-lint.toml"
    assert by_file["shows/b/shots/010/shot.usda"] == "shows/b/pyproject.toml"
    assert by_file["shows/c_clean.usda"] == ".usdrender-lint.toml"
    _status, isolated = _check(tree, "--isolated", "shows/c_clean.usda")
    assert isolated["files"][0]["config_file"] is None
    # merge keeps it, as check wrote it.
    shard = tmp_path / "shard.json"
    shard.write_text(json.dumps(report))
    merged = invoke_in(tree, "merge", "--format", "json", str(shard))
    assert merged.exit_code in (0, 1), merged.output
    again = {entry["file"]: entry["config_file"] for entry in json.loads(merged.stdout)["files"]}
    assert again == by_file


def _shared_sublayer_shows(root: Path, configs: dict[str, str]) -> Path:
    """A show per configuration, each a shot sublayering common/base.usda (an
    SE006 in it); the common folder."""
    common = root / "common"
    common.mkdir()
    (common / "base.usda").write_text(
        '#usda 1.0\n\ndef Scope "Render"\n{\n    def RenderSettings "Settings"\n    {\n'
        '        uniform token aspectRatioConformPolicy = "cropaperture"\n    }\n}\n'
    )
    for show, config in configs.items():
        (root / show).mkdir()
        (root / show / ".usdrender-lint.toml").write_text(config)
        (root / show / "shot.usda").write_text(
            '#usda 1.0\n(\n    renderSettingsPrimPath = "/Render/Settings"\n'
            "    subLayers = [@../common/base.usda@]\n)\n"
        )
    return common


def test_a_split_fix_reports_a_shared_layer_as_the_last_part_left_it(tmp_path: Path) -> None:
    """Shows a and b compose one sublayer; a marks SE006 unfixable, b fixes it.
    Each part had fixed and then linted in turn, so show a's report still had
    the SE006 that b's part then fixed: a finding of no file, exit 1."""
    common = _shared_sublayer_shows(
        tmp_path, {"a": 'unfixable = ["SE006"]\n', "b": 'select = ["SE006"]\n'}
    )

    def se006(document: dict) -> list[str]:
        return [r["file"] for r in document["files"] for f in r["findings"] if f["code"] == "SE006"]

    _, before = _check(tmp_path, "a", "b")
    assert se006(before) == ["a/shot.usda", "b/shot.usda"]
    code, fixed = _check(tmp_path, "--fix", "a", "b")
    assert '"cropAperture"' in (common / "base.usda").read_text()
    assert se006(fixed) == []
    assert code == 0


def test_a_split_diff_shows_a_shared_layer_once(tmp_path: Path) -> None:
    """Shows a and b compose one sublayer and both fix its SE006: each part's
    --diff had printed the same patch of it (the second copy does not apply)
    and counted the fix again, where --fix writes it once."""
    _shared_sublayer_shows(tmp_path, {"a": 'select = ["SE006"]\n', "b": 'select = ["SE006"]\n'})
    result = invoke_in(tmp_path, "check", "--no-cache", "--jobs", "1", "--diff", "a", "b")
    assert result.exit_code == 1, result.output
    assert result.stdout.count("--- common/base.usda") == 1, result.stdout
    assert result.stderr.splitlines() == ["usdrender-lint: --diff: 1 fix would be applied"]


def test_a_split_fix_lints_every_part_in_one_set_of_workers(tmp_path: Path, monkeypatch) -> None:
    """Fixing ran each part's fixes and then its lint, one part after another,
    each lint with workers of its own (about 200 ms a configuration past the
    first, measured): now every part is fixed, then all are linted together."""
    from usdrender_lint.running import pipeline

    _shared_sublayer_shows(tmp_path, {"a": 'select = ["SE006"]\n', "b": 'select = ["SE006"]\n'})
    asked: list[list[str]] = []
    lint_as_asked = pipeline.lint_as_asked

    def counted(execution, files, *args):
        asked.append(list(files))
        return lint_as_asked(execution, files, *args)

    monkeypatch.setattr(pipeline, "lint_as_asked", counted)
    result = invoke_in(tmp_path, "check", "--no-cache", "--jobs", "2", "--fix", "a", "b")
    assert result.exit_code == 0, result.output
    assert asked == [["a/shot.usda", "b/shot.usda"]]
