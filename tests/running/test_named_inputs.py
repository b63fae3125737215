"""A baseline or a report to merge that is a named pipe or a device: the
command waited forever (a pipe with no writer, ``/dev/zero``); now a pipe is
read to its writer's end, a named pipe nothing writes to ends in one line after
PIPE_WAIT seconds, and a device at once."""

from __future__ import annotations

import errno
import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint import atomic
from usdrender_lint.cli import cli
from usdrender_lint.reading import NOT_A_FILE, read_named_input

pytestmark = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes here")

SHOT = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        float4 dataWindowNDC = (1, 0, 0, 1)
    }
}
"""
#: Seconds a command may take before the test calls it hung.
HUNG = 60


def _command(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    """The command as a user runs it, killed (and the test failed) if it hangs."""
    return subprocess.run(
        [sys.executable, "-m", "usdrender_lint", *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        stdin=subprocess.DEVNULL,
        timeout=HUNG,
    )


def _one_line(result, *parts: str) -> None:
    code = getattr(result, "returncode", getattr(result, "exit_code", None))
    assert code == 2 and result.stdout == "", result
    assert result.stderr.startswith("usdrender-lint: error: ") and result.stderr.count("\n") == 1
    for part in parts:
        assert part in result.stderr, result.stderr


@pytest.fixture
def short_wait(monkeypatch: pytest.MonkeyPatch) -> str:
    """PIPE_WAIT cut to a moment, in this process; the message it gives."""
    monkeypatch.setattr(atomic, "PIPE_WAIT", 0.2)
    return "a named pipe nothing wrote to within 0.2 s"


def test_a_regular_file_is_read(tmp_path: Path) -> None:
    (tmp_path / "a.json").write_bytes(b"[1]")
    assert read_named_input(tmp_path / "a.json") == b"[1]"


def test_a_named_pipe_is_read_to_its_writers_end(tmp_path: Path) -> None:
    pipe = tmp_path / "pipe"
    os.mkfifo(pipe)

    def write() -> None:
        with open(pipe, "wb") as handle:  # waits for the reader's open
            time.sleep(0.3)  # the reader waits for what is written
            handle.write(b"x" * 300_000)  # more than a pipe's buffer

    writer = threading.Thread(target=write)
    writer.start()
    try:
        assert read_named_input(pipe) == b"x" * 300_000
    finally:
        writer.join(HUNG)


def test_a_named_pipe_nothing_writes_to_ends_after_the_wait(tmp_path: Path, short_wait) -> None:
    pipe = tmp_path / "pipe"
    os.mkfifo(pipe)
    began = time.monotonic()
    with pytest.raises(OSError) as raised:
        read_named_input(pipe)
    assert (raised.value.errno, raised.value.strerror) == (errno.ETIMEDOUT, short_wait)
    assert time.monotonic() - began < HUNG


def test_a_named_pipe_closed_unwritten_reads_as_empty(tmp_path: Path) -> None:
    pipe = tmp_path / "pipe"
    os.mkfifo(pipe)
    writer = threading.Thread(target=lambda: open(pipe, "wb").close())
    writer.start()
    try:
        assert read_named_input(pipe) == b""
    finally:
        writer.join(HUNG)


def test_a_folder_and_a_device_are_refused(tmp_path: Path) -> None:
    with pytest.raises(IsADirectoryError):
        read_named_input(tmp_path)
    with pytest.raises(OSError) as raised:
        read_named_input("/dev/zero")  # its read never ends
    assert (raised.value.errno, raised.value.strerror) == (errno.EINVAL, NOT_A_FILE)


@pytest.fixture
def shot(tmp_path: Path) -> Path:
    (tmp_path / "shot.usda").write_text(SHOT)
    os.mkfifo(tmp_path / "pipe.json")
    return tmp_path


def test_a_baseline_pipe_nothing_writes_to_is_one_line(
    shot: Path, short_wait, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(shot)
    result = CliRunner().invoke(
        cli, ["check", "--isolated", "--jobs", "1", "--baseline", "pipe.json", "shot.usda"]
    )
    _one_line(result, "pipe.json: cannot read baseline: ", short_wait)


def test_a_baseline_device_is_one_line(shot: Path) -> None:
    result = _command("check", "--isolated", "--baseline", "/dev/zero", "shot.usda", cwd=shot)
    _one_line(result, "/dev/zero: cannot read baseline: ", NOT_A_FILE)


def test_merge_of_a_pipe_nothing_writes_to_is_one_line(
    shot: Path, short_wait, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(shot)
    result = CliRunner().invoke(cli, ["merge", "pipe.json"])
    _one_line(result, "pipe.json: cannot read: ", short_wait)


def test_merge_of_a_device_is_one_line(shot: Path) -> None:
    _one_line(_command("merge", "/dev/zero", cwd=shot), "/dev/zero: cannot read: ", NOT_A_FILE)


def test_merge_reads_a_report_from_a_pipe(shot: Path) -> None:
    """``merge <(cat report.json)``: the shell hands over a pipe with its writer."""
    linted = _command("check", "--isolated", "--format", "json", "shot.usda", cwd=shot)
    assert linted.returncode == 1, linted
    read, write = os.pipe()
    os.write(write, linted.stdout.encode())  # a one-shot report fits in the pipe's buffer
    os.close(write)
    try:
        merged = subprocess.run(
            [
                sys.executable,
                "-m",
                "usdrender_lint",
                "merge",
                "--format",
                "json",
                f"/dev/fd/{read}",
            ],
            cwd=shot,
            capture_output=True,
            text=True,
            pass_fds=(read,),
            timeout=HUNG,
        )
    finally:
        os.close(read)
    assert merged.returncode == 1, merged
    assert json.loads(merged.stdout)["summary"] == json.loads(linted.stdout)["summary"]
