"""A worker's read-ahead of its next file (running/prefetch.py): the layers it
opens, the files it leaves to their own lint, and that it changes no answer."""

from __future__ import annotations

import os
import time
from multiprocessing import Pipe
from pathlib import Path

import pytest
from pxr import Sdf

from usdrender_lint.config import RACY_NS
from usdrender_lint.running import stalls
from usdrender_lint.running.prefetch import Reader, spare_core
from usdrender_lint.running.workers import FullyComposed, Pool, lint_one

SHOT = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings%d"
    {
        uniform int2 resolution = (0, 1080)
    }
}
"""


def _shots(folder: Path, count: int) -> list[str]:
    paths = []
    for index in range(count):
        path = folder / f"shot{index}.usda"
        path.write_text(SHOT % index)
        paths.append(str(path))
    # A file stamped within a clock tick of its writing is read again by its lint
    # (config.stat_state): these are read ahead once that tick is over.
    time.sleep(RACY_NS / 1e9)
    return paths


def _reader(items: list) -> Reader:
    """A Reader over a pipe that has ``items`` sent, then closed."""
    here, there = Pipe()
    for index, item in enumerate(items):
        here.send((index, item))
    here.close()
    return Reader(there, lambda item: isinstance(item, FullyComposed))


def test_each_file_s_root_layer_is_read_ahead_in_order(tmp_path: Path) -> None:
    paths = _shots(tmp_path, 3)
    reader = _reader(paths)
    for index, path in enumerate(paths):
        got, item, layer = reader.next()
        assert (got, item) == (index, path)
        assert layer is not None and layer.realPath == path
        assert Sdf.Layer.Find(path) is layer  # the lint's open finds it
    with pytest.raises(EOFError):
        reader.next()


def test_a_file_linted_again_after_a_crash_and_the_next_are_not_read_ahead(
    tmp_path: Path,
) -> None:
    first, second, third = _shots(tmp_path, 3)
    reader = _reader([FullyComposed(first), second, third])
    layers = [reader.next()[2] for _ in range(3)]
    assert layers[0] is None and layers[1] is None
    assert layers[2] is not None


def _read_ahead(path: str) -> Reader:
    """A Reader given ``path`` alone, once its read-ahead has read the file."""
    here, there = Pipe()
    reader = Reader(there, lambda item: False)
    here.send((0, path))
    here.close()
    deadline = time.monotonic() + 30
    while Sdf.Layer.Find(path) is None and time.monotonic() < deadline:
        time.sleep(0.001)
    assert Sdf.Layer.Find(path) is not None
    return reader


def test_a_file_changed_after_it_was_read_is_read_again_by_its_lint(tmp_path: Path) -> None:
    (path,) = _shots(tmp_path, 1)
    reader = _read_ahead(path)  # then the file changes
    os.utime(path, ns=(1, 1))
    _, _, layer = reader.next()
    assert layer is None


def test_a_file_rewritten_with_its_time_kept_after_it_was_read_is_read_again(
    tmp_path: Path,
) -> None:
    # The same size, its modification time set back (a copy that keeps times):
    # only the change time tells the file from the one read ahead.
    (path,) = _shots(tmp_path, 1)
    before = os.stat(path)
    reader = _read_ahead(path)
    time.sleep(0.01)  # a change time the clock tells from the first
    with open(path, "r+") as handle:  # the same file (inode), rewritten in place
        handle.write((SHOT % 7).replace("(0, 1080)", "(1, 1080)"))
    os.utime(path, ns=(before.st_atime_ns, before.st_mtime_ns))
    assert os.stat(path).st_size == before.st_size
    _, _, layer = reader.next()
    assert layer is None


def test_a_file_usd_must_not_read_is_left_to_its_own_lint(tmp_path: Path) -> None:
    deep = tmp_path / "deep.usda"
    deep.write_text("#usda 1.0\n" + "(" * 200_000 + "\n")
    fifo = tmp_path / "pipe.usda"
    os.mkfifo(fifo)  # reading it would wait for a writer
    text = tmp_path / "notes.txt"
    text.write_text("not a layer")
    reader = _reader([str(deep), str(fifo), str(text), 42])
    assert [reader.next()[2] for _ in range(4)] == [None, None, None, None]
    assert Sdf.Layer.Find(str(deep)) is None


def test_linting_through_a_worker_that_reads_ahead_gives_the_same_findings(
    tmp_path: Path,
) -> None:
    from usdrender_lint.engine import Linter
    from usdrender_lint.testing import all_rules

    paths = _shots(tmp_path, 6)
    expected = tuple(Linter(all_rules()).lint_path(p) for p in paths)
    pooled = Pool(_linter, 1, 60).run(paths)
    assert pooled == expected


def _linter():
    from usdrender_lint.engine import Linter
    from usdrender_lint.testing import all_rules

    return Linter(all_rules())


def test_one_worker_of_two_cores_reads_ahead_and_one_per_core_does_not() -> None:
    cores = os.cpu_count() or 1
    assert spare_core(cores - 1) is (cores > 1)
    assert not spare_core(cores)
    assert Pool(_linter, 1, None).handle is lint_one


def test_a_worker_waiting_for_its_read_ahead_times_out_in_usd_s_open() -> None:
    code = Reader.next.__code__
    dump = (
        "Current thread 0x00007f0000000000 (most recent call first):\n"
        f'  File "{code.co_filename}", line {code.co_firstlineno + 1} in {code.co_name}\n'
    )
    assert stalls.site(dump) == "while USD opened the stage"
