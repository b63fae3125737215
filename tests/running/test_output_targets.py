"""--output and --write-baseline write as a shell's ``>`` would, atomically
where that is possible: through a symbolic link to its target, streamed into a
FIFO or a device, and a regular file replaced atomically."""

from __future__ import annotations

import json
import os
import stat
import sys
import threading
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint import atomic
from usdrender_lint.atomic import write_output
from usdrender_lint.cli import cli

REPO = Path(__file__).resolve().parents[2]
BROKEN = str(REPO / "examples" / "broken_shot" / "shot.usda")
OPTIONS = ["--output", "--write-baseline"]


def check(option: str, target: Path | str):
    args = ["check", "--isolated", "--format", "json", option, str(target), BROKEN]
    return CliRunner().invoke(cli, args)


def written(option: str, text: str) -> dict:
    document = json.loads(text)
    assert ("usdrender_lint_baseline" in document) == (option == "--write-baseline")
    return document


@pytest.mark.parametrize("option", OPTIONS)
def test_a_symlink_is_followed_and_kept(tmp_path: Path, option: str) -> None:
    (tmp_path / "real").mkdir()
    target = tmp_path / "real" / "report.json"
    target.write_text("old")
    link = tmp_path / "report.json"
    link.symlink_to(Path("real") / "report.json")
    result = check(option, link)
    assert result.exit_code in (0, 1), result.output
    assert link.is_symlink() and os.readlink(link) == str(Path("real") / "report.json")
    written(option, target.read_text())
    assert sorted(p.name for p in (tmp_path / "real").iterdir()) == ["report.json"]


@pytest.mark.parametrize("option", OPTIONS)
def test_a_dangling_symlink_creates_its_target(tmp_path: Path, option: str) -> None:
    link = tmp_path / "report.json"
    link.symlink_to(tmp_path / "made.json")
    assert check(option, link).exit_code in (0, 1)
    assert link.is_symlink()
    written(option, (tmp_path / "made.json").read_text())


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs")
@pytest.mark.parametrize("option", OPTIONS)
def test_a_fifo_is_streamed_into(tmp_path: Path, option: str) -> None:
    fifo = tmp_path / "report.fifo"
    os.mkfifo(fifo)
    received: list[str] = []
    reader = threading.Thread(target=lambda: received.append(fifo.read_text()))
    reader.start()
    result = check(option, fifo)
    reader.join(60)
    assert result.exit_code in (0, 1), result.output
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)  # still a FIFO, not a regular file
    written(option, received[0])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report.fifo"]


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs")
@pytest.mark.parametrize(
    ("option", "what"), [("--output", "the report"), ("--write-baseline", "baseline")]
)
def test_a_fifo_nothing_reads_is_one_line(
    tmp_path: Path, option: str, what: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Its open waited for a reader without end: the run hung after linting."""
    monkeypatch.setattr(atomic, "PIPE_WAIT", 0.2)
    fifo = tmp_path / "report.fifo"
    os.mkfifo(fifo)
    result = check(option, fifo)
    assert result.exit_code == 2
    assert result.stderr == (
        f"usdrender-lint: error: {fifo}: cannot write {what}: "
        "a named pipe nothing read from within 0.2 s\n"
    )
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)


@pytest.mark.skipif(not os.path.exists("/dev/null"), reason="no /dev/null")
@pytest.mark.parametrize("option", OPTIONS)
def test_a_device_is_written_not_replaced(option: str) -> None:
    before = os.lstat("/dev/null")
    assert check(option, "/dev/null").exit_code in (0, 1)
    after = os.lstat("/dev/null")
    assert stat.S_ISCHR(after.st_mode) and after.st_rdev == before.st_rdev


@pytest.mark.parametrize("option", OPTIONS)
def test_a_regular_file_is_replaced_atomically_keeping_its_mode(
    tmp_path: Path, option: str
) -> None:
    target = tmp_path / "report.json"
    target.write_text("old")
    os.chmod(target, 0o640)
    inode = os.stat(target).st_ino
    assert check(option, target).exit_code in (0, 1)
    written(option, target.read_text())
    assert os.stat(target).st_ino != inode  # a new file renamed over the old one
    assert stat.S_IMODE(os.stat(target).st_mode) == 0o640
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report.json"]


def test_a_folder_is_refused(tmp_path: Path) -> None:
    with pytest.raises(IsADirectoryError):
        write_output(tmp_path, "x")
    assert check("--output", tmp_path).exit_code == 2  # click refuses it first


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX links")
def test_a_baseline_written_through_a_link_is_read_back_through_it(tmp_path: Path) -> None:
    (tmp_path / "elsewhere").mkdir()
    link = tmp_path / "baseline.json"
    link.symlink_to(tmp_path / "elsewhere" / "baseline.json")
    assert check("--write-baseline", link).exit_code == 0
    again = CliRunner().invoke(cli, ["check", "--isolated", "--baseline", str(link), BROKEN])
    assert again.exit_code == 0, again.output  # every finding is known


@pytest.mark.parametrize(
    ("first", "second", "named"),
    [
        (["--output", "same.json"], ["--write-baseline", "same.json"], "the report"),
        (["--output", "./new.usda"], ["--fix-to", "new.usda"], "the report (as ./new.usda)"),
        (["--write-baseline", "b.json"], ["--output", "sub/../b.json"], "the report (as sub/"),
    ],
    ids=["report-and-baseline", "report-and-fix-to", "one-file-two-names"],
)
def test_two_outputs_naming_one_file_are_refused_before_anything_is_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, first: list[str], second: list[str], named: str
) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "sub").mkdir()
    (tmp_path / "shot.usda").write_text(
        '#usda 1.0\ndef RenderSettings "S"\n{\n    uniform int2 resolution = (0, 1)\n}\n'
    )
    before = sorted(p.name for p in tmp_path.iterdir())
    args = ["check", "--isolated", "--no-cache", *first, *second, "shot.usda"]
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 2
    (line,) = result.stderr.splitlines()
    assert f"is named for both {named}" in line
    assert sorted(p.name for p in tmp_path.iterdir()) == before
