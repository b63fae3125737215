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
