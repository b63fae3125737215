"""File names that are not valid UTF-8 in --fix, --diff and --fix-to: the
file is fixed (or the patch shown) and named in the escaped, lossless form the
reports use; --fix-to cannot sublayer such a root (USD asset paths are UTF-8)
and says so in one line."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
BROKEN = (REPO / "examples" / "broken_shot" / "shot.usda").read_bytes()
FOLDER, NAME = b"d\xff", b"shot\xfe.usda"


def lint(folder: Path, *args: str | bytes) -> subprocess.CompletedProcess[bytes]:
    return subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "check", "--isolated", "--no-cache", *args],
        capture_output=True,
        cwd=folder,
        timeout=300,
    )


@pytest.fixture
def shot(tmp_path: Path) -> bytes:
    """``d\\xff/shot\\xfe.usda`` (the broken example shot), relative to tmp_path."""
    try:
        os.mkdir(os.path.join(os.fsencode(tmp_path), FOLDER))
    except (OSError, UnicodeError):
        pytest.skip("this file system keeps only UTF-8 names")
    path = os.path.join(FOLDER, NAME)
    with open(os.path.join(os.fsencode(tmp_path), path), "wb") as stream:
        stream.write(BROKEN)
    return path


def _read(tmp_path: Path, path: bytes) -> bytes:
    with open(os.path.join(os.fsencode(tmp_path), path), "rb") as stream:
        return stream.read()


def _listing(tmp_path: Path) -> list[bytes]:
    return sorted(
        os.path.relpath(os.path.join(root, name), os.fsencode(tmp_path))
        for root, _, names in os.walk(os.fsencode(tmp_path))
        for name in names
    )


@pytest.mark.parametrize(
    "jobs", [["--jobs", "1", "--timeout", "0"], []], ids=["in-process", "worker"]
)
def test_fix_rewrites_a_file_whose_name_is_not_utf8(
    tmp_path: Path, shot: bytes, jobs: list[str]
) -> None:
    result = lint(tmp_path, *jobs, "--fix", shot)
    assert result.returncode == 1, result.stderr  # findings without a safe fix remain
    assert result.stderr == b""
    fixed = _read(tmp_path, shot)
    assert b"rel camera = </World/camRig/shotCam>" in fixed
    assert b"uniform bool disableMotionBlur = 1" in fixed
    out = result.stdout.decode("utf-8")  # the report is valid UTF-8
    assert "d\\xff/shot\\xfe.usda: fixed CA004 " in out
    # The fixed file is linted again as itself, not as a corrupt file (ST001).
    assert "d\\xff/shot\\xfe.usda:51: error CA003 " in out and "ST001" not in out
    assert _listing(tmp_path) == [shot]  # no temporary file left beside it


def test_diff_shows_the_patch_of_a_file_whose_name_is_not_utf8(tmp_path: Path, shot: bytes) -> None:
    result = lint(tmp_path, "--diff", shot)
    assert (result.returncode, result.stderr) == (
        1,
        b"usdrender-lint: --diff: 2 fixes would be applied\n",
    )
    patch = result.stdout.decode("utf-8")
    # Quoted with octal escapes, as git quotes such a name: git apply and patch read it.
    assert patch.startswith('--- "d\\377/shot\\376.usda"\n+++ "d\\377/shot\\376.usda"\n')
    assert "+        rel camera = </World/camRig/shotCam>\n" in patch
    assert _read(tmp_path, shot) == BROKEN  # --diff writes nothing


def test_fix_to_a_layer_whose_name_is_not_utf8(tmp_path: Path, shot: bytes) -> None:
    (tmp_path / "shot.usda").write_bytes(BROKEN)
    overlay = b"over\xfd.usda"
    result = lint(tmp_path, "--fix-to", overlay, "shot.usda")
    assert result.returncode == 1 and result.stderr == b"", result.stderr
    assert "over\\xfd.usda: fixed CA004 " in result.stdout.decode("utf-8")
    text = _read(tmp_path, overlay).decode("utf-8")
    assert "@shot.usda@" in text and "</World/camRig/shotCam>" in text
    assert (tmp_path / "shot.usda").read_bytes() == BROKEN


def test_fix_to_cannot_sublayer_a_root_whose_name_is_not_utf8(tmp_path: Path, shot: bytes) -> None:
    result = lint(tmp_path, "--fix-to", "over.usda", shot)
    assert result.returncode == 2
    assert result.stderr.decode("utf-8").splitlines() == [
        "usdrender-lint: error: --fix-to over.usda: the stage's file name d\\xff/shot\\xfe.usda "
        "is not valid UTF-8, and a layer can only name a file whose name is"
    ]
    assert not (tmp_path / "over.usda").exists()
    assert _read(tmp_path, shot) == BROKEN


def test_a_stage_whose_name_is_not_utf8_with_arcs_lints_in_the_fast_path(
    tmp_path: Path, shot: bytes
) -> None:
    """A reference makes the stage worth the fast path, which reads the
    layers' identifiers: those must be read safely, or the file is taken for
    a corrupt one (ST001)."""
    (tmp_path / "asset.usda").write_text('#usda 1.0\ndef Xform "Asset"\n{\n}\n')
    text = BROKEN.replace(
        b'def Xform "World"\n{',
        b'def Xform "World"\n{\n    def "Asset" (\n        references = @../asset.usda@\n'
        b"    )\n    {\n    }",
        1,
    )
    assert text != BROKEN
    with open(os.path.join(os.fsencode(tmp_path), shot), "wb") as stream:
        stream.write(text)
    result = lint(tmp_path, "--jobs", "1", "--timeout", "0", shot)
    out = result.stdout.decode("utf-8")
    assert result.returncode == 1 and "ST001" not in out, out
    assert " error CA004 " in out
