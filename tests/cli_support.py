"""Helpers the command-line tests share: the command in its own process and
the processes it starts, a stage that hangs USD, a small crate layer to
corrupt, and a layer naming a variant \"\"."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from pxr import Gf, Sdf, Usd, UsdGeom, UsdRender

REPO = Path(__file__).resolve().parents[1]
#: The examples' shot with findings (exit 1).
BROKEN = REPO / "examples" / "broken_shot" / "shot.usda"

#: A sublayer that hangs USD: a named pipe no process writes, whose open() waits
#: for a writer. Named through an expression: the engine refuses a named pipe an
#: arc names before USD opens it (stage.arc_file_problem), but an expression only
#: the stage resolves, so this reaches USD, as a hung network mount's file would.
HANGING_SUBLAYER = '@`"./pipe.usda"`@'
#: A layer whose only opinion is that sublayer.
HANGS = f"#usda 1.0\n(\n    subLayers = [{HANGING_SUBLAYER}]\n)\n"

#: A RenderSettings whose variant set holds a variant named "": Sdf's walks of
#: such a layer abort or recurse without end (usd-core 26.11); composing it works.
EMPTY_VARIANT_NAME = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings" (
        variantSets = "quality"
    )
    {
        variantSet "quality" = {
            "" {
                rel camera = </World/cam>
            }
        }
    }
}
"""


def run_cli_process(folder: Path, *args: str) -> subprocess.CompletedProcess:
    """The command in its own process, for inputs that make USD abort: USD
    writes a crash report to its temporary folder, which here is ``folder``."""
    crash_reports = folder / "usd-crash-reports"
    crash_reports.mkdir(exist_ok=True)
    result = subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "check", "--isolated", "--format", "json", *args],
        capture_output=True,
        text=True,
        env={**os.environ, "TMPDIR": str(crash_reports)},
        timeout=600,
    )
    assert "Traceback" not in result.stdout + result.stderr, result.stderr
    return result


def settings_crate(path: Path) -> bytes:
    """A small crate layer with settings, product, var and camera (also fuzzed)."""
    layer = Sdf.Layer.CreateNew(str(path))
    stage = Usd.Stage.Open(layer)
    settings = UsdRender.Settings.Define(stage, "/Render/S")
    settings.CreateResolutionAttr(Gf.Vec2i(1920, 1080))
    settings.CreateDataWindowNDCAttr(Gf.Vec4f(0, 0, 1, 1))
    settings.GetCameraRel().SetTargets(["/World/Cam"])
    product = UsdRender.Product.Define(stage, "/Render/P")
    product.CreateProductNameAttr("a.exr")
    settings.GetProductsRel().SetTargets(["/Render/P"])
    var = UsdRender.Var.Define(stage, "/Render/V")
    var.CreateSourceNameAttr("Ci")
    product.GetOrderedVarsRel().SetTargets(["/Render/V"])
    UsdGeom.Camera.Define(stage, "/World/Cam").CreateFocalLengthAttr(35)
    layer.Save()
    return path.read_bytes()


def command(*args: str) -> list[str]:
    return [sys.executable, "-m", "usdrender_lint", *args]


def hanging_stage(folder: Path) -> Path:
    """A stage whose sublayer (HANGING_SUBLAYER) blocks USD forever."""
    os.mkfifo(folder / "pipe.usda")
    stage = folder / "hangs.usda"
    stage.write_text(HANGS)
    return stage


def descendants(pid: int) -> set[int]:
    found: set[int] = set()
    pending = [pid]
    while pending:
        parent = pending.pop()
        try:
            tasks = os.listdir(f"/proc/{parent}/task")
        except OSError:
            continue
        for task in tasks:
            try:
                children = Path(f"/proc/{parent}/task/{task}/children").read_text().split()
            except OSError:
                continue
            for child in map(int, children):
                if child not in found:
                    found.add(child)
                    pending.append(child)
    return found


def until_usd_loads(pid: int) -> None:
    """Wait until the process ``pid``, or one below it, has loaded USD's Gf
    module: USD's C++ sets a module up as it loads, where an exception a signal
    handler raised was swallowed (after USD's own warning and traceback)."""
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        for each in (pid, *descendants(pid)):
            with contextlib.suppress(OSError):
                if "/pxr/Gf/_gf" in Path(f"/proc/{each}/maps").read_text():
                    return
        time.sleep(0.002)
    raise AssertionError(f"process {pid} never loaded USD")


def signalled(
    argv: list[str],
    signum: int,
    wait: Callable[[int], None],
    stdin: Any = subprocess.DEVNULL,
    cwd: Path | None = None,
) -> tuple[int, str]:
    """Start ``argv`` in a session of its own, ``wait(pid)``, then signal its
    process group as a terminal's Ctrl-C does: its exit status and what it
    wrote on standard error."""
    run = subprocess.Popen(
        argv,
        cwd=cwd,
        stdin=stdin,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        start_new_session=True,
    )
    try:
        wait(run.pid)
        os.killpg(run.pid, signum)
        _, err = run.communicate(timeout=60)
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(run.pid, signal.SIGKILL)
        run.wait()
    return run.returncode, err.decode()


def blocked_on_a_fifo(pid: int) -> bool:
    """Whether a thread of a process below ``pid`` waits in ``open()`` for a
    FIFO's writer (Linux's ``wait_for_partner``): the lint of a
    :func:`hanging_stage` has reached its sublayer, however loaded the machine."""
    return blocked_on_fifos(pid) > 0


def blocked_on_fifos(pid: int) -> int:
    """How many processes below ``pid`` wait in ``open()`` for a FIFO's writer
    (see :func:`blocked_on_a_fifo`)."""
    blocked = 0
    for child in descendants(pid):
        try:
            tasks = os.listdir(f"/proc/{child}/task")
        except OSError:
            continue
        for task in tasks:
            try:
                waits_in = Path(f"/proc/{child}/task/{task}/wchan").read_text()
            except OSError:
                continue
            if waits_in in ("wait_for_partner", "fifo_open"):
                blocked += 1
                break
    return blocked


def is_running(pid: int) -> bool:
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False
    return "\nState:\tZ" not in status


def wait_for_a_worker(
    process: subprocess.Popen, temporary: Path, pool: bool = True, limit: float = 60
) -> None:
    """Until a worker is linting the :func:`hanging_stage` and blocked on its
    FIFO (for a pool, once it has made its temporary folder too; one file is
    linted by a forked child, without one)."""
    deadline = time.monotonic() + limit
    while time.monotonic() < deadline:
        assert process.poll() is None, process.communicate()
        started = any(temporary.glob("usdrender-lint-*/worker-*.log")) or not pool
        if started and blocked_on_a_fifo(process.pid):
            return
        time.sleep(0.05)
    raise AssertionError("no worker started")


#: Runs the command as the console script does, then prints from each process
#: that ran the command the JSON of ``[supervised child, <expression>]``: the
#: supervisor's run and its child's both end here.
_AFTER_THE_COMMAND = """
import json, resource, sys
import usdrender_lint.cli as cli
from usdrender_lint.__main__ import main
seen = []
command = cli.main
def watched(argv=None, supervision=None):
    seen.append(supervision is not None and supervision.ending is None)
    command(argv, supervision)
cli.main = watched
try:
    main()
except SystemExit:
    pass
print(json.dumps([any(seen), {expression}]), file=sys.stderr)
"""


def after_a_supervised_command(
    expression: str, *args: str, stdin: str | None = None
) -> tuple[bool, object, str]:
    """(supervised, the value of ``expression``, stdout) as the supervised
    child that ran ``usdrender-lint ARGS`` (``stdin`` on its standard input) sees
    them once the command is done (else as the process that ran it)."""
    proc = subprocess.run(
        [sys.executable, "-c", _AFTER_THE_COMMAND.format(expression=expression), *args],
        capture_output=True,
        text=True,
        timeout=120,
        input=stdin,
        stdin=subprocess.DEVNULL if stdin is None else None,
    )
    said = [json.loads(line) for line in proc.stderr.splitlines() if line.startswith("[")]
    supervised, value = next((entry for entry in said if entry[0]), said[-1])
    return supervised, value, proc.stdout


def unsupervised(*args: str) -> list[str]:
    """The command run by ``usdrender_lint.cli.main`` itself: no supervisor."""
    return [sys.executable, "-c", "import sys; from usdrender_lint.cli import main; main()", *args]


def invoke_in(cwd: Path, *args: str, input: str | None = None):
    """The command line run in this process (click's runner) with ``cwd`` as the
    working directory (and ``input`` on standard input); click's Result."""
    from click.testing import CliRunner

    from usdrender_lint.cli import cli

    previous = os.getcwd()
    os.chdir(cwd)
    try:
        return CliRunner().invoke(cli, list(args), input=input)
    finally:
        os.chdir(previous)


def busy_for(built: object, seconds: float) -> float:
    """A pool's handle (workers.Pool) that works ``seconds`` of CPU time (which,
    unlike a sleep's, stands still while the process is stopped), then answers them."""
    end = time.process_time() + seconds
    while time.process_time() < end:
        pass
    return seconds
