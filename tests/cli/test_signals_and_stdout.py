"""Exit codes a shell and a CI runner expect: Ctrl-C is 130 and SIGTERM 143,
after the workers are gone and nothing temporary is left; a stdout nobody
reads is a quiet exit 2, a full one a one-line error."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest
from cli_support import (
    BROKEN,
    command,
    descendants,
    hanging_stage,
    is_running,
    signalled,
    unsupervised,
    until_usd_loads,
    wait_for_a_worker,
)

from usdrender_lint.running.progress import PROGRESS_MIN_FILES

pytestmark = [
    pytest.mark.skipif(
        not sys.platform.startswith("linux"), reason="FIFOs, /proc and /dev/full are Linux's"
    ),
    pytest.mark.heavy(seconds=55),
]


@pytest.mark.parametrize(
    ("signum", "status", "line"),
    [
        (signal.SIGINT, 130, "interrupted"),
        (signal.SIGTERM, 143, "terminated"),
        (signal.SIGHUP, 129, "hung up"),
    ],
)
def test_a_signal_stops_the_run_and_cleans_up(
    tmp_path: Path, signum: int, status: int, line: str
) -> None:
    stage = hanging_stage(tmp_path)
    temporary = tmp_path / "tmp"
    temporary.mkdir()
    report = tmp_path / "report.json"
    process = subprocess.Popen(
        command(
            "check",
            "--isolated",
            "--format",
            "json",
            "--timeout",
            "600",
            "--output",
            str(report),
            str(stage),
            str(BROKEN),
        ),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "TMPDIR": str(temporary)},
        # As a terminal starts it, whatever this run inherited: under nohup the
        # command kept ignoring SIGHUP, as it should, and the test waited 30 s.
        preexec_fn=lambda: signal.signal(signum, signal.SIG_DFL),  # noqa: PLW1509
    )
    wait_for_a_worker(process, temporary)
    workers = descendants(process.pid)
    process.send_signal(signum)
    # communicate() returns only when every holder of stdout has closed it:
    # no worker is left keeping the pipe open.
    stdout, stderr = process.communicate(timeout=30)
    assert process.returncode == status
    assert stderr == f"usdrender-lint: {line}\n"
    assert stdout == ""
    assert not report.exists()  # no partial report
    assert list(temporary.iterdir()) == []  # the workers' folder is gone
    assert sorted(tmp_path.iterdir()) == sorted([stage, tmp_path / "pipe.usda", temporary])
    assert not [pid for pid in workers if is_running(pid)]


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_a_signal_the_command_was_started_ignoring_stays_ignored(
    tmp_path: Path, signum: int
) -> None:
    # A script's background job ('lint &') starts with SIGINT ignored, so that the
    # Ctrl-C stopping the foreground job spares it (as sleep and python are): the
    # command installed its own handler over that and stopped with exit 130.
    stage = hanging_stage(tmp_path)
    temporary = tmp_path / "tmp"
    temporary.mkdir()
    process = subprocess.Popen(
        command(
            "check", "--isolated", "--format", "json", "--timeout", "5", str(stage), str(BROKEN)
        ),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "TMPDIR": str(temporary)},
        preexec_fn=lambda: signal.signal(signum, signal.SIG_IGN),  # noqa: PLW1509
    )
    wait_for_a_worker(process, temporary)
    process.send_signal(signum)
    stdout, stderr = process.communicate(timeout=120)
    # The run went on: the hanging file timed out, the other was linted.
    assert process.returncode == 2, stderr
    assert "timed out after 5 s" in stderr
    statuses = {entry["file"]: entry["status"] for entry in json.loads(stdout)["files"]}
    assert statuses == {str(stage): "error", str(BROKEN): "linted"}


@pytest.mark.parametrize("pool", [False, True], ids=["one-file-child", "pool"])
def test_workers_die_with_a_parent_killed_outright(tmp_path: Path, pool: bool) -> None:
    """SIGKILL leaves no clean-up to run: Linux ends the workers itself."""
    stage = hanging_stage(tmp_path)
    temporary = tmp_path / "tmp"
    temporary.mkdir()
    files = [str(stage), str(BROKEN)] if pool else [str(stage)]
    process = subprocess.Popen(
        command("check", "--isolated", "--timeout", "600", *files),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env={**os.environ, "TMPDIR": str(temporary)},
    )
    wait_for_a_worker(process, temporary, pool=pool)
    workers = descendants(process.pid)
    process.kill()
    process.communicate(timeout=30)  # EOF: no worker holds the pipes
    deadline = time.monotonic() + 10
    while [pid for pid in workers if is_running(pid)] and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not [pid for pid in workers if is_running(pid)]


@pytest.mark.parametrize(
    "args",
    [
        ("check", "--isolated", str(BROKEN)),
        ("check", "--isolated", "--format", "json", str(BROKEN)),
        ("check", "--isolated", "--format", "sarif", str(BROKEN)),
        ("rules",),
        ("explain", "CA004"),
    ],
)
def test_a_broken_stdout_is_a_quiet_exit_2(args: tuple[str, ...]) -> None:
    read_end, write_end = os.pipe()
    os.close(read_end)  # nobody reads: every write fails with EPIPE
    try:
        result = subprocess.run(
            command(*args), stdout=write_end, stderr=subprocess.PIPE, text=True, timeout=120
        )
    finally:
        os.close(write_end)
    assert (result.returncode, result.stderr) == (2, "")


@pytest.mark.parametrize(
    "args",
    # click prints help and the version itself: they exited 0, printing nothing.
    [("check", "--isolated", str(BROKEN)), ("--version",), ("--help",), ("check", "--help")],
)
def test_a_closed_stdout_is_a_quiet_exit_2(args: tuple[str, ...]) -> None:
    result = subprocess.run(
        command(*args),
        stderr=subprocess.PIPE,
        text=True,
        timeout=120,
        preexec_fn=lambda: os.close(1),  # noqa: PLW1509 - the child only closes a descriptor
    )
    assert (result.returncode, result.stderr) == (2, "")


def test_a_closed_stdout_does_not_stop_a_report_to_a_file(tmp_path: Path) -> None:
    report = tmp_path / "report.json"
    result = subprocess.run(
        command("check", "--isolated", "--format", "json", "--output", str(report), str(BROKEN)),
        stderr=subprocess.PIPE,
        text=True,
        timeout=120,
        preexec_fn=lambda: os.close(1),  # noqa: PLW1509
    )
    assert (result.returncode, result.stderr) == (1, "")
    assert json.loads(report.read_text())["summary"]["findings"] > 0


@pytest.mark.parametrize("jobs", ["1", "2"])
@pytest.mark.parametrize("command_of", [command, unsupervised], ids=["supervised", "main"])
def test_a_closed_stderr_loses_only_what_is_said_on_it(
    tmp_path: Path, jobs: str, command_of: Callable[..., list[str]]
) -> None:
    # More files than the progress bar's threshold: asking whether stderr is a
    # terminal was an internal error (sys.stderr is None), exit 2 and no report.
    # Before the fork, the supervisor's pipe took fd 2's number: the child's
    # "stderr" was that pipe's read end.
    count = PROGRESS_MIN_FILES + 1
    for index in range(count):
        (tmp_path / f"shot{index}.usda").write_text(BROKEN.read_text())
    args = ("check", "--isolated", "--no-cache", "--jobs", jobs, "--format", "json")
    result = subprocess.run(
        command_of(*args, str(tmp_path), str(tmp_path / "missing.usda")),
        stdout=subprocess.PIPE,
        text=True,
        timeout=300,
        preexec_fn=lambda: os.close(2),  # noqa: PLW1509 - the child only closes a descriptor
    )
    assert result.returncode == 2  # the missing file
    statuses = [entry["status"] for entry in json.loads(result.stdout)["files"]]
    assert sorted(statuses) == ["error"] + ["linted"] * count


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full")
@pytest.mark.parametrize("output_format", ["text", "json"])
def test_stdout_on_a_full_device_is_one_line_and_exit_2(output_format: str) -> None:
    with open("/dev/full", "w") as full:
        result = subprocess.run(
            command("check", "--isolated", "--format", output_format, str(BROKEN)),
            stdout=full,
            stderr=subprocess.PIPE,
            text=True,
            timeout=120,
        )
    assert result.returncode == 2
    assert (
        result.stderr == "usdrender-lint: error: cannot write the report: No space left on device\n"
    )


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full")
@pytest.mark.parametrize(
    ("args", "what"),
    [
        (("rules",), "the rule list"),
        (("explain", "CA004"), "the rule's documentation"),
        (("spec", "--isolated", str(BROKEN)), "the specification"),
    ],
)
def test_a_full_stdout_names_what_could_not_be_written(args: tuple[str, ...], what: str) -> None:
    # 'rules' and 'explain' said "cannot write the report", a report they never make.
    with open("/dev/full", "w") as full:
        result = subprocess.run(
            command(*args), stdout=full, stderr=subprocess.PIPE, text=True, timeout=120
        )
    assert result.returncode == 2
    assert result.stderr == f"usdrender-lint: error: cannot write {what}: No space left on device\n"


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full")
@pytest.mark.parametrize(
    ("args", "status"),
    [
        (("check", "--isolated", "/no/such/shot.usda"), 2),
        (("check", "--isolated", "--jobs", "2", str(BROKEN), "/no/such/shot.usda"), 2),
        (("check", "--no-such-option"), 2),
        (("check", "--isolated", str(BROKEN)), 1),
    ],
)
def test_a_full_stderr_keeps_the_exit_code(args: tuple[str, ...], status: int) -> None:
    # The error line could not be written: Python's traceback (itself lost) and exit 1.
    with open("/dev/full", "w") as full:
        result = subprocess.run(
            command(*args), stdout=subprocess.DEVNULL, stderr=full, timeout=120, check=False
        )
    assert result.returncode == status


#: A pool of one worker whose every item takes 1 s of CPU, under a 4 s time-out, in a
#: process of its own session with the command's signal handlers: it prints the results.
_SLOW_POOL = """
import sys, time
sys.path.insert(0, sys.argv[1])
from usdrender_lint.running import interrupts
interrupts.install()
from usdrender_lint.running.workers import Pool
from cli_support import busy_for
print(Pool(dict, 1, 4.0, handle=busy_for, failed=lambda item, why: why).run([1.0, 1.0]))
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="SIGSTOP to a process group")
def test_a_run_stopped_and_continued_times_no_file_out(tmp_path: Path) -> None:
    """Ctrl-Z, then fg: the workers stood still as long as the command, so the
    file one holds is not timed out for the time the run was stopped."""
    run = subprocess.Popen(
        [sys.executable, "-c", _SLOW_POOL, str(Path(__file__).parents[1])],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    time.sleep(1.5)  # the worker started and holds an item
    os.killpg(run.pid, signal.SIGSTOP)
    time.sleep(5.0)  # longer than the time-out
    os.killpg(run.pid, signal.SIGCONT)
    out, err = run.communicate(timeout=60)
    assert run.returncode == 0, err
    assert out.strip() == "(1.0, 1.0)", out + err


#: The supervisor timing a child (running/supervisor.py) that says its lint has 4 s,
#: works 1 s of CPU and exits; it prints how the child ended.
_SUPERVISED = """
import os, time
from usdrender_lint.running import interrupts, supervisor
interrupts.install()
heard, says = os.pipe()
stack, _ = os.pipe()
child = os.fork()
if child == 0:
    os.write(says, b"4.0\\n")
    end = time.process_time() + 1.0
    while time.process_time() < end:
        pass
    os.write(says, b"0.0\\n" + supervisor.DONE + b"\\n")
    os._exit(0)
os.close(says)
print(supervisor._time_the_child(child, heard, stack))
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the supervisor is Linux's")
def test_a_supervised_lint_stopped_and_continued_is_not_timed_out() -> None:
    """The one-file check's timer (the supervisor's) after Ctrl-Z and fg: the
    child stood still as long as it did."""
    run = subprocess.Popen(
        [sys.executable, "-c", _SUPERVISED],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    time.sleep(1.0)
    os.killpg(run.pid, signal.SIGSTOP)
    time.sleep(5.0)  # longer than the child's time
    os.killpg(run.pid, signal.SIGCONT)
    out, err = run.communicate(timeout=60)
    assert (run.returncode, out.strip()) == (0, "done"), err


@pytest.mark.parametrize(
    "args",
    [
        ("check", "shot.usda"),
        ("spec", "shot.usda"),
        ("merge", "report.json"),
        ("clean", "."),
        ("rules",),
        ("explain", "SE001"),
        ("config",),
        ("plugin-path",),
    ],
    ids=lambda args: args[0],
)
def test_sigterm_while_usd_imports_ends_every_command_with_one_line(
    args: tuple[str, ...], tmp_path: Path
) -> None:
    """A signal while USD's modules load (a start on a slow machine): raised in
    USD's C++, the exception was swallowed after USD's warning and a Python
    traceback, and ``clean`` and ``plugin-path`` then exited 0 (click's closing
    sys.exit hid it). Every command ends with its one line and 143."""
    (tmp_path / "shot.usda").write_text("#usda 1.0\n")
    (tmp_path / "report.json").write_text("{}")
    status_and_said = signalled(command(*args), signal.SIGTERM, until_usd_loads, cwd=tmp_path)
    assert status_and_said == (143, "usdrender-lint: terminated\n")
