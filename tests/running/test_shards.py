"""check --shard K/N (running/shards.py) and usdrender-lint merge (running/merge.py):
the shards partition the files deterministically and evenly, a shot stays with
its roots, and the merged JSON reports are the report of one unsharded run."""

from __future__ import annotations

import hashlib
import json
import os
import random
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.running.shards import (
    ShardError,
    assign,
    parse_shard,
    partition,
    select_shard,
    shard_key,
)

pytestmark = pytest.mark.heavy(seconds=55)

REPO = Path(__file__).resolve().parents[2]


def _shot(index: int, bad: bool) -> str:
    window = "(1, 1, 0, 0)" if bad else "(0, 0, 1, 1)"
    return f"""#usda 1.0
def Scope "Render"
{{
    def RenderSettings "Settings_{index}"
    {{
        uniform float4 dataWindowNDC = {window}
    }}
}}
"""


@pytest.fixture
def project(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A checkout of 23 shots in nested folders, a third of them with an error."""
    root = tmp_path / "project"
    for i in range(23):
        folder = root / "shots" / f"seq{i % 4}"
        folder.mkdir(parents=True, exist_ok=True)
        (folder / f"shot_{i:02d}.usda").write_text(_shot(i, bad=i % 3 == 0))
    (root / "pyproject.toml").write_text("[tool.usdrender-lint]\n")
    monkeypatch.chdir(root)
    return root


def _check(*args: str) -> tuple[int, str]:
    result = CliRunner().invoke(cli, ["check", *args])
    return result.exit_code, result.stdout


def _files(json_text: str) -> list[str]:
    return [entry["file"] for entry in json.loads(json_text)["files"]]


# -- partitioning -----------------------------------------------------------------------


def test_shard_values_are_k_of_n() -> None:
    assert parse_shard("2/4") == (2, 4) and parse_shard(" 1/1 ") == (1, 1)
    for bad in ("0/2", "3/2", "2", "a/b", "1/0", "-1/2", ""):
        with pytest.raises(ShardError):
            parse_shard(bad)


@pytest.mark.parametrize("value", ["0/2", "3/2", "two"])
def test_a_bad_shard_is_a_usage_error(project: Path, value: str) -> None:
    result = CliRunner().invoke(cli, ["check", "--shard", value, "shots"])
    assert result.exit_code == 2
    assert "--shard" in result.stderr and "Traceback" not in result.stderr


@pytest.mark.parametrize("count", [1, 2, 3, 4, 7])
def test_the_shards_partition_the_files_and_differ_by_at_most_one(
    project: Path, count: int
) -> None:
    everything = _files(_check("--format", "json", "shots")[1])
    shards = [
        _files(_check("--format", "json", "--shard", f"{k}/{count}", "shots")[1])
        for k in range(1, count + 1)
    ]
    assert sorted(f for shard in shards for f in shard) == sorted(everything)
    assert sum(len(shard) for shard in shards) == len(everything)  # disjoint
    sizes = [len(shard) for shard in shards]
    assert max(sizes) - min(sizes) <= 1
    assert max(sizes) <= 2 * max(1, min(sizes))


def test_a_shard_does_not_depend_on_the_argument_order_or_the_checkout_location(
    project: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    folders = [f"shots/seq{i}" for i in range(4)]
    first = _files(_check("--format", "json", "--shard", "2/3", *folders)[1])
    shuffled = folders[:]
    random.Random(7).shuffle(shuffled)
    again = _files(_check("--format", "json", "--shard", "2/3", *shuffled)[1])
    assert sorted(again) == sorted(first)
    moved = tmp_path / "elsewhere" / "checkout"
    shutil.copytree(project, moved)
    monkeypatch.chdir(moved)
    assert sorted(_files(_check("--format", "json", "--shard", "2/3", *folders)[1])) == sorted(
        first
    )
    # Named from another working directory, the files are the same ones.
    monkeypatch.chdir(moved.parent)
    named = _files(_check("--format", "json", "--shard", "2/3", "checkout/shots")[1])
    assert sorted(Path(p).relative_to("checkout").as_posix() for p in named) == sorted(first)


def test_groups_that_stay_together_are_balanced_largest_first(tmp_path: Path) -> None:
    units = [["a", "b", "c", "d"], ["e"], ["f", "g"], ["h"], ["i"], ["j", "k"]]
    shards = [partition(units, 2, tmp_path, k) for k in (1, 2)]
    sizes = [sum(len(units[i]) for i in shard) for shard in shards]
    assert sorted(sizes) == [5, 6]
    assert sorted(i for shard in shards for i in shard) == list(range(len(units)))
    assert select_shard([], (1, 3), tmp_path) == []


def test_a_shard_costs_the_same_whatever_the_shard_count(tmp_path: Path) -> None:
    """Shards still empty are never held: 1e23 shards cost what 10 do (this
    took over 300 s for 1e7 and never ended for 1e23)."""
    units = [["a", "b"], ["c"], ["d"], ["e", "f", "g"]]
    huge = 10**23
    assert assign(units, huge, tmp_path) == assign(units, len(units), tmp_path)
    assert sorted(assign(units, huge, tmp_path)) == [0, 1, 2, 3]
    files = [f"f{i}.usda" for i in range(5)]
    picked = [select_shard(files, (k, huge), tmp_path) for k in (1, 2, 3, 4, 5, 6, huge)]
    assert sorted(f for shard in picked for f in shard) == sorted(files)
    assert picked[-2:] == [[], []]
    # The greedy rule is the one it was: the fewest files, then the lowest index.
    assert assign([["a", "b", "c"], ["d"], ["e"], ["f"]], 2, tmp_path) == [0, 1, 1, 1]
    # Which single goes where follows the files' shard keys (they hash the paths).
    pair_first = assign([["a", "b"], ["d"], ["e"], ["f"]], 2, tmp_path)
    assert pair_first[0] == 0 and sorted(pair_first[1:]) == [0, 1, 1]


def test_a_huge_shard_count_from_the_command_line(project: Path) -> None:
    status, out = _check("--format", "json", "--shard", f"{10**23}/{10**23}", "shots")
    assert status == 0 and _files(out) == []


def test_a_shot_stays_with_its_roots(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """With config roots, changed layers are linted inside the roots that use
    them: roots that share a changed layer go to one shard, and the merged
    shards report exactly what one run does (findings a shared layer causes
    are reported once, as without shards)."""
    root = tmp_path / "project"
    (root / "shared").mkdir(parents=True)
    (root / "shared" / "look.usda").write_text(
        '#usda 1.0\nover "Render"\n{\n    over "Settings"\n    {\n'
        "        uniform float4 dataWindowNDC = (1, 1, 0, 0)\n    }\n}\n"
    )
    for i in range(6):
        shot = root / "shots" / f"s{i}"
        shot.mkdir(parents=True)
        sublayer = "@../../shared/look.usda@" if i < 3 else "@./own.usda@"
        (shot / "own.usda").write_text('#usda 1.0\ndef "World"\n{\n}\n')
        (shot / "shot.usda").write_text(
            f'#usda 1.0\n(\n    subLayers = [{sublayer}]\n)\ndef Scope "Render"\n{{\n'
            '    def RenderSettings "Settings"\n    {\n    }\n}\n'
        )
    (root / "pyproject.toml").write_text('[tool.usdrender-lint]\nroots = ["shots/*/shot.usda"]\n')
    monkeypatch.chdir(root)
    changed = ["shared/look.usda", *[f"shots/s{i}/own.usda" for i in range(3, 6)]]
    whole = json.loads(_check("--format", "json", *changed)[1])
    reports = []
    for k in (1, 2, 3):
        code, text = _check("--format", "json", "--shard", f"{k}/3", *changed)
        (root / f"r{k}.json").write_text(text)
        reports.append(json.loads(text))
    holders = {
        i
        for i, report in enumerate(reports)
        for entry in report["files"]
        if entry["file"] in ("shots/s0/shot.usda", "shots/s1/shot.usda", "shots/s2/shot.usda")
    }
    assert len(holders) == 1, "the roots that share look.usda are in one shard"
    merged = CliRunner().invoke(cli, ["merge", "--format", "json", "r1.json", "r2.json", "r3.json"])
    expected = sorted(whole["files"], key=lambda entry: entry["file"])
    assert json.loads(merged.stdout)["files"] == expected
    assert (
        sum(
            1
            for f in json.loads(merged.stdout)["files"]
            for x in f["findings"]
            if x["code"] == "SE003"
        )
        == 1
    )


# -- merge ------------------------------------------------------------------------------


def _sharded_reports(count: int, *extra: str) -> list[str]:
    names = []
    for k in range(1, count + 1):
        name = f"report-{k}.json"
        code, _ = _check(
            "--format", "json", "--output", name, "--shard", f"{k}/{count}", *extra, "shots"
        )
        assert code in (0, 1)
        names.append(name)
    return names


@pytest.mark.parametrize("fmt", ["json", "sarif", "text", "github"])
def test_merged_shards_are_the_report_of_one_run(project: Path, fmt: str) -> None:
    code, whole = _check("--format", fmt, "shots")
    merged = CliRunner().invoke(cli, ["merge", "--format", fmt, *reversed(_sharded_reports(3))])
    assert merged.exit_code == code == 1
    assert merged.stdout == whole


def test_merge_keeps_statistics_info_and_fail_on_like_check(project: Path) -> None:
    reports = _sharded_reports(2)
    for flags in (["--statistics"], ["--show-info"], ["--fail-on", "never"]):
        code, whole = _check(*flags, "shots")
        merged = CliRunner().invoke(cli, ["merge", *flags, *reports])
        assert (merged.exit_code, merged.stdout) == (code, whole), flags
    assert CliRunner().invoke(cli, ["merge", "--fail-on", "never", *reports]).exit_code == 0


def test_merge_refuses_reports_of_different_configurations(project: Path) -> None:
    """A shard linted under --select CA merged with full shards made a smaller
    report, silently: the configuration digest tells them apart."""
    full = _sharded_reports(2)
    assert _check(
        "--format", "json", "--output", "narrow.json", "--shard", "1/2", "--select", "SE", "shots"
    )[0] in (0, 1)
    result = CliRunner().invoke(cli, ["merge", "narrow.json", full[1]])
    assert result.exit_code == 2
    assert result.stderr == (
        "usdrender-lint: error: narrow.json and report-2.json were made with different "
        "configurations (rules, options, settings or baseline): lint every part with the same "
        "ones\n"
    )
    # A baseline, a profile or a setting from the config file count too.
    _check("--write-baseline", "base.json", "shots")
    for flags in (["--baseline", "base.json"], ["--profile", "karma"], ["--variants"]):
        _check("--format", "json", "--output", "other.json", "--shard", "1/2", *flags, "shots")
        result = CliRunner().invoke(cli, ["merge", full[0], "other.json"])
        assert result.exit_code == 2 and "different configurations" in result.stderr, flags


def test_merge_refuses_reports_of_different_versions(project: Path) -> None:
    reports = _sharded_reports(2)
    document = json.loads(Path(reports[1]).read_text())
    document["tool"]["version"] = "0.0.1"
    Path("old.json").write_text(json.dumps(document))
    result = CliRunner().invoke(cli, ["merge", reports[0], "old.json"])
    assert result.exit_code == 2
    assert "report-1.json and old.json were made by different versions" in result.stderr


def test_merge_refuses_reports_that_disagree_about_a_file(project: Path) -> None:
    """Both reports hold a file with different findings: the first was kept,
    silently. Reports that agree about a file merge (a shard given twice)."""
    reports = _sharded_reports(2)
    twice = CliRunner().invoke(cli, ["merge", "--format", "json", reports[0], *reports])
    once = CliRunner().invoke(cli, ["merge", "--format", "json", *reports])
    assert twice.exit_code == once.exit_code == 1 and twice.stdout == once.stdout
    document = json.loads(Path(reports[0]).read_text())
    entry = next(e for e in document["files"] if e["findings"])
    entry["findings"] = entry["findings"][1:]
    Path("edited.json").write_text(json.dumps(document))
    result = CliRunner().invoke(cli, ["merge", reports[0], "edited.json", reports[1]])
    assert result.exit_code == 2 and result.stdout == ""
    findings = len(entry["findings"])
    assert result.stderr.startswith(
        f"usdrender-lint: error: report-1.json and edited.json disagree about {entry['file']} ("
        f"{findings + 1} findings vs {findings} finding"
    )
    assert result.stderr.count("\n") == 1


def test_merge_of_a_deeply_nested_report_is_one_line(project: Path) -> None:
    Path("deep.json").write_text("[" * 200_000 + "]" * 200_000)
    result = CliRunner().invoke(cli, ["merge", "deep.json"])
    assert result.exit_code == 2
    assert result.stderr == (
        "usdrender-lint: error: deep.json: not a report: JSON nested too deeply\n"
    )


def test_the_combined_exit_status(project: Path, tmp_path: Path) -> None:
    clean = project / "clean"
    clean.mkdir()
    (clean / "a.usda").write_text(_shot(0, bad=False))
    assert _check("--format", "json", "--output", "clean.json", "clean")[0] == 0
    assert CliRunner().invoke(cli, ["merge", "clean.json"]).exit_code == 0
    reports = _sharded_reports(2)
    assert CliRunner().invoke(cli, ["merge", "clean.json", *reports]).exit_code == 1
    error = (
        "--format",
        "json",
        "--output",
        "error.json",
        "clean",
        "missing.usda",
    )
    assert _check(*error)[0] == 2
    merged = CliRunner().invoke(cli, ["merge", "clean.json", "error.json", *reports])
    assert merged.exit_code == 2
    assert "missing.usda: no such file" in merged.stderr


@pytest.mark.parametrize(
    "content, message",
    [
        (None, "cannot read"),
        ("not json", "not JSON"),
        ('{"schema_version": 2, "files": []}', "schema_version 2"),
        ('{"schema_version": 1, "files": [{"file": "a"}]}', "'status'"),
        ("[]", "not a JSON object"),
        (
            '{"schema_version": 1, "files": [{"file": "a", "status": "computed"}]}',
            "a document of 'usdrender-lint spec', not a check report",
        ),
    ],
    ids=["missing", "not-json", "future-schema", "bad-entry", "not-an-object", "spec"],
)
def test_a_report_merge_cannot_read_is_one_line_and_exit_2(
    project: Path, content: str | None, message: str
) -> None:
    if content is not None:
        (project / "bad.json").write_text(content)
    result = CliRunner().invoke(cli, ["merge", "bad.json"])
    assert result.exit_code == 2
    assert result.stderr.startswith("usdrender-lint: error: bad.json") and message in result.stderr
    assert result.stderr.count("\n") == 1


def test_merge_writes_its_output_atomically_and_reads_fixes(project: Path) -> None:
    reports = _sharded_reports(2)
    result = CliRunner().invoke(
        cli, ["merge", "--format", "sarif", "--output", "all.sarif", *reports]
    )
    assert result.exit_code == 1 and result.stdout == ""
    sarif = json.loads((project / "all.sarif").read_text())
    windows = [r for r in sarif["runs"][0]["results"] if r["ruleId"] == "SE003"]
    assert len(windows) == 8  # shots 0, 3, ..., 21
    assert len(sarif["runs"][0]["tool"]["driver"]["rules"]) > 50  # the rules that ran
    fixed = _check(
        "--format",
        "json",
        "--diff",
        "--unsafe-fixes",
        "--output",
        "diff.json",
        "--select",
        "SE003",
        "shots/seq0",
    )
    assert fixed[0] == 1
    merged = CliRunner().invoke(cli, ["merge", "--format", "json", "diff.json"])
    assert len(json.loads(merged.stdout)["fixes"]) == 2  # shots 0 and 12 of seq0
    assert (
        json.loads(merged.stdout)["fixes"]
        == json.loads((project / "diff.json").read_text())["fixes"]
    )


def test_the_configuration_digest_is_the_same_on_every_machine() -> None:
    """Options printed with an object's address (a plugin's class without a
    repr) must not make the shards of one CI run look like two runs."""
    from usdrender_lint.config import Settings
    from usdrender_lint.running.merge import configuration_digest

    class Options:
        pass

    class Rule:
        code = "XX001"

        def __init__(self) -> None:
            self.options = Options()

    one, other = Rule(), Rule()
    assert repr(one.options) != repr(other.options)
    settings = Settings()
    assert configuration_digest(settings, [one]) == configuration_digest(settings, [other])  # type: ignore[list-item]
    assert configuration_digest(settings, [one]) != configuration_digest(
        Settings(select=("CA",)),
        [one],  # type: ignore[list-item]
    )


# -- a shard report records its shard, and merge needs every shard -------------------------


def _merge(*args: str):
    return CliRunner().invoke(cli, ["merge", *args])


def test_a_shard_report_records_its_shard(project: Path) -> None:
    reports = _sharded_reports(3)
    shards = [json.loads(Path(name).read_text())["shard"] for name in reports]
    assert shards == [{"index": k, "count": 3} for k in (1, 2, 3)]
    assert "shard" not in json.loads(_check("--format", "json", "shots")[1])
    assert "shard" not in json.loads(_merge("--format", "json", *reports).stdout)


def _one_line_refusal(result, *parts: str) -> None:
    assert result.exit_code == 2 and result.stdout == ""
    assert result.stderr.startswith("usdrender-lint: error: ") and result.stderr.count("\n") == 1
    for part in parts:
        assert part in result.stderr, result.stderr


def test_merge_refuses_a_missing_shard(project: Path) -> None:
    """A shard job that failed or was cancelled left no report: merging the
    others passed, gating on part of the files."""
    reports = _sharded_reports(3)
    for given, missing in (
        ([reports[1]], "2 of 3 shards missing (1/3, 3/3)"),
        ([reports[0], reports[2]], "1 of 3 shards missing (2/3)"),
    ):
        _one_line_refusal(_merge(*given), missing, "every shard 1/3 to 3/3")
    # An unsharded report does not stand in for a missing shard.
    _check("--format", "json", "--output", "whole.json", "shots")
    _one_line_refusal(_merge("whole.json", reports[0]), "missing (2/3, 3/3)")


def test_merge_refuses_shards_of_different_counts(project: Path) -> None:
    halves = _sharded_reports(2)
    Path(halves[0]).rename("half-1.json")
    thirds = _sharded_reports(3)
    _one_line_refusal(
        _merge("half-1.json", *thirds),
        "half-1.json is shard 1/2 and report-1.json is shard 1/3",
        "same --shard count",
    )


def test_merge_refuses_two_different_reports_of_one_shard(project: Path) -> None:
    """Two reports of shard 1/2 that agree about the files both hold but not
    about which files there are (a shard run on another checkout)."""
    reports = _sharded_reports(2)
    document = json.loads(Path(reports[0]).read_text())
    document["files"] = document["files"][1:]
    Path("fewer.json").write_text(json.dumps(document))
    _one_line_refusal(
        _merge(reports[0], "fewer.json", reports[1]),
        "report-1.json and fewer.json are both shard 1/2",
    )


def test_merge_reads_a_shard_given_twice_once(project: Path) -> None:
    reports = _sharded_reports(2)
    once = _merge("--format", "json", *reports)
    twice = _merge("--format", "json", *reports, *reversed(reports))
    assert once.exit_code == twice.exit_code == 1 and once.stdout == twice.stdout
    # With whole-run reports besides, as before shards were recorded.
    _check("--format", "json", "--output", "whole.json", "shots")
    alongside = _merge("--format", "json", "whole.json", *reports)
    assert (alongside.exit_code, alongside.stdout) == (1, once.stdout)
    assert (_merge("--format", "json", "whole.json").stdout) == once.stdout


def test_merge_counts_a_fix_several_reports_hold_once(project: Path) -> None:
    """The files of a report given twice were kept once, its fixes twice:
    '2 fixes applied' became 4."""
    _check("--format", "json", "--fix", "--select", "SE003", "--unsafe-fixes",
           "--output", "fixed.json", "shots/seq0")  # fmt: skip
    fixes = json.loads(Path("fixed.json").read_text())["fixes"]
    assert len(fixes) == 2  # shots 0 and 12 of seq0
    twice = _merge("--format", "json", "fixed.json", "fixed.json")
    assert json.loads(twice.stdout)["fixes"] == fixes
    assert "2 fixes applied" in _merge("fixed.json", "fixed.json").stdout


def test_merge_refuses_standard_input_in_one_line(project: Path) -> None:
    # '-' is standard input to check: merge said "-: cannot read: No such file
    # or directory", as if a file named '-' were missing.
    reports = _sharded_reports(2)
    result = CliRunner().invoke(cli, ["merge", "-", *reports], input=Path(reports[0]).read_text())
    _one_line_refusal(result, "merge reads report files, not standard input ('-')")


@pytest.mark.parametrize("shard", ["1/2", {"index": 3, "count": 2}, {"index": True, "count": 1}])
def test_merge_refuses_a_shard_it_cannot_read(project: Path, shard: object) -> None:
    reports = _sharded_reports(2)
    document = json.loads(Path(reports[0]).read_text())
    document["shard"] = shard
    Path("odd.json").write_text(json.dumps(document))
    _one_line_refusal(_merge("odd.json", reports[1]), "odd.json: 'shard' is not")


# -- names that are not UTF-8 -----------------------------------------------------------

#: A name that is not UTF-8, a name with a backslash, and a plain one.
NAMES = (b"bad\xff\xfe.usda", b"back\\slash.usda", b"plain.usda")


@pytest.fixture
def odd_names(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    root = tmp_path / "odd"
    (root / "h").mkdir(parents=True)
    (root / "pyproject.toml").write_text("[tool.usdrender-lint]\n")
    for i, name in enumerate(NAMES):
        try:
            with open(os.path.join(os.fsencode(root / "h"), name), "wb") as stream:
                stream.write(_shot(i, bad=True).encode())
        except (OSError, UnicodeError):
            pytest.skip("this file system keeps only UTF-8 names")
    (root / "h" / "broken.usda").write_text("#usda 1.0\ndef {\n")
    monkeypatch.chdir(root)
    return root


def test_a_name_that_is_not_utf8_lands_in_one_shard(odd_names: Path) -> None:
    """check --shard crashed (UnicodeEncodeError) hashing such a name."""
    everything = _files(_check("--format", "json", "h")[1])
    assert len(everything) == 4
    for count in (2, 3):
        shards = []
        for k in range(1, count + 1):
            status, out = _check("--format", "json", "--shard", f"{k}/{count}", "h")
            assert status == 1, out
            shards.append(_files(out))
            listed = CliRunner().invoke(
                cli, ["check", "--show-files", "--shard", f"{k}/{count}", "h"]
            )
            assert listed.exit_code == 0 and sorted(listed.stdout.splitlines()) == sorted(
                shards[-1]
            )
        assert sorted(f for shard in shards for f in shard) == sorted(everything)
    # The key is the hash of the name's bytes on disk, the same on every machine.
    assert (
        shard_key(os.fsdecode(b"h/bad\xff\xfe.usda"), odd_names)
        == hashlib.sha256(b"h/bad\xff\xfe.usda").hexdigest()
    )


@pytest.mark.parametrize(
    "fmt", ["json", "sarif", "text", "full", "github", "gitlab", "junit", "html"]
)
def test_merge_names_files_that_are_not_utf8_as_check_does(odd_names: Path, fmt: str) -> None:
    """The JSON report holds such a name escaped (``bad\\xff\\xfe.usda``):
    merge read the escape as the name, so its SARIF URI, GitLab fingerprint
    and every other format named another file than check."""
    code, whole = _check("--show-info", "--format", fmt, "h")
    assert "bad" in whole
    _check("--format", "json", "--output", "whole.json", "h")
    for k in (1, 2):
        _check("--format", "json", "--output", f"part-{k}.json", "--shard", f"{k}/2", "h")
    for reports in (["whole.json"], ["part-2.json", "part-1.json"]):
        merged = _merge("--show-info", "--format", fmt, *reports)
        assert (merged.exit_code, merged.stdout) == (code, whole), reports


def test_the_report_reader_inverts_escape(monkeypatch: pytest.MonkeyPatch) -> None:
    """restored() reads a string as escaped only when escape() gives it back:
    it follows escape() rather than a copy of its rules, so it stays its inverse
    if escape() doubles the backslash in every name, not only in names that
    are not UTF-8."""
    from usdrender_lint import report_json
    from usdrender_lint.paths import escape

    names = ["bad\udcff\udcfe.usda", "a\\b.usda", "x\udcff\\y", "plain.usda", "é\\\\.usda"]
    for name in names:
        assert report_json.restored(escape(name)) == name, name
    for text in ("a\\q", "a\\x4", "a\\xFF", "lone\udcff", "a\\\\b"):
        assert report_json.restored(text) == text, text

    def every_backslash_doubled(text: str) -> str:
        raw = text.encode("utf-8", "surrogateescape").replace(b"\\", b"\\\\")
        return raw.decode("utf-8", "backslashreplace")

    monkeypatch.setattr(report_json, "escape", every_backslash_doubled)
    for name in [*names, "a\\xff.usda"]:
        assert report_json.restored(every_backslash_doubled(name)) == name, name


VARIANT_SHOT = """#usda 1.0
def Scope "Render" (
    prepend variantSets = ["q"]
    variants = {
        string q = "a"
    }
)
{
    def RenderSettings "S"
    {
    }
    variantSet "q" = {
        "a" {
        }
        "b" {
        }
        "c" {
        }
    }
}
"""


def test_a_files_notes_survive_the_json_report_and_merge(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """--variants' note of the combinations its cap skipped: check says it on
    stderr, the JSON report keeps it, and merge says it again."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "shot.usda").write_text(VARIANT_SHOT)
    args = ["check", "--isolated", "--no-cache", "--variants", "--max-variant-combinations", "2"]
    whole = CliRunner().invoke(cli, [*args, "shot.usda"])
    (said,) = [line for line in whole.stderr.splitlines() if "skipped" in line]
    reports = []
    for k in (1, 2):
        report = tmp_path / f"r{k}.json"
        CliRunner().invoke(
            cli,
            [*args, "--shard", f"{k}/2", "--format", "json", "--output", str(report), "shot.usda"],
        )
        reports.append(str(report))
    (entry,) = [e for r in reports for e in json.loads(Path(r).read_text())["files"]]
    assert entry["notes"] == [said.removeprefix("usdrender-lint: ")]
    merged = CliRunner().invoke(cli, ["merge", "--isolated", *reports])
    assert said in merged.stderr.splitlines()


def test_a_finding_without_a_severity_is_named_once(project: Path) -> None:
    (report,) = _sharded_reports(1)
    document = json.loads(Path(report).read_text())
    entry = next(f for f in document["files"] if f["findings"])
    del entry["findings"][0]["severity"]
    Path("edited.json").write_text(json.dumps(document))
    index = document["files"].index(entry)
    _one_line_refusal(
        _merge("edited.json"),
        f"usdrender-lint: error: edited.json: files[{index}].findings[0]: "
        "'severity' is missing or not a str\n",
    )


def test_merge_config_judges_the_files_as_check_under_it(project: Path) -> None:
    """``merge --config FILE`` took that configuration's fail-on and the rules a
    SARIF report describes, but not what check applies after linting: its
    per-path ignores and unfixable rules. Shards linted under another
    configuration merged into a report that showed the findings and offered the
    fixes a check under FILE leaves out ("2 fixable" where check said none)."""
    reports = _sharded_reports(2, "--isolated")
    Path("strict.toml").write_text(
        'unfixable = ["SE003"]\n\n[per-path-ignores]\n"shots/seq1/*" = ["SE003"]\n'
    )
    for fmt in ("sarif", "text", "html"):
        code, whole = _check("--config", "strict.toml", "--format", fmt, "shots")
        merged = _merge("--config", "strict.toml", "--format", fmt, *reports)
        assert (merged.exit_code, merged.stdout) == (code, whole), fmt
    _code, whole = _check("--config", "strict.toml", "--format", "json", "shots")
    merged = _merge("--config", "strict.toml", "--format", "json", *reports)
    findings = [
        [f for e in json.loads(t)["files"] for f in e["findings"]] for t in (whole, merged.stdout)
    ]
    assert findings[0] == findings[1]
    assert all(f["fix"] is None for f in findings[1] if f["code"] == "SE003")
    assert not any("seq1" in f["file"] and f["code"] == "SE003" for f in findings[1])
    assert any(f["code"] == "SE003" for f in findings[1])


def test_merged_shards_describe_the_configuration_s_unfixable_rules_as_check(
    project: Path,
) -> None:
    # The CI workflow (merge --format sarif of the shards, no --config): the
    # merged SARIF described SE003 with its class ("unsafe"), check's with "none".
    (project / "pyproject.toml").write_text('[tool.usdrender-lint]\nunfixable = ["SE003"]\n')
    code, whole = _check("--format", "sarif", "shots")
    merged = _merge("--format", "sarif", *_sharded_reports(2))
    assert (merged.exit_code, merged.stdout) == (code, whole)
    described = json.loads(whole)["runs"][0]["tool"]["driver"]["rules"]
    assert [r["properties"]["fix"] for r in described if r["id"] == "SE003"] == ["none"]


def test_merge_from_another_folder_reads_the_configuration_the_shards_record(
    project: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The shards record their configuration relative to the folder they ran
    in; a merge run from another folder did not find it and silently described
    the rules without it (SE003 fixable, at its default level)."""
    (project / "pyproject.toml").write_text(
        '[tool.usdrender-lint]\nunfixable = ["SE003"]\n\n[tool.usdrender-lint.severity]\n'
        'SE003 = "warning"\n'
    )
    reports = [str(project / name) for name in _sharded_reports(2)]

    def described(result) -> tuple[list, list]:
        run = json.loads(result.stdout)["runs"][0]
        rules = run["tool"]["driver"]["rules"]
        fixes = [r["properties"]["fix"] for r in rules if r["id"] == "SE003"]
        return fixes, run["invocations"][0].get("ruleConfigurationOverrides", [])

    here = described(_merge("--format", "sarif", *reports))
    assert here[0] == ["none"] and [o["descriptor"]["id"] for o in here[1]] == ["SE003"]
    elsewhere = project.parent / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    merged = _merge("--format", "sarif", *reports)
    assert described(merged) == here
    # Its locations name the files from here: said, with the folder to run it in.
    (said,) = merged.stderr.splitlines()
    assert said == (
        f"usdrender-lint: note: 23 files the reports name are not found from here but in "
        f"{project}, where their checks ran: the merged report names files from this folder "
        "(SARIF's and the HTML report's locations); run merge there"
    )
    # The folder they ran in is not here (another machine): said, not dropped.
    for name in reports:
        document = json.loads(Path(name).read_text())
        assert document["working_directory"] == str(project)
        document["working_directory"] = str(project.parent / "gone")
        Path(name).write_text(json.dumps(document))
    merged = _merge("--format", "sarif", *reports)
    assert merged.exit_code == 0  # SE003 a warning: its findings, as recorded
    (line,) = merged.stderr.splitlines()
    assert line.startswith(
        "usdrender-lint: note: pyproject.toml: the configuration file the reports record for "
        f"23 files is not found from here nor in {project.parent / 'gone'}"
    )
    # Shards of another checkout of the tree (another machine's folder) name
    # files found here: nothing to say.
    monkeypatch.chdir(project)
    assert _merge("--format", "sarif", *reports).stderr == ""
    monkeypatch.chdir(elsewhere)
    # A folder this system cannot name (another system's) is not one to look in.
    for name in reports:
        document = json.loads(Path(name).read_text())
        document["working_directory"] = "C:\\checkout"
        Path(name).write_text(json.dumps(document))
    (line,) = _merge("--format", "sarif", *reports).stderr.splitlines()
    assert "23 files is not found from here: merge cannot read again" in line
