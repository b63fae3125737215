"""``merge --config FILE`` judges the merged findings as ``check --config FILE``
would: its selection and severities as well as its per-path ignores and
unfixable rules. A rule the shards did not run cannot be added: refused."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli

#: A real folder of several files with findings of many rules.
FOLDER = Path("corpus") / "files" / "PixarAnimationStudios__OpenUSD"


def _invoke(*args: str):
    return CliRunner().invoke(cli, [*args])


def _shards(folder: Path, count: int, *flags: str) -> list[str]:
    names = []
    for k in range(1, count + 1):
        name = f"shard-{k}.json"
        result = _invoke(
            "check", "--no-cache", "--format", "json", "--fail-on", "never", "--output", name,
            "--shard", f"{k}/{count}", *flags, str(folder),
        )  # fmt: skip
        assert result.exit_code == 0, result.output
        names.append(name)
    return names


def _document(text: str) -> dict:
    # The digest names the configuration the files were linted under: the
    # shards', which merge keeps (it compares them when the report is merged again).
    document = json.loads(text)
    del document["configuration"]
    return document


@pytest.fixture
def folder(shared_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(tmp_path)
    return shared_dir / FOLDER


def test_merge_config_ignores_and_sets_severities_as_check_does(folder: Path) -> None:
    """merge --config re-applied per-path-ignores and unfixable only: the
    merged report kept SE015's findings the configuration ignores and ST003's
    and CA006's severities as the shards' defaults had them."""
    Path("strict.toml").write_text(
        'ignore = ["SE015"]\n\n[severity]\nST003 = "warning"\nCA006 = "error"\n'
    )
    shards = _shards(folder, 3, "--isolated")
    codes = {f["code"] for s in shards for e in json.loads(Path(s).read_text())["files"]
             for f in e["findings"]}  # fmt: skip
    assert {"SE015", "ST003", "CA006"} <= codes  # what the configuration changes is there
    whole = _invoke("check", "--no-cache", "--config", "strict.toml", "--format", "json",
                    str(folder))  # fmt: skip
    merged = _invoke("merge", "--config", "strict.toml", "--format", "json", *shards)
    assert merged.exit_code == whole.exit_code == 1, merged.output
    assert merged.stderr == ""
    assert _document(merged.stdout) == _document(whole.stdout)
    for fmt in ("sarif", "text"):  # SARIF's rule configuration overrides too
        whole = _invoke("check", "--no-cache", "--config", "strict.toml", "--format", fmt,
                        str(folder))  # fmt: skip
        merged = _invoke("merge", "--config", "strict.toml", "--format", fmt, *shards)
        assert merged.stdout == whole.stdout, fmt


def test_merge_refuses_a_configuration_selecting_a_rule_the_shards_did_not_run(
    folder: Path,
) -> None:
    Path("lax.toml").write_text('ignore = ["SE015"]\n')
    shards = _shards(folder, 2, "--config", "lax.toml")
    merged = _invoke("merge", "--isolated", *shards)
    assert merged.exit_code == 2 and merged.stdout == ""
    assert merged.stderr == (
        "usdrender-lint: error: the configuration selects 1 rule the checks of these reports "
        "did not run (SE015): their findings cannot be added; lint with that configuration, "
        "or merge without it\n"
    )
    # The configuration they ran: merged as before.
    assert _invoke("merge", "--config", "lax.toml", *shards).exit_code == 1


def test_merge_says_when_the_reports_do_not_tell_which_rules_ran(folder: Path) -> None:
    # The checks' own --select is recorded only in the digest.
    shards = _shards(folder, 2, "--isolated", "--select", "ST")
    merged = _invoke("merge", "--isolated", *shards)
    assert merged.exit_code == 1
    (line,) = merged.stderr.splitlines()
    assert line.startswith("usdrender-lint: note: the reports do not tell whether their checks ran")
    assert "AR001" in line
