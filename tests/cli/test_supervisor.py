"""The supervised one-file check (running/supervisor.py): the command's own
process waits, holding no USD, while its child lints the file in-process; a
time-out, a crash and a signal end as they did with a forked lint child."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import click
import pytest
from cli_support import (
    BROKEN,
    after_a_supervised_command,
    command,
    descendants,
    hanging_stage,
    is_running,
    unsupervised,
    wait_for_a_worker,
)

from usdrender_lint.running import supervisor
from usdrender_lint.running.supervisor import wants_supervision

pytestmark = [
    pytest.mark.skipif(
        not sys.platform.startswith("linux"), reason="the supervisor is Linux's (PR_SET_PDEATHSIG)"
    ),
    pytest.mark.heavy(seconds=27),
]


@pytest.mark.parametrize(
    ("argv", "supervised"),
    [
        (["check", "shot.usda"], True),
        (["check", "--format", "json", "--output", "out.json", "shot.usda"], True),
        (["--help", "check"], False),
        (["check", "--fix", "shot.usda"], False),
        (["check", "--diff", "shot.usda"], False),
        (["check", "--fix-to=out.usda", "shot.usda"], False),
        (["check", "--write-baseline", "b.json", "shot.usda"], False),
        # '-' is --output's value (stdout), not standard input's text to fix.
        (["check", "--fix", "--output", "-", "shot.usda"], False),
        (["check", "--", "--fix"], True),  # a file named --fix
        (["rules"], False),
        (["explain", "CA004"], False),
    ],
)
def test_only_a_check_that_writes_nothing_is_supervised(argv: list[str], supervised: bool) -> None:
    assert wants_supervision(argv) is supervised


@pytest.mark.parametrize("name", ["check", "spec"])
def test_the_options_that_take_a_value_are_the_commands(name: str) -> None:
    """The supervisor tells a path from an option's value before click is imported."""
    from usdrender_lint.cli import cli

    params = cli.commands[name].params
    taking = {o for p in params if isinstance(p, click.Option) and not p.is_flag for o in p.opts}
    assert taking <= supervisor.VALUE_OPTIONS


def test_an_output_to_stdout_does_not_wait_for_standard_input(tmp_path: Path) -> None:
    """``--output -`` names stdout: the check lints its file and ends while
    standard input (a pipe nobody closes, as a CI runner's) stays open."""
    read, write = os.pipe()
    try:
        run = subprocess.run(
            command("check", "--isolated", "--output", "-", str(BROKEN)),
            stdin=read,
            capture_output=True,
            text=True,
            timeout=60,
        )
    finally:
        os.close(read)
        os.close(write)
    assert run.returncode == 1, run.stderr
    assert "SE003" in run.stdout


def test_no_module_global_or_environment_variable_steers_it(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # How the supervisor ran a process is a value handed to the command
    # (Supervision), not a module global or an environment variable.
    assert not hasattr(supervisor, "supervised") and not hasattr(supervisor, "verdict")
    # Nor does the supervisor keep its child's pid, a stop signal or pipes in globals.
    assert not {"_child", "_stop_signal", "_watched", "_says"} & set(vars(supervisor))
    monkeypatch.setenv("USDRENDER_LINT_NO_SUPERVISOR", "1")
    assert wants_supervision(["check", "shot.usda"])


def _run(*args: str, supervised: bool) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        command(*args) if supervised else unsupervised(*args),
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )


@pytest.mark.parametrize("report_format", ["text", "json"])
def test_a_supervised_check_reports_as_one_without(report_format: str) -> None:
    args = ("check", "--isolated", "--no-cache", "--format", report_format, str(BROKEN))
    ours, theirs = _run(*args, supervised=True), _run(*args, supervised=False)
    assert (ours.returncode, ours.stdout, ours.stderr) == (
        theirs.returncode,
        theirs.stdout,
        theirs.stderr,
    )
    assert ours.returncode == 1 and "CA004" in ours.stdout


def _uses_usd(pid: int) -> bool:
    return "/pxr/Usd/_usd" in Path(f"/proc/{pid}/maps").read_text()


def _start_on_a_hang(tmp_path: Path, *args: str) -> tuple[subprocess.Popen[str], Path]:
    stage = hanging_stage(tmp_path)
    process = subprocess.Popen(
        command("check", "--isolated", "--no-cache", "--format", "json", *args, str(stage)),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        assert process.poll() is None, process.communicate()
        children = descendants(process.pid)
        if children and all(_uses_usd(child) for child in children):
            time.sleep(0.3)  # the child is in USD, blocked on the FIFO
            return process, stage
        time.sleep(0.05)
    raise AssertionError("the child never reached USD")


def test_the_supervisor_holds_no_usd_while_its_child_lints(tmp_path: Path) -> None:
    process, _ = _start_on_a_hang(tmp_path, "--timeout", "30")
    try:
        [child] = descendants(process.pid)
        assert not _uses_usd(process.pid)
        assert _uses_usd(child)
    finally:
        process.kill()
        process.communicate(timeout=30)


def test_a_time_out_is_the_files_error_as_without_a_supervisor(tmp_path: Path) -> None:
    stage = hanging_stage(tmp_path)
    args = ("check", "--isolated", "--no-cache", "--format", "json", "--timeout", "1", str(stage))
    ours, theirs = _run(*args, supervised=True), _run(*args, supervised=False)
    assert (ours.returncode, ours.stderr) == (theirs.returncode, theirs.stderr)
    assert json.loads(ours.stdout) == json.loads(theirs.stdout)
    [entry] = json.loads(ours.stdout)["files"]
    assert entry["status"] == "error" and "timed out after 1 s" in entry["error"]
    assert ours.returncode == 2


def test_a_crash_of_the_child_costs_a_retry_not_the_report(tmp_path: Path) -> None:
    process, stage = _start_on_a_hang(tmp_path, "--timeout", "3")
    [child] = descendants(process.pid)
    os.kill(child, signal.SIGSEGV)  # as USD crashing on the file would
    # The supervisor lints the file again itself, in a worker with the whole
    # stage composed (AfterSupervisedChild); the FIFO still blocks it, so that
    # one times out.
    stdout, stderr = process.communicate(timeout=60)
    assert (process.returncode, stderr) == (
        2,
        f"usdrender-lint: error: {stage}: timed out "
        "after 3 s while USD opened the stage (raise --timeout, or 0 for no limit)\n",
    )
    [entry] = json.loads(stdout)["files"]
    assert entry["status"] == "error" and entry["error"].startswith(str(stage))
    assert not is_running(child)


ENDING_RULE = """
import os
from pxr import UsdRender
from usdrender_lint.api import Rule, Severity


class Ending(Rule):
    \"\"\"Ends the process on a file named crash.usda, as USD may on a hostile file.\"\"\"

    code = "END001"
    name = "ending-rule"
    severity = Severity.WARNING
    prim_types = (UsdRender.Product,)

    def check_prim(self, prim, ctx):
        if os.path.basename(ctx.file) == "crash.usda":
            {ending}
        yield from ()


RULES = [Ending]
"""


def _ending_plugin(tmp_path: Path, ending: str) -> dict[str, str]:
    """The environment of a command with a rule plugin that runs ``ending``."""
    site = tmp_path / "site"
    (site / "ending-0.1.dist-info").mkdir(parents=True)
    (site / "ending.py").write_text(ENDING_RULE.replace("{ending}", ending))
    (site / "ending-0.1.dist-info" / "METADATA").write_text(
        "Metadata-Version: 2.1\nName: ending\nVersion: 0.1\n"
    )
    (site / "ending-0.1.dist-info" / "entry_points.txt").write_text(
        "[usdrender_lint.rules]\nending = ending:RULES\n"
    )
    return {**os.environ, "PYTHONPATH": str(site)}


def _crash_run(
    tmp_path: Path, ending: str, options: tuple[str, ...], both: bool
) -> dict[str, dict]:
    """``check`` (JSON) of crash.usda, whose lint a rule ends with ``ending``,
    and with ``both`` other.usda: exit 2, one line naming the crash on stderr;
    each file's entry by path."""
    env = _ending_plugin(tmp_path, ending)
    crash, other = tmp_path / "crash.usda", tmp_path / "other.usda"
    for path in (crash, other):
        path.write_text(BROKEN.read_text())
    paths = (str(crash), str(other)) if both else (str(crash),)
    args = ("--isolated", "--no-cache", *options, "--format", "json", *paths)
    result = subprocess.run(
        command("check", *args), env=env, capture_output=True, text=True, timeout=300, check=False
    )
    assert result.returncode == 2, result.stderr
    how = "signal SIGABRT" if "abort" in ending else "exit code 0"
    assert result.stderr == (
        f"usdrender-lint: error: {crash}: the linter process crashed while reading it ({how})\n"
    )
    files = {entry["file"]: entry for entry in json.loads(result.stdout)["files"]}
    assert files[str(crash)]["status"] == "error"
    return files


def test_after_the_child_crashed_in_process_the_rest_are_still_linted(tmp_path: Path) -> None:
    # --jobs 1 --timeout 0 lints every file in the child; after its crash the
    # supervisor linted them again in its own process, crashed on the same file,
    # and the command died of SIGABRT with no report.
    files = _crash_run(tmp_path, "os.abort()", ("--jobs", "1", "--timeout", "0"), both=True)
    other = files[str(tmp_path / "other.usda")]
    assert other["status"] == "linted" and other["findings"]


@pytest.mark.parametrize(
    "options", [(), ("--jobs", "1", "--timeout", "0")], ids=["lone", "in-process"]
)
def test_a_child_ended_by_os_exit_is_a_crash_not_its_status(
    tmp_path: Path, options: tuple[str, ...]
) -> None:
    # A rule's os._exit(0) ended the child linting in-process with status 0: the
    # supervisor exited 0 with no report, and a CI gate passed.
    files = _crash_run(tmp_path, "os._exit(0)", options, both=bool(options))
    assert all(entry["status"] == "linted" for path, entry in files.items() if "other" in path)


@pytest.mark.parametrize(
    ("signum", "status", "line"),
    [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")],
)
def test_a_signal_to_the_supervisor_ends_a_child_stuck_in_usd(
    tmp_path: Path, signum: int, status: int, line: str
) -> None:
    process, _ = _start_on_a_hang(tmp_path, "--timeout", "600")
    [child] = descendants(process.pid)
    started = time.monotonic()
    process.send_signal(signum)
    stdout, stderr = process.communicate(timeout=30)
    assert (process.returncode, stdout) == (status, "")
    assert stderr == f"usdrender-lint: {line}\n"
    assert time.monotonic() - started < 10
    assert not is_running(child)


@pytest.mark.parametrize(
    "options", [(), ("--jobs", "1", "--timeout", "0"), ("-",)], ids=["file", "in-process", "stdin"]
)
def test_the_supervised_child_lints_under_a_memory_cap(options: tuple[str, ...]) -> None:
    """A corrupt crate can make USD allocate until the machine runs out: in the
    child, under the cap the pool's workers have, the allocation fails for that
    file instead (tests/cli/test_hostile.py has the crate). ``check -`` lints
    standard input's text in the child too."""
    stdin = BROKEN.read_text() if "-" in options else None
    paths = () if stdin is not None else (str(BROKEN),)
    supervised, capped, stdout = after_a_supervised_command(
        "resource.getrlimit(resource.RLIMIT_DATA)[0] != resource.RLIM_INFINITY",
        *("check", "--isolated", *options, *paths),
        stdin=stdin,
    )
    assert "findings in 1 file" in stdout  # it did lint
    assert (supervised, capped) == (True, True)


def _pipes(pid: int) -> set[str]:
    found = set()
    for fd in Path(f"/proc/{pid}/fd").iterdir():
        with contextlib.suppress(OSError):
            target = os.readlink(fd)
            if target.startswith("pipe:"):
                found.add(target)
    return found


def test_only_the_child_holds_the_pipe_it_watches(tmp_path: Path) -> None:
    """The pool's workers, forked from the child, close their copies: the pipe,
    and the SIGIO its closing sends to the child's pid, end with the child, and
    the supervisor hears the child end, not its workers."""
    temporary = tmp_path / "tmp"
    temporary.mkdir()
    process = subprocess.Popen(
        command(
            "check", "--isolated", "--timeout", "600", str(hanging_stage(tmp_path)), str(BROKEN)
        ),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env={**os.environ, "TMPDIR": str(temporary)},
    )
    try:
        wait_for_a_worker(process, temporary)
        standard = {os.readlink(f"/proc/{process.pid}/fd/{fd}") for fd in (0, 1, 2)}
        # The pipe the child watches (the supervisor holds its write end), the one
        # the child tells the supervisor on and the one it writes its stack into
        # when asked (the supervisor holds their read ends).
        watch = _pipes(process.pid) - standard
        [child] = [pid for pid in descendants(process.pid) if _parent(pid) == process.pid]
        workers = descendants(child)
        assert len(watch) == 3 and watch <= _pipes(child)
        assert workers and not any(watch & _pipes(worker) for worker in workers)
    finally:
        process.kill()
        process.communicate(timeout=30)


def _parent(pid: int) -> int:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return int(fields[1])


HANGS_WITH_A_STACK = (
    "import faulthandler, signal, sys, time; "
    "faulthandler.register(signal.SIGUSR2, file=int(sys.argv[1]), all_threads=True); time.sleep(60)"
)


def test_the_supervisor_owns_the_timer_of_the_lint_its_child_says_started() -> None:
    """The child says "started, may take N s" and "ended" over a pipe; past N s
    the supervisor kills it (the child arms no timer of its own)."""
    # A child that writes its stack into a pipe when asked, as the command's does.
    stack, stack_write = os.pipe()
    hung = subprocess.Popen(
        [sys.executable, "-c", HANGS_WITH_A_STACK, str(stack_write)], pass_fds=(stack_write,)
    )
    os.close(stack_write)
    time.sleep(1)  # its handler is registered
    heard, says = os.pipe()
    supervisor.Supervision(says=says)._say(0.3)  # as timed() does, then hangs
    started = time.monotonic()
    assert supervisor._time_the_child(hung.pid, heard, stack) == "timeout"
    assert hung.wait(10) == -signal.SIGKILL
    assert 0.3 <= time.monotonic() - started < 10
    # Asked before it was killed, it said where it was.
    assert "line 1 in <module>" in supervisor._read_stack(stack)
    os.close(says)
    os.close(heard)
    os.close(stack)
    stack, _ = os.pipe()  # from the children below, which are never asked
    # A lint that ended in time: the supervisor waits for the child's end, no kill.
    finished = subprocess.Popen(["sleep", "60"])
    heard, says = os.pipe()
    assert supervisor.Supervision(says=says).timed(0.3, len, "done") == 4
    os.close(says)
    assert supervisor._time_the_child(finished.pid, heard, stack) is None  # it did not say it exits
    assert finished.poll() is None
    finished.kill()
    finished.wait(10)
    os.close(heard)
    # A child that says it exits: its status is the command's.
    heard, says = os.pipe()
    supervisor.Supervision(says=says).timed(0.3, len, "done")
    supervisor.Supervision(says=says).exiting()
    os.close(says)
    assert supervisor._time_the_child(finished.pid, heard, stack) == "done"
    os.close(heard)


ENDS_AS_ITS_STACK_IS_TAKEN = """
import os, signal, sys, time
stack, says = int(sys.argv[1]), int(sys.argv[2])
def ended(*_):
    os.write(stack, b"the stack\\n")
    os.write(says, b"0.0\\n")  # its lint returned
    time.sleep(0.3)  # it writes its report
    os.write(says, b"done\\n")
    os._exit(0)
signal.signal(int(sys.argv[3]), ended)
os.write(says, b"0.3\\n")  # its lint started
time.sleep(60)
"""


def test_a_lint_that_ends_as_its_stack_is_taken_stands() -> None:
    """Past its deadline the child is asked for its stack, and goes on meanwhile:
    a lint that returned then wrote its report, and the supervisor still killed
    it and ran the command again with "timed out", a second report after the
    first (two JSON documents on stdout for 'spec --timeout' of one file)."""
    from usdrender_lint.running.interrupts import STALL_SIGNAL

    stack, stack_write = os.pipe()
    heard, says = os.pipe()
    child = subprocess.Popen(
        [sys.executable, "-c", ENDS_AS_ITS_STACK_IS_TAKEN, str(stack_write), str(says),
         str(int(STALL_SIGNAL))],
        pass_fds=(stack_write, says),
    )  # fmt: skip
    os.close(stack_write)
    os.close(says)
    try:
        assert supervisor._time_the_child(child.pid, heard, stack) == "done"
        assert child.wait(10) == 0
    finally:
        child.kill()
        child.wait(10)
        for fd in (heard, stack):
            os.close(fd)
