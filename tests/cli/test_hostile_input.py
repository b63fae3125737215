"""Hostile input (issue 31, item 5): every crash a one-line error or an ST001
finding, the other files still linted. Each case broke before (its docstring
says how); the inputs are small, and the subprocesses carry generous time-outs
instead of timed assertions."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

from tests.cli_support import command

CLEAN = '#usda 1.0\ndef Scope "Render"\n{\n}\n'


def _without_permission_bypass() -> list[str] | None:
    """A prefix that runs a command with file permissions enforced: nothing for
    a normal user; for root, setpriv dropping the capabilities that bypass them."""
    if os.geteuid() != 0:
        return []
    setpriv = shutil.which("setpriv")
    if setpriv is None:
        return None
    prefix = [setpriv, "--bounding-set", "-dac_override,-dac_read_search"]
    probe = subprocess.run([*prefix, "true"], capture_output=True)
    return prefix if probe.returncode == 0 else None


def test_a_path_inside_a_folder_without_search_permission(tmp_path: Path) -> None:
    """The first path inside a folder without search permission was
    'internal error: PermissionError' and nothing was linted."""
    prefix = _without_permission_bypass()
    if prefix is None:
        pytest.skip("cannot drop root's permission bypass here")
    locked = tmp_path / "locked"
    locked.mkdir()
    (locked / "a.usda").write_text(CLEAN)
    (tmp_path / "open.usda").write_text(CLEAN)
    locked.chmod(0)
    try:
        result = subprocess.run(
            [*prefix, *command("check", "--no-cache", "locked/a.usda", "open.usda")],
            capture_output=True,
            text=True,
            cwd=tmp_path,
            timeout=300,
        )
    finally:
        locked.chmod(0o755)
    assert result.returncode == 2
    assert result.stderr == "usdrender-lint: error: locked/a.usda: permission denied\n"
    assert "in 2 files" in result.stdout and "1 file could not be linted" in result.stdout
