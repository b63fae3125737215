"""The messages files-and-output.md quotes for a full disk are the ones the
command prints: a report's, and --version's and --help's."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PAGE = (REPO / "docs" / "guides" / "files-and-output.md").read_text(encoding="utf-8")
CLEAN = REPO / "examples" / "clean_shot" / "shot.usda"


def _stderr_onto_full(*args: str) -> str:
    with open("/dev/full", "w") as full:
        result = subprocess.run(
            [sys.executable, "-m", "usdrender_lint", *args],
            stdout=full,
            stderr=subprocess.PIPE,
            text=True,
            timeout=120,
        )
    assert result.returncode == 2
    return result.stderr.removeprefix("usdrender-lint: error: ").strip()


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full")
def test_the_full_disk_messages_quoted_are_printed() -> None:
    paragraph = PAGE[PAGE.index("A full disk is one line") :].split("\n\n")[0]
    quoted = re.findall(r"`(cannot write [^`]*)`", paragraph)
    assert len(quoted) == 2, paragraph
    report, version = quoted
    assert _stderr_onto_full("check", "--isolated", "-j", "1", str(CLEAN)) == report
    assert _stderr_onto_full("--version") == version
    assert _stderr_onto_full("--help") == version
