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

pytestmark = pytest.mark.heavy(seconds=39)

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


#: The whole command (``python -m usdrender_lint``'s main: its supervisor, the
#: child it forks, standard input read before that fork) once per file, each run
#: in a process forked from one that imported it and linted once: every file's
#: run but the interpreter's start-up and the imports. Standard input is the
#: corpus file's text, stdout and stderr are files; an exit ends the child as it
#: ends the command's process (SystemExit, the atexit handlers run).
_COMMAND_PER_TEXT = """
import os, sys
import usdrender_lint.__main__ as command
from usdrender_lint import lint_file

corpus, out, files = sys.argv[1], sys.argv[2], sys.argv[3:]
lint_file(files[0])  # USD, the engine, the rules and their first-use costs: once, here
import usdrender_lint.cli.check, usdrender_lint.fixing, usdrender_lint.running.documents
for index, file in enumerate(files):
    child = os.fork()
    if child == 0:
        os.dup2(os.open(os.path.join(corpus, file), os.O_RDONLY), 0)
        for fd, stream in ((1, "out"), (2, "err")):
            os.dup2(os.open(f"{out}/{index}.{stream}", os.O_WRONLY | os.O_CREAT, 0o644), fd)
        sys.argv = ["usdrender-lint", "check", "--isolated", "--no-cache", "-",
                    "--stdin-filename", file, "--fix", "--fail-on", "never"]
        command.main()
        sys.exit(0)
    _, status = os.waitpid(child, 0)
    print(os.waitstatus_to_exitcode(status), flush=True)
"""


def _fixed_texts(root: Path, out: Path, files: list[str]) -> dict[str, tuple[int, bytes, bytes]]:
    """``_COMMAND_PER_TEXT`` over ``files`` (relative to ``root``): per file, the
    command's exit status, stdout and stderr."""
    done = subprocess.run(
        [sys.executable, "-c", _COMMAND_PER_TEXT, str(CORPUS), str(out), *files],
        cwd=root,
        capture_output=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    statuses = [int(line) for line in done.stdout.decode().split()]
    assert len(statuses) == len(files), done.stdout[-3000:]
    return {
        file: (status, (out / f"{index}.out").read_bytes(), (out / f"{index}.err").read_bytes())
        for index, (file, status) in enumerate(zip(files, statuses, strict=True))
    }


def test_a_text_on_standard_input_is_fixed_as_its_file(
    fixed: tuple[Path, dict], tmp_path: Path
) -> None:
    root, report = fixed
    layers: dict[str, set[str | None]] = {}
    for fix in report["fixes"]:
        layer = os.path.normpath(fix["layer"]) if fix["layer"] else None
        layers.setdefault(os.path.normpath(fix["file"]), set()).add(layer)
    own = sorted(file for file, touched in layers.items() if touched == {file})
    assert len(own) > 50
    texts = own[::5]  # every fifth
    # The first as the installed command runs, interpreter and all; the rest
    # forked (_COMMAND_PER_TEXT).
    first = subprocess.run(
        [*LINT, "-", "--stdin-filename", texts[0], "--fix", "--fail-on", "never"],
        input=(CORPUS / texts[0]).read_bytes(),
        cwd=root,
        capture_output=True,
        timeout=120,
    )
    runs = {texts[0]: (first.returncode, first.stdout, first.stderr)}
    runs.update(_fixed_texts(root, tmp_path, texts[1:]))
    differing = []
    for file in texts:
        status, stdout, stderr = runs[file]
        if status != 0 or stdout != (root / file).read_bytes():
            differing.append(f"{file}: exit {status}, {stderr[-300:]!r}")
    assert differing == []
