"""The ways to fix, on every real file (``../shared/corpus``, copied; skipped
without it): ``--diff``'s patch, applied by ``patch -p0``, leaves every file as
``--fix`` does, and ``check - --fix`` of a layer's text prints what ``--fix``
wrote into it (each layer whose fixes are all its own)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import SHARED, SHARED_MISSING

pytestmark = pytest.mark.heavy(seconds=40)

LINT = [sys.executable, "-m", "usdrender_lint", "check", "--isolated", "--no-cache"]


CORPUS = SHARED / "corpus" / "files"


def _copy(target: Path) -> Path:
    if not CORPUS.is_dir():
        pytest.skip(SHARED_MISSING)
    shutil.copytree(CORPUS, target)
    for folder, _, files in os.walk(target):
        for name in files:
            os.chmod(os.path.join(folder, name), 0o644)  # the corpus is read-only
    return target


def _contents(root: Path) -> dict[str, bytes]:
    files = sorted(p for p in root.rglob("*") if p.is_file())
    return {str(p.relative_to(root)): p.read_bytes() for p in files}


@pytest.fixture(scope="module")
def fixed(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    """The corpus after ``--fix``, and the report of that run."""
    root = _copy(tmp_path_factory.mktemp("fix") / "files")
    done = subprocess.run(
        [*LINT, "--fix", "--fail-on", "never", "--format", "json", "."],
        cwd=root,
        capture_output=True,
        timeout=600,
    )
    assert done.returncode in (0, 2), done.stderr[-3000:]
    report = json.loads(done.stdout)
    assert sum(fix["applied"] for fix in report["fixes"]) > 100
    return root, report


def test_the_diff_applied_leaves_every_file_as_fix_does(
    fixed: tuple[Path, dict], tmp_path: Path
) -> None:
    if shutil.which("patch") is None:
        pytest.skip("no patch program")
    root = _copy(tmp_path / "files")
    before = _contents(root)
    diff = subprocess.run(
        [*LINT, "--diff", "--fail-on", "never", "."], cwd=root, capture_output=True, timeout=600
    )
    assert diff.returncode == 1, diff.stderr[-3000:]  # fixes are pending
    assert _contents(root) == before  # --diff writes nothing
    subprocess.run(["patch", "-p0", "-s"], input=diff.stdout, cwd=root, check=True, timeout=60)
    assert _contents(root) == _contents(fixed[0])


def test_a_text_on_standard_input_is_fixed_as_its_file(fixed: tuple[Path, dict]) -> None:
    root, report = fixed
    layers: dict[str, set[str | None]] = {}
    for fix in report["fixes"]:
        layer = os.path.normpath(fix["layer"]) if fix["layer"] else None
        layers.setdefault(os.path.normpath(fix["file"]), set()).add(layer)
    own = sorted(file for file, touched in layers.items() if touched == {file})
    assert len(own) > 50
    differing = []
    for file in own[::5]:  # a process each: every fifth
        source = (CORPUS / file).read_bytes()
        done = subprocess.run(
            [*LINT, "-", "--stdin-filename", file, "--fix", "--fail-on", "never"],
            input=source,
            cwd=root,
            capture_output=True,
            timeout=120,
        )
        if done.returncode != 0 or done.stdout != (root / file).read_bytes():
            differing.append(f"{file}: exit {done.returncode}, {done.stderr[-300:]!r}")
    assert differing == []
