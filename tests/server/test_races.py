"""Races in the language server, each placed deterministically: a message of
the editor that lands while a lint starts, runs or answers. Unplaced, each
showed now and then (the stress test of test_stress.py found them): a
document left with an older text's diagnostics, or none."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from lsp_editor import Editor, until

from usdrender_lint.server.protocol import FIX_ALL

pytestmark = pytest.mark.heavy(seconds=31)

BROKEN_SHOT = Path(__file__).resolve().parents[2] / "examples" / "broken_shot" / "shot.usda"
FINE = '#usda 1.0\ndef RenderSettings "S"\n{\n    uniform int2 resolution = (0, 10)\n}\n'


def test_a_settings_change_as_the_server_starts_does_not_stop_its_linting(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Neovim sends the editor's settings right after initialized: a new
    ``configuration`` in them ended the child the server was starting, the
    start failed as "cancelled", and the server never linted a document."""
    from usdrender_lint.server import worker

    path = tmp_path / "shot.usda"
    path.write_text(FINE)
    linting = worker.Linting()
    real_ready = worker.Child.ready
    changed: list[worker.Child] = []

    def settings_come_in(child: worker.Child, timeout: float = worker.START_TIMEOUT):
        if not changed:
            changed.append(child)
            linting.reconfigure({"ignore": ["SE015"]})  # didChangeConfiguration
        return real_ready(child, timeout)

    monkeypatch.setattr(worker.Child, "ready", settings_come_in)
    try:
        assert "SE001" in {rule.code for rule in linting.start()}
        linted = linting.call("lint", str(path), 1, (str(path),), {}, 60.0)
        codes = {f.code for f in linted.findings}
        assert changed and "SE001" in codes and "SE015" not in codes
    finally:
        linting.close()


#: The server, its calls on a document held where the test says: a file
#: ``hold-NAME`` in the control folder holds the next lint of the document NAME
#: (``hold-METHOD-NAME``: the next call of that method, ``fixes`` say), its texts
#: taken, before it reaches USD; it says ``held``, and lets it go on ``go``.
HELD_SERVER = """
import os, sys, time
from usdrender_lint.server import protocol, worker
control = sys.argv[1]
real = worker.Linting.call
def call(self, method, path, version, args, texts, timeout):
    name = os.path.basename(path)
    hold = os.path.join(control, "hold-" + (name if method == "lint" else method + "-" + name))
    if os.path.exists(hold):
        os.remove(hold)
        open(os.path.join(control, "held"), "w").close()
        while not os.path.exists(os.path.join(control, "go")):
            time.sleep(0.01)
    return real(self, method, path, version, args, texts, timeout)
worker.Linting.call = call
protocol.serve()
"""


def layer(name: str, resolution: str, *, sublayers: tuple[str, ...] = (), note: str = "") -> str:
    head = "#usda 1.0\n"
    if sublayers:
        head += "(\n    subLayers = [{}]\n)\n".format(", ".join(f"@./{s}@" for s in sublayers))
    return (
        f'{head}# {note}\ndef RenderSettings "{name}"\n{{\n'
        f"    uniform int2 resolution = {resolution}\n}}\n"
    )


def wrong(resolution: str) -> str:
    """SE001's message."""
    return (
        f"resolution {resolution} has a component <= 0; "
        "author a positive pixel size such as (1920, 1080)"
    )


def _shows_only(editor: Editor, uri: str, resolution: str, older: str) -> bool:
    """Whether ``uri`` comes to show SE001 of ``resolution`` and not of ``older``
    (within 10 s: the lints are of a few lines)."""
    now = {wrong(resolution)}
    if until(lambda: editor.messages(uri)[1] & {wrong(older), *now} == now, 10.0):
        return True
    shown = sorted(m for m in editor.messages(uri)[1] if "resolution" in m)
    raise AssertionError(f"{uri} shows {shown}")


@pytest.fixture
def held(tmp_path: Path) -> Iterator[tuple[Editor, Path, Path]]:
    """A server whose lints the test holds, its control folder and its documents' folder."""
    control, folder = tmp_path / "control", tmp_path / "documents"
    control.mkdir()
    folder.mkdir()
    editor = Editor(tmp_path / "server.log", ("-c", HELD_SERVER, str(control)))
    try:
        yield editor, control, folder
    finally:
        editor.end()


def _hold(control: Path, name: str) -> None:
    (control / f"hold-{name}").touch()


def _open_in_turn(editor: Editor, *documents: tuple[Path, str]) -> list[str]:
    """Open each document once the one before it is shown. A lint lints again
    the open documents that name its file among those open as it started: so
    each document here is linted once, and no lint is still to come when the
    test holds the next one (opened together, a lint the opening had set off
    could be the one held, and the lint the test meant ran unheld)."""
    uris = []
    for path, text in documents:
        uri = editor.open(path, text)
        assert until(lambda uri=uri: editor.count(uri))
        uris.append(uri)
    return uris


def _go(control: Path) -> None:
    assert until(lambda: (control / "held").exists())
    (control / "go").touch()


def test_a_layer_edited_while_a_shot_s_lint_runs_is_not_shown_as_before(held) -> None:
    """A shot's lint took the texts, and its stage came to compose a layer that
    was then edited (the layer's lint did not lint the shot again: its last
    lint had not composed that layer): the shot's findings of the layer's older
    text stayed shown on the layer, beside its newer ones, until the next edit."""
    editor, control, folder = held
    shot, middle, leaf = (folder / n for n in ("shot.usda", "middle.usda", "leaf.usda"))
    leaf_uri, middle_uri, shot_uri = _open_in_turn(
        editor,
        (leaf, layer("L", "(0, 480)")),
        (middle, layer("M", "(1920, 1080)")),
        (shot, layer("S", "(1920, 1080)", sublayers=("middle.usda",))),
    )
    assert until(lambda: editor.count(middle_uri) >= 2)  # the shot's lint shows on it too
    _hold(control, "shot.usda")
    # The middle layer comes to sublayer the leaf: its lint lints the shot again (held).
    editor.change(middle_uri, 2, layer("M", "(1920, 1080)", sublayers=("leaf.usda",)))
    assert until(lambda: (control / "held").exists())
    editor.change(leaf_uri, 2, layer("L", "(640, 0)"))
    assert until(lambda: editor.messages(leaf_uri)[0] == 2)
    shown = editor.count(shot_uri)
    _go(control)
    assert until(lambda: editor.count(shot_uri) > shown)
    assert _shows_only(editor, leaf_uri, "(640, 0)", "(0, 480)")


def test_an_edit_whose_lint_a_close_outdates_still_relints_the_shot(held) -> None:
    """A layer's edit lints the documents that compose it once its lint is
    shown; closing another document it names asked for a newer lint of the
    layer first, which did not, and the shot's findings of the layer's older
    text stayed shown on it."""
    editor, control, folder = held
    shot, middle, other = (folder / n for n in ("shot.usda", "middle.usda", "other.usda"))
    other_uri, middle_uri, shot_uri = _open_in_turn(
        editor,
        (other, layer("O", "(1920, 1080)")),
        (middle, layer("M", "(0, 480)", note="see other.usda")),
        (shot, layer("S", "(1920, 1080)", sublayers=("middle.usda",))),
    )
    assert until(lambda: editor.count(middle_uri) >= 2)  # the shot's lint shows on it too
    _hold(control, "middle.usda")
    editor.change(middle_uri, 2, layer("M", "(640, 0)", note="see other.usda"))
    assert until(lambda: (control / "held").exists())
    # The middle layer names it: its lint is asked for again.
    editor.close(other_uri)
    assert until(lambda: editor.messages(middle_uri)[0] == 2)
    _go(control)
    assert _shows_only(editor, middle_uri, "(640, 0)", "(0, 480)")


def test_a_fix_all_resolved_as_the_text_changes_brings_no_edit_of_the_older_text(held) -> None:
    """A fix-all offered without its edit (a light bulb) is resolved when it is
    chosen: an edit that came in while its fixes were made left it the older
    text's edit, which the editor applied to the newer text (lines off by the
    lines typed meanwhile)."""
    editor, control, folder = held
    shot = folder / "shot.usda"
    text = BROKEN_SHOT.read_text()
    uri = editor.open(shot, text)
    assert until(lambda: editor.count(uri))
    _hold(control, "fixes-shot.usda")
    fix_all = {"title": "fix all", "kind": FIX_ALL, "data": {"uri": uri, "version": 1}}
    asked = editor.ask("codeAction/resolve", fix_all)
    assert until(lambda: (control / "held").exists())
    editor.change(uri, 2, "#usda 1.0\n# typed meanwhile\n" + text.split("\n", 1)[1])
    (control / "go").touch()
    assert editor.answer(asked)["result"].get("edit") is None  # the client asks again


def test_a_lint_waiting_for_the_child_is_skipped_once_a_newer_one_is_asked_for(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Edits typed while another lint held the child queued a lint each, and
    every text was linted in turn before the newest was shown (the editors
    guide says only the newest is linted)."""
    from usdrender_lint.server import worker
    from usdrender_lint.server.protocol import SLOW

    busy, typed = tmp_path / "busy.usda", tmp_path / "typed.usda"
    for path in (busy, typed):
        path.write_text(FINE)
    monkeypatch.setattr(worker, "BUSY_LIMIT", 60.0)  # no second child meanwhile
    linting = worker.Linting()
    holding, release = threading.Event(), threading.Event()
    real_call = worker.Child.call

    def held(child, method, args, texts, timeout):
        if args == (str(busy),):
            holding.set()
            release.wait(60)
        return real_call(child, method, args, texts, timeout)

    monkeypatch.setattr(worker.Child, "call", held)
    outcome: dict[int, object] = {}

    def lint(path: Path, version: int) -> None:
        try:
            outcome[version] = linting.call("lint", str(path), version, (str(path),), {}, 60.0)
        except worker.LintFailed as failed:
            outcome[version] = failed

    try:
        linting.start()
        threads = [threading.Thread(target=lint, args=(busy, 1))]
        threads[0].start()
        assert holding.wait(60)
        threads.append(threading.Thread(target=lint, args=(typed, 2)))  # waits for the child
        threads[1].start()
        time.sleep(0.2)
        linting.cancel(str(typed), 3, running_for=SLOW)  # the next keystroke's lint
        release.set()
        for thread in threads:
            thread.join(60)
        skipped = outcome[2]
        assert isinstance(skipped, worker.LintFailed) and skipped.cancelled, skipped
        lint(typed, 3)
        assert "SE001" in {f.code for f in outcome[3].findings}  # type: ignore[attr-defined]
    finally:
        release.set()
        linting.close()


def test_a_settings_change_never_leaves_a_lint_waiting_on_an_ended_child(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A settings change (or shutdown) closed the socket of a child a lint was
    waiting on; a new child's socket took its number before the wait saw the
    child die, and the wait went on for the new socket: the lint's thread hung
    for the start time-out (120 s), and the server took as long to exit (seen
    in the stress test, the server's exit timed out)."""
    import socket

    from usdrender_lint.server import worker

    path = str(tmp_path / "shot.usda")
    # Children that take a while to start: the lint waits on its child.
    monkeypatch.setattr(worker, "_CHILD", "import time; time.sleep(60)")
    real_close = worker.Child.close
    sockets: list[socket.socket] = []

    def close_as_a_new_child_starts(child: worker.Child) -> None:
        child.connection.close()
        sockets.extend(socket.socketpair())  # _fill's next child takes the number
        real_close(child)

    monkeypatch.setattr(worker.Child, "close", close_as_a_new_child_starts)
    linting = worker.Linting()
    outcome: list[worker.LintFailed] = []

    def lint() -> None:
        try:
            linting.call("lint", path, 1, (path,), {}, 60.0)
        except worker.LintFailed as failed:
            outcome.append(failed)

    waiting = threading.Thread(target=lint, daemon=True)
    try:
        waiting.start()
        time.sleep(0.5)  # it waits for its child to start
        linting.reconfigure({"ignore": ["SE015"]})
        waiting.join(10)
        assert not waiting.is_alive(), "the lint still waits on an ended child"
        assert outcome and outcome[0].cancelled
    finally:
        linting.close()
        for each in sockets:
            each.close()


def test_a_lint_asked_for_while_a_fix_is_made_does_not_stop_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A save, or another document's lint that lints this one again, asks
    for a lint with the text unchanged: it stopped the code action's call
    making the document's fixes, and the editor was offered none."""
    from usdrender_lint.server import worker

    path = tmp_path / "shot.usda"
    path.write_text(FINE)
    texts = {str(path): FINE}
    linting = worker.Linting()
    making, go = threading.Event(), threading.Event()
    real_call = worker.Child.call

    def held(child, method, args, texts, timeout):
        if method == "fixes":
            making.set()
            go.wait(60)
        return real_call(child, method, args, texts, timeout)

    monkeypatch.setattr(worker.Child, "call", held)
    outcome: list[object] = []

    def fixes() -> None:
        try:
            outcome.append(linting.call("fixes", str(path), 1, (str(path), None, False), texts, 60))
        except worker.LintFailed as failed:
            outcome.append(failed)

    thread = threading.Thread(target=fixes)
    try:
        linting.start()
        thread.start()
        assert making.wait(60)
        linting.cancel(str(path), 2)  # the save's lint
        go.set()
        thread.join(60)
        assert outcome and not isinstance(outcome[0], worker.LintFailed), outcome
    finally:
        go.set()
        linting.close()
