"""A lone file's layers are read on a thread while the supervised child imports
the linter (running/read_ahead.py), and no finding changes for it."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from cli_support import after_a_supervised_command
from pxr import Sdf, Work

from usdrender_lint.running import read_ahead
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
#: Read ahead once, inside the command: what the supervised child recorded.
USED = "__import__('usdrender_lint.running.read_ahead', fromlist=['used']).used"


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


def test_the_lint_of_another_file_ends_the_read_and_usd_gets_its_threads_back(
    shot: Path,
) -> None:
    limit = Work.GetConcurrencyLimit()
    read_ahead.start(str(shot))
    other = shot.with_name("other.usda")
    other.write_text(LIGHTING)
    with read_ahead.held(str(other)):  # as with roots: a stage that uses the file
        assert Work.GetConcurrencyLimit() == limit
        assert Sdf.Layer.Find(str(shot)) is None


def test_usd_runs_no_thread_pool_while_a_read_is_pending(shot: Path) -> None:
    limit = Work.GetConcurrencyLimit()
    read_ahead.start(str(shot))
    assert Work.GetConcurrencyLimit() == 1
    with read_ahead.held(str(shot)):
        assert Work.GetConcurrencyLimit() == limit


#: In a fresh process (this one runs USD's thread pool already): start a read
#: ahead of a crate, then ask what a fork would.
_FORK_CHECK = """
import json, sys, threading
from usdrender_lint.running import read_ahead, workers
read_ahead.start(sys.argv[1])
single = workers._single_threaded()
alive = [t.name for t in threading.enumerate() if t is not threading.main_thread()]
print(json.dumps([single, alive]))
"""


def test_a_fork_waits_for_the_read_and_the_process_is_single_threaded_again(
    shot: Path,
) -> None:
    crate = shot.with_suffix(".usdc")  # a crate starts USD's thread pool when read
    Sdf.Layer.FindOrOpen(str(shot)).Export(str(crate))
    proc = subprocess.run(
        [sys.executable, "-c", _FORK_CHECK, str(crate)],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    assert json.loads(proc.stdout) == [True, []]


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
