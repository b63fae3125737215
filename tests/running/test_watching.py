"""The watcher of ``check --watch`` in-process: the paths given that come,
go and come again are heard (the operating system's watch on a folder ends
with the folder, and a path that does not exist yet has none)."""

from __future__ import annotations

import os
import shutil
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

pytest.importorskip("watchfiles")

from usdrender_lint.running.watching import Watcher  # noqa: E402

LAYER = '#usda 1.0\ndef RenderSettings "rs"\n{\n}\n'
WAIT = 30.0  # seconds a change may take to be heard on a loaded machine


class Waiting:
    """One :meth:`Watcher.wait` in a thread, so that a change never heard
    fails the test instead of hanging it."""

    def __init__(self, watcher: Watcher) -> None:
        self.changed: list[str] | None = None
        self._thread = threading.Thread(target=self._wait, args=(watcher,), daemon=True)
        self._thread.start()

    def _wait(self, watcher: Watcher) -> None:
        self.changed = watcher.wait()

    def result(self) -> list[str]:
        self._thread.join(WAIT)
        assert self.changed is not None, "the change was not heard"
        return self.changed


@pytest.fixture
def folders(tmp_path: Path) -> Iterator[tuple[Path, Path]]:
    here = tmp_path / "here"
    here.mkdir()
    (here / "a.usda").write_text(LAYER)
    yield here, tmp_path / "later"


def test_a_folder_given_that_appears_later_is_heard(folders: tuple[Path, Path]) -> None:
    here, later = folders
    watcher = Watcher([str(here), str(later)])
    waiting = Waiting(watcher)
    later.mkdir()
    (later / "b.usda").write_text(LAYER)
    assert str(later) in waiting.result()
    # and from then on its saves are heard as any other
    waiting = Waiting(watcher)
    (later / "b.usda").write_text(LAYER + "\n")
    assert str(later / "b.usda") in waiting.result()


def test_a_folder_removed_and_made_again_is_heard_again(folders: tuple[Path, Path]) -> None:
    here, _ = folders
    watcher = Watcher([str(here)])
    waiting = Waiting(watcher)
    shutil.rmtree(here)
    assert waiting.result()
    waiting = Waiting(watcher)
    here.mkdir()
    assert str(here) in waiting.result()
    waiting = Waiting(watcher)
    (here / "c.usda").write_text(LAYER)
    assert str(here / "c.usda") in waiting.result()


def test_a_file_given_that_appears_later_is_heard(folders: tuple[Path, Path]) -> None:
    here, later = folders
    watcher = Watcher([str(here), str(later / "shot.usda")])
    waiting = Waiting(watcher)
    later.mkdir()
    (later / "shot.usda").write_text(LAYER)
    assert str(later / "shot.usda") in waiting.result()
    watcher.poll([])
    waiting = Waiting(watcher)
    (later / "shot.usda").write_text(LAYER + "\n")
    assert str(later / "shot.usda") in waiting.result()


def test_a_polled_layer_rewritten_with_its_time_kept_is_heard(
    folders: tuple[Path, Path], tmp_path: Path
) -> None:
    # A sublayer beside the file given is polled; rewritten with its size and
    # modification time kept (set back, or within one tick of a coarse clock)
    # it changes the report all the same.
    here, _ = folders
    sublayer = tmp_path / "lighting.usda"
    sublayer.write_text(LAYER)
    watcher = Watcher([str(here)])
    watcher.poll([str(sublayer)])
    waiting = Waiting(watcher)
    times = sublayer.stat()
    sublayer.write_text(LAYER.replace('"rs"', '"RS"'))
    os.utime(sublayer, ns=(times.st_atime_ns, times.st_mtime_ns))
    assert str(sublayer) in waiting.result()
