"""Fuzz the command at the process level: Ctrl-C or SIGTERM at a random moment,
a stdout whose reader goes away after a random number of bytes, across worker
counts, time limits, formats and report destinations.

Whatever happens, the run ends promptly with a status a shell expects, one
clear line at most for the fault, never a traceback; no temporary file or
folder is left, and a report file is either absent or complete. The moment is
taken from when the command has installed its handlers: a signal during
Python's own start-up, before the command's first line runs, is Python's.

CI runs a few examples, reproducibly; ``USDRENDER_LINT_FUZZ_EXAMPLES`` scales
them (a tenth of it here, each example being whole processes).
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from cli_support import HANGS
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

REPO = Path(__file__).resolve().parents[2]
EXAMPLE_FILES = [
    REPO / "examples" / "broken_shot" / "shot.usda",
    REPO / "examples" / "broken_shot" / "lighting_wip.usda",
    REPO / "examples" / "clean_shot" / "shot.usda",
]
_EXAMPLES_ENV = os.environ.get("USDRENDER_LINT_FUZZ_EXAMPLES")
EXAMPLES = max(8, int(_EXAMPLES_ENV or 0) // 10)
STOPPED = {"SIGINT": (130, "interrupted"), "SIGTERM": (143, "terminated")}

pytestmark = [
    pytest.mark.skipif(
        not sys.platform.startswith("linux"), reason="signals, FIFOs and pipes as on Linux"
    ),
    pytest.mark.heavy(seconds=30),
]


def _wait_for_the_handlers(pid: int) -> None:
    """Until the process catches SIGTERM (installed with SIGINT's, first thing)."""
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        try:
            status = Path(f"/proc/{pid}/status").read_text()
        except OSError:
            return  # it is gone already
        caught = next(line for line in status.splitlines() if line.startswith("SigCgt:"))
        if int(caught.split()[1], 16) & (1 << (signal.SIGTERM - 1)):
            return
        time.sleep(0.005)


def _folder(root: Path, files: int, hang: bool) -> list[str]:
    folder = root / "shots"
    folder.mkdir()
    names = []
    for index in range(files):
        source = EXAMPLE_FILES[index % len(EXAMPLE_FILES)]
        name = f"shot_{index:03d}.usda"
        (folder / name).write_text(source.read_text())
        names.append(str(folder / name))
    if hang:  # a sublayer that blocks USD forever keeps a worker busy
        os.mkfifo(folder / "pipe.usda")
        (folder / "hangs.usda").write_text(HANGS)
        names.append(str(folder / "hangs.usda"))
    return names


@settings(
    max_examples=EXAMPLES,
    deadline=None,
    database=None,
    derandomize=_EXAMPLES_ENV is None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
@given(
    fault=st.sampled_from(["SIGINT", "SIGTERM", "reader-leaves"]),
    delay=st.floats(min_value=0.0, max_value=2.5),
    read_bytes=st.integers(min_value=0, max_value=4096),
    files=st.integers(min_value=1, max_value=12),
    parallel=st.booleans(),
    output_format=st.sampled_from(["text", "json", "sarif", "github"]),
    to_file=st.booleans(),
    hang=st.booleans(),
)
def test_a_fault_at_any_moment_ends_the_run_cleanly(
    tmp_path_factory: pytest.TempPathFactory,
    fault: str,
    delay: float,
    read_bytes: int,
    files: int,
    parallel: bool,
    output_format: str,
    to_file: bool,
    hang: bool,
) -> None:
    root = tmp_path_factory.mktemp("fault")
    temporary = root / "tmp"
    temporary.mkdir()
    # A hang in this process cannot be interrupted (--jobs 1 --timeout 0 is
    # documented so): hangs go with workers and a time limit only.
    limits = (
        ["--jobs", "2", "--timeout", "20"]
        if parallel or hang
        else ["--jobs", "1", "--timeout", "0"]
    )
    report = root / "out" / "report"
    report.parent.mkdir()
    args = ["check", "--isolated", "--format", output_format, *limits]
    if to_file:
        args += ["--output", str(report)]
    process = subprocess.Popen(
        [sys.executable, "-m", "usdrender_lint", *args, *_folder(root, files, hang)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env={**os.environ, "TMPDIR": str(temporary)},
    )
    _wait_for_the_handlers(process.pid)
    if fault == "reader-leaves":
        process.stdout.read(read_bytes)  # type: ignore[union-attr]
        process.stdout.close()  # type: ignore[union-attr]
        if hang:  # nothing would end the wait on the FIFO but the time limit
            time.sleep(delay)
            process.send_signal(signal.SIGTERM)
        stderr = process.stderr.read().decode()  # type: ignore[union-attr]
        process.wait(timeout=120)
    else:
        time.sleep(delay)
        process.send_signal(getattr(signal, fault))
        stdout_bytes, stderr_bytes = process.communicate(timeout=120)
        stderr = stderr_bytes.decode()
    status = process.returncode
    signum = getattr(signal, fault, signal.SIGTERM)
    if status == -signum:
        # The signal came as the run was ending, after Python restored the
        # default handlers: it was all done by then.
        status = STOPPED.get(fault, (143,))[0]
    assert "Traceback" not in stderr and "internal error" not in stderr, stderr
    lines = stderr.splitlines()
    assert all(line.startswith("usdrender-lint: ") for line in lines), stderr
    if fault in STOPPED and status == STOPPED[fault][0] and process.returncode > 0:
        assert lines[-1] == f"usdrender-lint: {STOPPED[fault][1]}"
        assert lines.count(lines[-1]) == 1
    elif fault == "reader-leaves" and hang:
        assert status in (1, 2, 143)
    else:
        # It finished before the fault, or the reader left: quietly exit 2.
        assert status in (0, 1, 2), (status, stderr)
    # Nothing temporary is left: neither the workers' folder nor a report's.
    assert list(temporary.iterdir()) == []
    assert [p.name for p in report.parent.iterdir()] in ([], ["report"])
    if report.exists():
        text = report.read_text(encoding="utf-8")
        if output_format in ("json", "sarif"):
            json.loads(text)  # complete, never cut
        elif output_format == "text":
            assert text.endswith(".\n")  # the summary line ends the report
