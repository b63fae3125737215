"""``check --watch``: a check again after each save that can change the report
(a layer, a configuration, a .gitignore), until Ctrl-C; the real command in its
own process, its files changed as an editor saves them."""

from __future__ import annotations

import json
import os
import queue
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import IO

import pytest

from usdrender_lint.running.watching import relevant

pytestmark = pytest.mark.heavy(seconds=36)

REPO = Path(__file__).parents[2]
BIN = Path(sys.executable).parent / "usdrender-lint"
CLEAN = REPO / "examples" / "clean_shot" / "shot.usda"
#: The clean shot's camera target, and one that is an Xform (CA004).
GOOD_CAMERA = "rel camera = </World/shotCam>"
BAD_CAMERA = "rel camera = </World>"
WAIT = 60.0  # seconds a round may take on a loaded machine


def save(path: Path, text: str) -> None:
    """As an editor saves: a new file renamed over the old one."""
    temporary = path.with_name(f".{path.name}.swp")
    temporary.write_text(text)
    os.replace(temporary, path)


class Watched:
    """``check --watch`` running; ``rounds`` counts the checks it has finished."""

    def __init__(self, cwd: Path, *args: str) -> None:
        self.process = subprocess.Popen(
            [str(BIN), "check", "--watch", *args],
            cwd=cwd,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            stdin=subprocess.DEVNULL,
            text=True,
        )
        self.stderr: list[str] = []
        self.stdout: list[str] = []
        self._lines: queue.Queue[str] = queue.Queue()
        self.rounds = 0
        self._readers = [
            threading.Thread(target=self._read, args=(self.process.stderr, self._lines.put)),
            threading.Thread(target=self._read, args=(self.process.stdout, self.stdout.append)),
        ]
        for reader in self._readers:
            reader.start()

    @staticmethod
    def _read(stream: IO[str] | None, keep: Callable[[str], None]) -> None:
        assert stream is not None
        for line in stream:
            keep(line)

    def next_round(self) -> list[str]:
        """Wait for the next check to finish; the stderr lines it wrote."""
        lines = []
        deadline = time.monotonic() + WAIT
        while True:
            line = self._lines.get(timeout=max(0.1, deadline - time.monotonic()))
            self.stderr.append(line)
            lines.append(line)
            if "watching for changes" in line:
                self.rounds += 1
                return lines

    def quiet_for(self, seconds: float) -> bool:
        """No round starts within ``seconds``."""
        try:
            line = self._lines.get(timeout=seconds)
        except queue.Empty:
            return True
        self.stderr.append(line)
        return False

    def stop(self, signum: int = signal.SIGINT) -> tuple[int, str, str]:
        """Signal the command; its exit status, stdout and stderr."""
        self.process.send_signal(signum)
        status = self.process.wait(timeout=WAIT)
        for reader in self._readers:
            reader.join(timeout=WAIT)
        while not self._lines.empty():
            self.stderr.append(self._lines.get())
        return status, "".join(self.stdout), "".join(self.stderr)


@pytest.fixture
def show(tmp_path: Path) -> Path:
    folder = tmp_path / "show"
    folder.mkdir()
    shutil.copy(CLEAN, folder / "shot.usda")
    return folder


def _codes(report: Path) -> list[str]:
    data = json.loads(report.read_text())
    return [f["code"] for file in data["files"] for f in file["findings"]]


def test_each_save_is_checked_again_until_ctrl_c(show: Path) -> None:
    report = show.parent / "report.json"
    watched = Watched(show.parent, "--format", "json", "--output", str(report), "show")
    try:
        watched.next_round()
        assert _codes(report) == []
        shot = show / "shot.usda"
        save(shot, shot.read_text().replace(GOOD_CAMERA, BAD_CAMERA))
        assert "changed: show/shot.usda" in "".join(watched.next_round())
        assert _codes(report) == ["CA004"]
        assert watched.quiet_for(1.0)  # one save, one check
        # The show's configuration: written, saved broken (one line, still watching), mended.
        config = show / ".usdrender-lint.toml"
        save(config, 'ignore = ["CA004"]\n')
        watched.next_round()
        assert _codes(report) == []
        save(config, "ignore = [\n")
        lines = "".join(watched.next_round())
        assert "usdrender-lint: error: " in lines and ".usdrender-lint.toml" in lines
        save(config, "")
        watched.next_round()
        assert _codes(report) == ["CA004"]
        # A new layer in a new folder; a file the walk never lints changes nothing.
        (show / "seq").mkdir()
        save(show / "seq" / "other.usda", shot.read_text())
        watched.next_round()
        assert _codes(report) == ["CA004", "CA004"]
        (show / "notes.txt").write_text("not a layer\n")
        assert watched.quiet_for(1.5)
    finally:
        status, out, err = watched.stop()
    assert status == 130, err
    assert "usdrender-lint: interrupted" in err
    assert "Traceback" not in err and out == ""


def test_a_configuration_above_the_watched_folder_is_watched_too(show: Path) -> None:
    """Outside the paths watched (a project's pyproject.toml above its shots): its
    stamp is compared once a second. The text report goes to stdout each round."""
    shot = show / "shot.usda"
    save(shot, shot.read_text().replace(GOOD_CAMERA, BAD_CAMERA))
    project = show.parent / "pyproject.toml"
    project.write_text("[tool.usdrender-lint]\n")
    watched = Watched(show.parent, str(show))
    try:
        watched.next_round()
        save(project, '[tool.usdrender-lint]\nignore = ["CA004"]\n')
        assert "pyproject.toml" in "".join(watched.next_round())
        save(project, "[tool.usdrender-lint\n")  # half-written: one line, and it goes on
        assert "usdrender-lint: error: " in "".join(watched.next_round())
        save(project, "[tool.usdrender-lint]\n")
        watched.next_round()
    finally:
        status, out, err = watched.stop(signal.SIGTERM)
    assert status == 143, err
    assert out.count("1 finding in 1 file") == 2 and out.count("0 findings in 1 file") == 1
    assert "Traceback" not in err


def test_a_file_given_is_seen_save_after_save(show: Path) -> None:
    """An editor's save replaces the file, which ends a watch on the file itself."""
    shot = show / "shot.usda"
    good = shot.read_text()
    watched = Watched(show, "shot.usda")
    try:
        watched.next_round()
        save(shot, good.replace(GOOD_CAMERA, BAD_CAMERA))
        watched.next_round()
        save(shot, good)
        watched.next_round()
    finally:
        status, out, err = watched.stop()
    assert status == 130, err
    assert out.count("0 findings in 1 file") == 2 and out.count("1 finding in 1 file") == 1


def test_a_sublayer_of_a_file_given_is_seen(show: Path) -> None:
    """Only the file given is watched by events; the layers it composes are
    polled, so the stage is linted again when its sublayer is saved."""
    shot = show / "shot.usda"
    (show / "sub.usda").write_text("#usda 1.0\n")
    (show / "stage.usda").write_text("#usda 1.0\n(\n    subLayers = [@sub.usda@]\n)\n")
    watched = Watched(show, "stage.usda")
    try:
        watched.next_round()
        save(show / "sub.usda", shot.read_text().replace(GOOD_CAMERA, BAD_CAMERA))
        watched.next_round()
    finally:
        status, out, err = watched.stop()
    assert status == 130, err
    assert "0 findings in 1 file" in out and "CA004" in out, out


def test_a_missing_sublayer_saved_later_is_seen(show: Path) -> None:
    """The stage reports its missing sublayer; saving it starts a round, as a
    watch of the folder would (only the file given is watched by events)."""
    (show / "stage.usda").write_text("#usda 1.0\n(\n    subLayers = [@./sub.usda@]\n)\n")
    watched = Watched(show, "stage.usda")
    try:
        watched.next_round()
        save(show / "sub.usda", "#usda 1.0\n")
        watched.next_round()
    finally:
        status, out, err = watched.stop()
    assert status == 130, err
    assert "ST002" in out and "0 findings in 1 file" in out, out


def test_a_configuration_saved_nearer_than_the_one_in_effect_is_seen(show: Path) -> None:
    """A show's configuration saved between the watched folder and the project's:
    it is the one a fresh check reads from then on."""
    seq = show / "seq"
    seq.mkdir()
    shot = show / "shot.usda"
    (seq / "shot.usda").write_text(shot.read_text().replace(GOOD_CAMERA, BAD_CAMERA))
    (show.parent / "pyproject.toml").write_text("[tool.usdrender-lint]\n")
    watched = Watched(show.parent, str(seq))
    try:
        watched.next_round()
        save(show / ".usdrender-lint.toml", 'ignore = ["CA004"]\n')
        assert ".usdrender-lint.toml" in "".join(watched.next_round())
    finally:
        status, out, err = watched.stop()
    assert status == 130, err
    assert out.count("1 finding in 1 file") == 1 and out.count("0 findings in 1 file") == 1


def test_the_repository_gitignore_above_the_watched_folder_is_seen(show: Path) -> None:
    """A walk reads the .gitignore files up to the repository's root."""
    (show.parent / ".git").mkdir()
    seq = show / "seq"
    seq.mkdir()
    shutil.copy(show / "shot.usda", seq / "shot.usda")
    watched = Watched(show.parent, str(show))
    try:
        watched.next_round()
        save(show.parent / ".gitignore", "seq/\n")
        assert ".gitignore" in "".join(watched.next_round())
    finally:
        status, out, err = watched.stop()
    assert status == 130, err
    assert out.count("0 findings in 2 files") == 1 and out.count("0 findings in 1 file") == 1


def _finished(cwd: Path, *command: str) -> subprocess.CompletedProcess:
    """A command that must end by itself, its standard input a layer's text."""
    return subprocess.run(
        list(command),
        cwd=cwd,
        input=CLEAN.read_text(),
        capture_output=True,
        text=True,
        check=False,
        timeout=WAIT,
    )


@pytest.mark.parametrize(
    ("args", "named"),
    [
        (("--fix", "show"), "--fix, --diff or --fix-to"),
        (("--diff", "show"), "--fix, --diff or --fix-to"),
        (("--write-baseline", "b.json", "show"), "--write-baseline"),
        (("-",), "'-' (standard input)"),
    ],
)
def test_what_a_watched_check_refuses(show: Path, args: tuple[str, ...], named: str) -> None:
    run = _finished(show.parent, str(BIN), "check", "--watch", *args)
    assert run.returncode == 2
    assert run.stderr.strip().splitlines() == [
        f"usdrender-lint: error: --watch cannot be combined with {named}: "
        "it writes nothing but its report"
    ]
    assert (show / "shot.usda").read_text() == CLEAN.read_text()


def test_a_path_that_does_not_exist_is_nothing_to_watch(show: Path) -> None:
    run = _finished(show.parent, str(BIN), "check", "--watch", "nowhere")
    assert run.returncode == 2
    assert run.stderr.strip().splitlines() == [
        "usdrender-lint: error: --watch: nothing to watch: nowhere: no such file or folder"
    ]


def test_without_the_extra_it_says_what_to_install(show: Path) -> None:
    code = (
        "import sys; sys.modules['watchfiles'] = None\n"
        "from usdrender_lint.cli import main\n"
        "main(['check', '--watch', 'show'])\n"
    )
    run = _finished(show.parent, sys.executable, "-c", code)
    assert run.returncode == 2
    assert run.stderr.strip() == (
        "usdrender-lint: error: --watch needs the watchfiles package (the [watch] extra): "
        "pip install watchfiles"
    )


@pytest.mark.parametrize(
    ("path", "wanted"),
    [
        ("show/shot.usda", True),
        ("show/SHOT.USDC", True),
        ("show/.usdrender-lint.toml", True),
        ("show/pyproject.toml", True),
        ("show/.gitignore", True),
        ("show/notes.txt", False),
        ("show/.shot.usda.swp", False),
        ("show/.git/shot.usda", False),
        ("show/.usdrender_lint_cache/x.usda", False),
        ("show/.usdrender_lint_cache/.gitignore", False),
    ],
)
def test_which_changes_matter(tmp_path: Path, path: str, wanted: bool) -> None:
    assert relevant(str(tmp_path / path), str(tmp_path)) is wanted


def test_a_folder_moved_in_matters_and_a_hidden_one_does_not(tmp_path: Path) -> None:
    (tmp_path / "seq").mkdir()
    (tmp_path / ".cache").mkdir()
    assert relevant(str(tmp_path / "seq"), str(tmp_path))
    assert not relevant(str(tmp_path / ".cache"), str(tmp_path))


def test_a_save_right_after_the_watch_starts_is_seen(tmp_path: Path) -> None:
    """What changes during the first round (before the first wait) starts the next."""
    from usdrender_lint.running.watching import Watcher

    watcher = Watcher([str(tmp_path)])
    save(tmp_path / "shot.usda", CLEAN.read_text())  # at once, as a round would run
    seen: list[list[str]] = []
    waiting = threading.Thread(target=lambda: seen.append(watcher.wait()), daemon=True)
    waiting.start()
    waiting.join(timeout=WAIT)
    assert seen == [[str(tmp_path / "shot.usda")]]


def test_the_users_own_configuration_is_watched_where_no_project_has_one(
    show: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """With no project configuration above the shots, the user's own
    (~/.config/usdrender-lint) is read: a save of it starts a round too."""
    shot = show / "shot.usda"
    save(shot, shot.read_text().replace(GOOD_CAMERA, BAD_CAMERA))
    user = tmp_path / "xdg" / "usdrender-lint"
    user.mkdir(parents=True)
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "xdg"))  # the command inherits it
    watched = Watched(show, str(show))
    try:
        watched.next_round()
        save(user / "usdrender-lint.toml", 'ignore = ["CA004"]\n')
        assert "usdrender-lint.toml" in "".join(watched.next_round())
    finally:
        status, out, err = watched.stop(signal.SIGTERM)
    assert status == 143, err
    assert out.count("1 finding in 1 file") == 1 and out.count("0 findings in 1 file") == 1
