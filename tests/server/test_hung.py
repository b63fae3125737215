"""Documents whose lint hangs USD (a FIFO on a sublayer path): what the
editor asks about them is answered in bounded time, and the other documents
are linted meanwhile, over the real protocol (raw JSON-RPC); and the race of
giving up a call as it answers, placed deterministically."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
from cli_support import HANGS as HANGS_ALONE
from cli_support import blocked_on_a_fifo, blocked_on_fifos
from lsp_editor import Editor, until

from usdrender_lint.server.protocol import FIX_ALL

pytestmark = pytest.mark.heavy(seconds=30)

FINE = '#usda 1.0\ndef RenderSettings "S"\n{\n    uniform int2 resolution = (0, 10)\n}\n'
#: FINE with a sublayer that blocks USD forever (cli_support.HANGING_SUBLAYER).
HANGS = f'{HANGS_ALONE}def RenderSettings "S"\n{{\n}}\n'


def diagnostics(editor: Editor, uri: str) -> list[dict]:
    with editor.lock:
        return list(editor.published.get(uri, (None, []))[1])


def hanging_folder(folder: Path) -> Path:
    import os

    folder.mkdir(parents=True, exist_ok=True)
    os.mkfifo(folder / "pipe.usda")
    return folder


def code_action(editor: Editor, uri: str, diagnostic: dict) -> tuple[dict, float]:
    """The answer to a light bulb's codeAction on ``diagnostic``, and its seconds."""
    started = time.monotonic()
    answer = editor.request(
        "textDocument/codeAction",
        {
            "textDocument": {"uri": uri},
            "range": diagnostic["range"],
            "context": {"diagnostics": [diagnostic]},
        },
    )
    return answer, time.monotonic() - started


def test_a_code_action_on_a_document_that_hangs_usd_is_answered_at_once(tmp_path: Path):
    """An edit adds a sublayer USD hangs on; the editor still shows the older
    text's finding and asks for its quick fix. The fix composed the stage, so
    the answer came only at the lint's time-out (15 s here, 120 s by default),
    its child held meanwhile; and again for every later request, each holding
    one more child."""
    folder = hanging_folder(tmp_path / "shot")
    editor = Editor(tmp_path / "server.log", options={"timeout": 15})
    try:
        uri = editor.open(folder / "shot.usda", FINE)
        assert until(lambda: any(d["code"] == "ST003" for d in diagnostics(editor, uri)), 60)
        (st003,) = [d for d in diagnostics(editor, uri) if d["code"] == "ST003"]
        editor.change(uri, 2, HANGS)
        assert until(lambda: blocked_on_a_fifo(editor.server.pid), 60)
        answer, seconds = code_action(editor, uri, st003)
        assert "error" not in answer and answer["result"] == []
        assert seconds < 10, seconds  # not the 15 s time-out
        # Fix-all offered without its edit, chosen: codeAction/resolve makes it.
        started = time.monotonic()
        fix_all = {"title": "fix all", "kind": FIX_ALL, "data": {"uri": uri, "version": 2}}
        answer = editor.request("codeAction/resolve", fix_all)
        assert "error" not in answer and "edit" not in answer["result"]
        assert time.monotonic() - started < 10
        # The editor asks again and again (VS Code, as the cursor moves): each
        # request held one more child, until every child was held and another
        # document's lint waited for the time-out.
        asked = [
            editor.ask(
                "textDocument/codeAction",
                {
                    "textDocument": {"uri": uri},
                    "range": st003["range"],
                    "context": {"diagnostics": [st003]},
                },
            )
            for _ in range(4)
        ]
        other = editor.open(tmp_path / "other.usda", FINE)
        assert until(lambda: editor.messages(other)[0] == 1, 8)
        answers = [editor.answers.get(timeout=60) for _ in asked]  # in any order
        assert sorted(a["id"] for a in answers) == asked
        assert all(a["result"] == [] for a in answers)
        # Its lint timed out: a fix would hang as long, and is not tried.
        assert until(lambda: editor.messages(uri)[0] == 2, 60)
        assert any("did not finish" in m for m in editor.messages(uri)[1])
        answer, seconds = code_action(editor, uri, st003)
        assert "error" not in answer and answer["result"] == []
        assert seconds < 10, seconds  # not the 15 s time-out
        # The document's text mended, its fix is offered again.
        editor.change(uri, 3, FINE)
        assert until(lambda: editor.messages(uri)[0] == 3, 60)
        (st003,) = [d for d in diagnostics(editor, uri) if d["code"] == "ST003"]
        answer, seconds = code_action(editor, uri, st003)
        assert [a["title"] for a in answer["result"]][:1] == [
            'Fix ST003: author renderSettingsPrimPath = "/S" in the root layer'
        ]
    finally:
        editor.end()


def test_a_document_is_linted_while_four_others_hang_usd(tmp_path: Path):
    """Four broken shots open, each hanging USD, held all four children, and a
    healthy shot's lint waited for their time-out (120 s by default): now the
    call held longest is given up for it, and that shot says so."""
    editor = Editor(tmp_path / "server.log")
    try:
        hung = [
            editor.open(hanging_folder(tmp_path / name) / "shot.usda", HANGS)
            for name in ("one", "two", "three", "four")
        ]
        assert until(lambda: blocked_on_fifos(editor.server.pid) == 4, 60)
        fine = editor.open(tmp_path / "fine.usda", FINE)
        assert until(lambda: editor.messages(fine)[0] == 1, 30)
        assert any("resolution (0, 10)" in m for m in editor.messages(fine)[1])
        given_up = [uri for uri in hung if editor.messages(uri)[0] == 1]
        assert len(given_up) == 1  # one, for the one lint that waited
        (said,) = editor.messages(given_up[0])[1]
        assert said.startswith("USD had not finished after ")
        assert "edit or save the document to lint it again" in said
        assert blocked_on_fifos(editor.server.pid) == 3
        # A second healthy document is linted in the first one's child.
        again = editor.open(tmp_path / "again.usda", FINE)
        assert until(lambda: editor.messages(again)[0] == 1, 10)
        assert blocked_on_fifos(editor.server.pid) == 3
    finally:
        editor.end()


def test_a_give_up_that_lands_as_the_call_answers_never_fails_the_next_lint(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A call given up for another's as its answer came in: its child, killed
    all the same (the kill not yet taken), must not serve the next call, which
    would fail with the given-up call's reason."""
    from usdrender_lint.server import worker

    first, second = tmp_path / "first.usda", tmp_path / "second.usda"
    for path in (first, second):
        path.write_text(FINE)
    linting = worker.Linting()
    given_up: list[worker.Child] = []
    real_call = worker.Child.call

    def answered_then_given_up(child, method, args, texts, timeout):  # noqa: ANN001, ANN202
        answer = real_call(child, method, args, texts, timeout)
        if args == (str(first),) and not given_up:
            child.given_up = "given up for another document"  # as _give_up_stuck does
            child.kill()
            given_up.append(child)
        return answer

    monkeypatch.setattr(worker.Child, "call", answered_then_given_up)
    monkeypatch.setattr(
        worker.Child, "alive", property(lambda c: c in given_up or c.process.poll() is None)
    )
    try:
        linting.start()
        linting.call("lint", str(first), 1, (str(first),), {}, 60.0)
        linted = linting.call("lint", str(second), 2, (str(second),), {}, 60.0)
        assert given_up and linted.error is None
        assert "SE001" in {f.code for f in linted.findings}
    finally:
        linting.close()
