"""The linter a long-running host (the Asset Validator plugin) lints a stage
with follows the configuration as ``check`` run again would: an edited file,
and a configuration file created while the host runs."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from pxr import Usd

from usdrender_lint.running.stage_lints import CheckLinters

SHOT = '#usda 1.0\ndef RenderSettings "S"\n{\n    uniform int2 resolution = (0, 10)\n}\n'


def _codes(linters: CheckLinters, stage: Usd.Stage) -> set[str]:
    return {type(rule).code for rule in linters.linter(stage).rules}


@pytest.mark.parametrize("where", [".", "..", "../.."])
@pytest.mark.parametrize("name", [".usdrender-lint.toml", "usdrender-lint.toml", "pyproject.toml"])
def test_a_configuration_created_while_the_host_runs_is_read(
    tmp_path: Path, where: str, name: str
) -> None:
    # A folder with no configuration at all: nothing was stamped, so the
    # defaults stayed until the host (Kit) restarted.
    folder = tmp_path / "show" / "shots"
    folder.mkdir(parents=True)
    (folder / "shot.usda").write_text(SHOT)
    stage = Usd.Stage.Open(str(folder / "shot.usda"))
    linters = CheckLinters()
    assert "SE001" in _codes(linters, stage)
    text = 'ignore = ["SE001"]\n'
    if name == "pyproject.toml":
        text = "[tool.usdrender-lint]\n" + text
    config = folder / where / name
    config.write_text(text)
    assert "SE001" not in _codes(linters, stage)
    os.remove(config)
    assert "SE001" in _codes(linters, stage)


def test_a_nearer_configuration_created_later_wins(tmp_path: Path) -> None:
    (tmp_path / ".usdrender-lint.toml").write_text('ignore = ["SE001"]\n')
    folder = tmp_path / "shots"
    folder.mkdir()
    (folder / "shot.usda").write_text(SHOT)
    stage = Usd.Stage.Open(str(folder / "shot.usda"))
    linters = CheckLinters()
    assert "SE001" not in _codes(linters, stage)
    (folder / ".usdrender-lint.toml").write_text('select = ["SE001"]\n')
    assert _codes(linters, stage) == {"SE001"}


def test_a_configuration_rewritten_with_its_time_kept_is_read_again(tmp_path: Path) -> None:
    # Its modification time set back (a copy that keeps times, a checkout), or
    # two writes within one tick of a coarse clock: the host kept the first
    # configuration, where check run again reads the second.
    (tmp_path / "shot.usda").write_text(SHOT)
    config = tmp_path / ".usdrender-lint.toml"
    config.write_text('ignore = ["SE001"]\n')
    stage = Usd.Stage.Open(str(tmp_path / "shot.usda"))
    linters = CheckLinters()
    assert "SE001" not in _codes(linters, stage)
    times = config.stat()
    config.write_text('ignore = ["SE002"]\n')
    os.utime(config, ns=(times.st_atime_ns, times.st_mtime_ns))
    assert config.stat().st_size == times.st_size
    assert "SE001" in _codes(linters, stage)


def test_a_configuration_that_cannot_be_read_is_read_once_per_state(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Every validator's call on every prim read it again to fail again: a
    # 300-prim stage took 12 s to validate under a typo, against 2 s.
    from usdrender_lint.running import pipeline, stage_lints
    from usdrender_lint.running.pipeline import RequestError

    calls = []
    real = pipeline.prepare

    def counted(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(pipeline, "prepare", counted)
    # Kept for as long as the loop takes, which on a loaded machine was over 1 s.
    monkeypatch.setattr(stage_lints, "FAILURE_SECONDS", 3600.0)
    (tmp_path / "shot.usda").write_text(SHOT)
    config = tmp_path / ".usdrender-lint.toml"
    config.write_text("selct = 1\n")
    stage = Usd.Stage.Open(str(tmp_path / "shot.usda"))
    linters = CheckLinters()
    for _ in range(20):
        with pytest.raises(RequestError, match="unknown key 'selct'"):
            linters.linter(stage)
    assert len(calls) == 1
    config.write_text('select = ["SE001"]\n')
    assert _codes(linters, stage) == {"SE001"}


def test_a_file_the_configuration_extends_is_read_again_after_a_failure(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Not among the files the search looks at: the failure is kept for a moment only.
    from usdrender_lint.running import stage_lints
    from usdrender_lint.running.pipeline import RequestError

    (tmp_path / "shot.usda").write_text(SHOT)
    (tmp_path / ".usdrender-lint.toml").write_text('extend = "base.toml"\n')
    base = tmp_path / "base.toml"
    base.write_text("selct = 1\n")
    stage = Usd.Stage.Open(str(tmp_path / "shot.usda"))
    linters = CheckLinters()
    with pytest.raises(RequestError, match="selct"):
        linters.linter(stage)
    base.write_text('select = ["SE001"]\n')
    monkeypatch.setattr(stage_lints, "FAILURE_SECONDS", 0.0)
    assert _codes(linters, stage) == {"SE001"}


def test_a_stage_linted_anew_checks_its_configuration_twice_not_three_times(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A host's validator on a stage not linted yet asks for the linter (to know
    # whether the cached findings are still its) and for what lints the stage:
    # each look-up stats the configuration's files, once each is enough.
    from usdrender_lint.running.stage_lints import StageLints

    (tmp_path / "shot.usda").write_text(SHOT)
    stage = Usd.Stage.Open(str(tmp_path / "shot.usda"))
    linters = CheckLinters()
    looks: list[str] = []
    prepared = CheckLinters.prepared
    monkeypatch.setattr(
        CheckLinters, "prepared", lambda self, s: looks.append("look") or prepared(self, s)
    )
    findings = StageLints(linters.linter, linters.lint).findings(stage)
    assert {f.finding.code for f in findings} >= {"SE001"}
    assert len(looks) == 2


def test_a_host_call_looks_at_the_configuration_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A host calls once per validator and prim: each look stats every file the
    # search reads, so a call on a stage already linted looks once, and still
    # follows a configuration edited between calls.
    from usdrender_lint.running.stage_lints import CheckedLints

    (tmp_path / "shot.usda").write_text(SHOT)
    config = tmp_path / ".usdrender-lint.toml"
    config.write_text("force-exclude = true\n")  # the force-exclude answer is asked for
    stage = Usd.Stage.Open(str(tmp_path / "shot.usda"))
    checked = CheckedLints()
    assert "SE001" in {t.finding.code for t in checked.reported(stage)}
    looks: list[str] = []
    prepared = CheckLinters.prepared
    monkeypatch.setattr(
        CheckLinters, "prepared", lambda self, s: looks.append("look") or prepared(self, s)
    )
    assert "SE001" in {t.finding.code for t in checked.reported(stage)}
    assert len(looks) == 1
    config.write_text('force-exclude = true\nignore = ["SE001"]\n')
    looks.clear()
    assert "SE001" not in {t.finding.code for t in checked.reported(stage)}
    assert len(looks) == 2  # the look that found the edit, and the new lint's
