"""A file rewritten within one tick of the clock that timestamps it, with the
same size, keeps its size, times and inode: the stamp a long-running host took
(config.file_state) could not tell it from the file it read, and the host served
the first configuration or layer. A stamp taken while the file's last change is
that recent proves nothing later (git's "racily clean" entries,
Documentation/technical/racy-git.txt in git's sources): it never matches.

Here the filesystem's clock does not tick on ext4 or tmpfs, where it is fine; the
tests show the second write with the first one's stamp, as a coarse clock would,
through the ``os.stat`` the stamps read."""

from __future__ import annotations

import os
import time
import types
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from pxr import Sdf, Usd

from usdrender_lint import config as config_module
from usdrender_lint.config import file_stamps, file_state, is_racy, stamps_hold, stat_state
from usdrender_lint.running.documents import Documents
from usdrender_lint.running.stage_lints import CheckLinters

SHOT = '#usda 1.0\ndef RenderSettings "S"\n{\n    uniform int2 resolution = (0, 10)\n}\n'
SECOND = 1_000_000_000


class _OneTick:
    """``os`` as a filesystem whose clock did not tick between two writes of
    ``path`` shows it: the size, times and inode of its first stamp."""

    def __init__(self, path: Path) -> None:
        self.real = os.path.realpath(path)
        self.first = os.stat(path)

    def __getattr__(self, name: str) -> Any:
        return getattr(os, name)

    def stat(self, path: Any, *args: Any, **kwargs: Any) -> Any:
        info = os.stat(path, *args, **kwargs)
        if os.path.realpath(path) != self.real:
            return info
        first = self.first
        return types.SimpleNamespace(
            st_mode=info.st_mode,
            st_size=first.st_size,
            st_mtime_ns=first.st_mtime_ns,
            st_ctime_ns=first.st_ctime_ns,
            st_ino=first.st_ino,
        )


def _clock_at(monkeypatch: pytest.MonkeyPatch, ns: int) -> None:
    """The stamps' clock stopped at ``ns``: a slow machine stamps within the tick too."""
    monkeypatch.setattr(config_module, "time", types.SimpleNamespace(time_ns=lambda: ns))


@pytest.fixture
def one_tick(monkeypatch: pytest.MonkeyPatch) -> Iterator[Any]:
    def frozen(path: Path) -> None:
        shown = _OneTick(path)
        monkeypatch.setattr(config_module, "os", shown)
        _clock_at(monkeypatch, shown.first.st_ctime_ns)

    yield frozen


def _rewrite(path: Path, text: str) -> None:
    """Write ``text`` (the same size) over ``path`` in place, its times kept:
    USD's own reload compares the modification time alone."""
    before = path.stat()
    assert len(text.encode()) == before.st_size
    path.write_text(text)
    os.utime(path, ns=(before.st_atime_ns, before.st_mtime_ns))


# -- the stamp ---------------------------------------------------------------------------


def test_a_racy_stamp_taken_after_the_read_never_matches(tmp_path: Path) -> None:
    path = tmp_path / "a.toml"
    started = time.time_ns()
    path.write_text("x = 1\n")
    first = file_state(str(path), read_ns=started)
    assert is_racy(first) and file_state(str(path), read_ns=started) != first
    assert file_stamps([str(path)], started) != file_stamps([str(path)], started)


def test_a_racy_stamp_taken_before_the_read_is_compared_by_the_bytes(
    tmp_path: Path, one_tick: Any
) -> None:
    path = tmp_path / "a.toml"
    path.write_text("x = 1\n")
    one_tick(path)
    first = file_state(str(path))
    assert is_racy(first) and file_state(str(path)) == first
    _rewrite(path, "x = 2\n")
    assert file_state(str(path)) != first


def test_a_digested_stamp_holds_once_settled_while_the_bytes_are_the_same(
    tmp_path: Path, one_tick: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A host that read its configuration within a tick of its last write read
    # it again (and linted its stage again) once the clock had moved on.
    path = tmp_path / "a.toml"
    path.write_text("x = 1\n")
    one_tick(path)
    stamps = file_stamps([str(path)])
    assert is_racy(stamps[0][1]) and stamps_hold(stamps)
    later = os.stat(path).st_ctime_ns + SECOND
    _clock_at(monkeypatch, later)
    assert not is_racy(file_state(str(path))) and stamps_hold(stamps)
    _rewrite(path, "x = 2\n")  # the same size, times and inode shown (one tick)
    assert file_state(str(path)) == file_state(str(path))  # settled: no digest
    assert not stamps_hold(stamps)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_a_racy_fifo_is_not_read_for_its_digest(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Its reader would wait for a writer: the host hung on a configuration's name.
    fifo = tmp_path / ".usdrender-lint.toml"
    os.mkfifo(fifo)
    _clock_at(monkeypatch, fifo.stat().st_ctime_ns)
    state = file_state(str(fifo))
    assert is_racy(state) and file_state(str(fifo)) != state


def test_a_stamp_taken_a_tick_after_the_change_matches() -> None:
    info = os.stat(__file__)
    changed = max(info.st_mtime_ns, info.st_ctime_ns)
    later = changed + SECOND // 2  # read when a fine-grained clock (ns here) had ticked
    assert stat_state(info, later) == stat_state(info, later)
    assert stat_state(info, changed) != stat_state(info, changed)
    assert file_state(None) is None and file_state(str(Path(__file__).with_name("gone"))) is None


def test_whole_second_stamps_are_racy_for_two_seconds() -> None:
    # A filesystem that keeps whole seconds (HFS+, ext3) or two (FAT).
    info = types.SimpleNamespace(
        st_size=1, st_mtime_ns=7 * SECOND, st_ctime_ns=7 * SECOND, st_ino=3
    )
    assert stat_state(info, 9 * SECOND) != stat_state(info, 9 * SECOND)
    assert stat_state(info, 10 * SECOND) == stat_state(info, 10 * SECOND)


# -- the hosts ---------------------------------------------------------------------------


def test_the_validator_plugins_read_a_configuration_rewritten_within_a_tick(
    tmp_path: Path, one_tick: Any
) -> None:
    # CheckLinters: the UsdValidation and Asset Validator plugins' linter.
    (tmp_path / "shot.usda").write_text(SHOT)
    config = tmp_path / ".usdrender-lint.toml"
    config.write_text('ignore = ["SE001"]\n')
    one_tick(config)
    stage = Usd.Stage.Open(str(tmp_path / "shot.usda"))
    linters = CheckLinters()
    assert "SE001" not in {type(r).code for r in linters.linter(stage).rules}
    _rewrite(config, 'ignore = ["SE002"]\n')
    assert "SE001" in {type(r).code for r in linters.linter(stage).rules}


@pytest.mark.parametrize("dated", ["found", "extended"])
def test_a_configuration_dated_ahead_of_the_clock_is_read_once(tmp_path: Path, dated: str) -> None:
    # Its stamp stays racy until the clock catches up (a file server's clock
    # ahead of this one, an archive's times): compared by its bytes, not read
    # again on each of the validators' many calls.
    (tmp_path / "shot.usda").write_text(SHOT)
    config = tmp_path / ".usdrender-lint.toml"
    base = tmp_path / "base.toml"
    config.write_text('extend = "base.toml"\n')
    base.write_text('ignore = ["SE001"]\n')
    ahead = time.time_ns() + 3600 * SECOND
    file = config if dated == "found" else base
    os.utime(file, ns=(ahead, ahead))
    stage = Usd.Stage.Open(str(tmp_path / "shot.usda"))
    linters = CheckLinters()
    assert linters.linter(stage) is linters.linter(stage)
    assert "SE001" not in {type(r).code for r in linters.linter(stage).rules}
    base.write_text('ignore = ["SE002"]\n')
    os.utime(file, ns=(ahead, ahead))
    assert "SE001" in {type(r).code for r in linters.linter(stage).rules}


def test_the_language_server_reads_a_configuration_rewritten_within_a_tick(
    tmp_path: Path, one_tick: Any
) -> None:
    path = str(tmp_path / "shot.usda")
    config = tmp_path / ".usdrender-lint.toml"
    config.write_text('ignore = ["SE001"]\n')
    one_tick(config)
    documents = Documents()
    documents.update({path: SHOT})
    assert "SE001" not in {f.code for f in documents.lint(path).findings}
    _rewrite(config, 'ignore = ["SE002"]\n')
    assert "SE001" in {f.code for f in documents.lint(path).findings}


def test_the_language_server_reads_a_layer_rewritten_within_a_tick(
    tmp_path: Path, one_tick: Any
) -> None:
    cams = tmp_path / "cams.usda"
    cams.write_text('#usda 1.0\ndef Xform "rig"\n{\n    def Camera "cam"\n    {\n    }\n}\n')
    one_tick(cams)
    text = (
        '#usda 1.0\ndef Xform "World" (\n    references = @./cams.usda@</rig>\n)\n{\n}\n'
        'def RenderSettings "S"\n{\n    rel camera = </World/cam>\n}\n'
    )
    path = str(tmp_path / "shot.usda")
    documents = Documents()
    documents.update({path: text})
    assert "CA003" not in {f.code for f in documents.lint(path).findings}
    # The camera renamed: the relationship targets nothing.
    _rewrite(cams, '#usda 1.0\ndef Xform "rig"\n{\n    def Camera "cxm"\n    {\n    }\n}\n')
    assert "CA003" in {f.code for f in documents.lint(path).findings}


def test_the_language_server_reads_a_layer_read_within_a_tick_once_settled_no_more(
    tmp_path: Path, one_tick: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Its stamp, taken within the tick, carries its digest; the next lint,
    # once the clock moved on, forced USD to read it again (and recompose).
    cams = tmp_path / "cams.usda"
    cams.write_text('#usda 1.0\ndef Xform "rig"\n{\n    def Camera "cam"\n    {\n    }\n}\n')
    one_tick(cams)
    text = '#usda 1.0\ndef Xform "World" (\n    references = @./cams.usda@</rig>\n)\n{\n}\n'
    path = str(tmp_path / "shot.usda")
    documents = Documents()
    documents.update({path: text})
    documents.lint(path)
    forced: list[str] = []
    reload = Sdf.Layer.Reload

    def counted(layer: Sdf.Layer, force: bool = False) -> bool:
        if force:
            forced.append(layer.identifier)
        return reload(layer, force)

    monkeypatch.setattr(Sdf.Layer, "Reload", counted)
    _clock_at(monkeypatch, os.stat(cams).st_ctime_ns + SECOND)
    documents.lint(path)
    assert forced == []
    monkeypatch.setattr(config_module, "os", os)  # the file's own stamp from here on
    _rewrite(cams, '#usda 1.0\ndef Xform "rig"\n{\n    def Camera "cxm"\n    {\n    }\n}\n')
    documents.lint(path)
    assert [Path(f).name for f in forced] == ["cams.usda"]
