"""A lone file's layers are read on a thread while the supervised child imports
the linter (running/read_ahead.py), and no finding changes for it."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
from pathlib import Path

import pytest
from cli_support import after_a_supervised_command
from pxr import Sdf

from usdrender_lint.running import read_ahead, workers
from usdrender_lint.running.supervisor import NO_SUPERVISOR_ENV

SHOT = """#usda 1.0
(
    subLayers = [@./lighting.usda@]
)
def RenderSettings "Settings"
{
    float4 dataWindowNDC = (1, 0, 0, 1)
}
"""
LIGHTING = '#usda 1.0\ndef Xform "Lights"\n{\n}\n'
#: What the supervised child recorded of its reads ahead, once the command is done.
USED = "__import__('usdrender_lint.running.read_ahead', fromlist=['used']).used"
STARTED = "__import__('usdrender_lint.running.read_ahead', fromlist=['started']).started"


@pytest.fixture
def shot(tmp_path: Path) -> Path:
    (tmp_path / "lighting.usda").write_text(LIGHTING)
    root = tmp_path / "shot.usda"
    root.write_text(SHOT)
    return root


def test_the_root_layer_stack_is_held_until_the_lint_is_done(shot: Path) -> None:
    read_ahead.start(str(shot))
    with read_ahead.held(str(shot)):
        assert Sdf.Layer.Find(str(shot)) is not None
        assert Sdf.Layer.Find(str(shot.parent / "lighting.usda")) is not None
    # Nothing else holds them: the lint's own stage would have.
    assert Sdf.Layer.Find(str(shot)) is None
    assert Sdf.Layer.Find(str(shot.parent / "lighting.usda")) is None


def test_the_lint_claims_the_read_by_the_file_not_the_spelling(
    shot: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(shot.parent)
    read_ahead.start(str(shot))
    with read_ahead.held("./shot.usda"):
        assert Sdf.Layer.Find(str(shot)) is not None
    assert read_ahead.used[-1] == "./shot.usda"


def test_a_read_that_fails_keeps_no_layer(tmp_path: Path) -> None:
    broken = tmp_path / "broken.usda"
    broken.write_text('#usda 1.0\ndef Xform "A" {\n  float x = \n}\n')
    read_ahead.start(str(broken))
    before = list(read_ahead.used)
    with read_ahead.held(str(broken)):
        assert Sdf.Layer.Find(str(broken)) is None
    assert read_ahead.used == before


def test_a_fifo_sublayer_is_left_to_the_lint(tmp_path: Path) -> None:
    if not hasattr(os, "mkfifo"):
        pytest.skip("no FIFOs")
    os.mkfifo(tmp_path / "pipe.usda")
    root = tmp_path / "hangs.usda"
    root.write_text("#usda 1.0\n(\n    subLayers = [@./pipe.usda@]\n)\n")
    read_ahead.start(str(root))
    with read_ahead.held(str(root)):  # returns: the FIFO was never opened
        assert Sdf.Layer.Find(str(root)) is not None


def test_the_lint_of_another_file_drops_the_read(shot: Path) -> None:
    read_ahead.start(str(shot))
    other = shot.with_name("other.usda")
    other.write_text(LIGHTING)
    with read_ahead.held(str(other)):
        assert Sdf.Layer.Find(str(shot)) is None


def test_a_fork_waits_for_the_read_and_drops_it(shot: Path) -> None:
    read_ahead.start(str(shot))
    read_ahead.finish()
    assert "usdrender-lint read-ahead" not in [t.name for t in threading.enumerate()]
    assert Sdf.Layer.Find(str(shot)) is None
    with read_ahead.held(str(shot)):  # nothing left to claim
        assert Sdf.Layer.Find(str(shot)) is None


def test_a_fork_checks_for_threads_after_the_read(
    shot: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    finished: list[bool] = []
    monkeypatch.setattr(read_ahead, "finish", lambda: finished.append(True))
    workers._single_threaded()
    assert finished == [True]


class _Exited(Exception):
    pass


def test_the_command_ends_without_waiting_for_a_read_no_lint_claimed(
    shot: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def exit_now(status: int) -> None:
        raise _Exited(status)

    monkeypatch.setattr(os, "_exit", exit_now)
    read_ahead.end_unclaimed(1)  # nothing pending: returns
    release = threading.Event()
    read_ahead.start(str(shot))
    pending = next(iter(read_ahead._pending.values()))
    pending.thread.join()
    stuck = threading.Thread(target=release.wait)  # a read still inside USD
    monkeypatch.setattr(pending, "thread", stuck)
    stuck.start()
    try:
        with pytest.raises(_Exited) as exited:
            read_ahead.end_unclaimed(1)
        assert exited.value.args == (1,)
        with pytest.raises(_Exited) as exited:
            read_ahead.end_unclaimed(None)
        assert exited.value.args == (0,)
    finally:
        release.set()
        read_ahead.finish()


def test_a_cached_lone_file_reports_as_the_first_run(tmp_path: Path) -> None:
    # Big enough that its read is likely still running when the cache answers.
    body = "".join(f'def Xform "X{i}"\n{{\n    double a = {i}\n}}\n' for i in range(60000))
    big = tmp_path / "big.usda"
    big.write_text(SHOT.replace('def RenderSettings "Settings"', body + 'def RenderSettings "S"'))
    (tmp_path / "lighting.usda").write_text(LIGHTING)
    unset = (NO_SUPERVISOR_ENV, "USDRENDER_LINT_NO_CACHE")  # supervised, cached
    env = {k: v for k, v in os.environ.items() if k not in unset}
    runs = [
        subprocess.run(
            [sys.executable, "-m", "usdrender_lint", "check", "--isolated", "big.usda"],
            capture_output=True,
            text=True,
            env=env,
            cwd=tmp_path,
            timeout=120,
        )
        for _ in range(2)
    ]
    assert (tmp_path / ".usdrender_lint_cache").is_dir()
    assert runs[0].returncode == runs[1].returncode == 1
    assert runs[0].stdout == runs[1].stdout
    assert "SE003" in runs[1].stdout


@pytest.mark.parametrize(
    ("name", "wanted"),
    [("shot.usda", True), ("shot.USDC", True), ("shot.usdz", False), ("missing.usda", False)],
)
def test_only_layer_files_are_read_ahead(tmp_path: Path, name: str, wanted: bool) -> None:
    if name != "missing.usda":
        (tmp_path / name).write_text("#usda 1.0\n")
    assert read_ahead.wanted(str(tmp_path / name)) is wanted
    assert not read_ahead.wanted(str(tmp_path))  # a folder


@pytest.mark.parametrize("command", ["check", "spec"])
def test_the_supervised_child_reads_a_lone_file_ahead(shot: Path, command: str) -> None:
    supervised, used, _ = after_a_supervised_command(USED, command, "--isolated", str(shot))
    assert supervised
    assert used == [str(shot)]


def test_a_file_linted_inside_its_roots_is_not_read_ahead(shot: Path) -> None:
    (shot.parent / ".usdrender-lint.toml").write_text('roots = ["shot.usda"]\n')
    lighting = str(shot.parent / "lighting.usda")
    supervised, started, _ = after_a_supervised_command(STARTED, "check", "--no-cache", lighting)
    assert supervised
    assert started == []
    # --no-roots lints it on its own, in the child: read ahead.
    supervised, used, _ = after_a_supervised_command(
        USED, "check", "--no-cache", "--no-roots", lighting
    )
    assert used == [lighting]


def test_several_files_are_not_read_ahead(shot: Path) -> None:
    other = shot.with_name("other.usda")
    other.write_text(LIGHTING)
    supervised, used, _ = after_a_supervised_command(
        USED, "check", "--isolated", str(shot), str(other)
    )
    assert supervised
    assert used == []


def _report(path: Path, cwd: Path, supervised: bool) -> dict:
    env = dict(os.environ)
    if supervised:
        env.pop(NO_SUPERVISOR_ENV, None)
    else:
        env[NO_SUPERVISOR_ENV] = "1"
    proc = subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "check", "--isolated", "--no-cache"]
        + ["--format", "json", path.name],
        capture_output=True,
        text=True,
        env=env,
        cwd=cwd,
        timeout=120,
    )
    return {"status": proc.returncode, "report": json.loads(proc.stdout)}


@pytest.mark.parametrize(
    "case",
    ["findings", "syntax error", "missing sublayer", "broken sublayer", "crate"],
)
def test_findings_are_those_of_a_run_without_a_read_ahead(tmp_path: Path, case: str) -> None:
    (tmp_path / "lighting.usda").write_text(LIGHTING)
    root = tmp_path / "shot.usda"
    if case == "syntax error":
        root.write_text('#usda 1.0\ndef Xform "A" {\n  float x = \n}\n')
    elif case == "missing sublayer":
        root.write_text(SHOT.replace("lighting.usda", "nowhere.usda"))
    elif case == "broken sublayer":
        (tmp_path / "lighting.usda").write_text('#usda 1.0\ndef "A" {{\n')
        root.write_text(SHOT)
    else:
        root.write_text(SHOT)
    if case == "crate":
        crate = tmp_path / "shot.usdc"
        Sdf.Layer.FindOrOpen(str(root)).Export(str(crate))
        root = crate
    ahead = _report(root, tmp_path, supervised=True)
    assert ahead == _report(root, tmp_path, supervised=False)
    assert ahead["report"]["files"]
