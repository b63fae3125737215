"""Documents whose lint hangs USD (a FIFO on a sublayer path): what the
editor asks about them is answered in bounded time, and the other documents
are linted meanwhile, over the real protocol (raw JSON-RPC)."""

from __future__ import annotations

import time
from pathlib import Path

from cli_support import blocked_on_a_fifo
from lsp_editor import Editor

from usdrender_lint.server.protocol import FIX_ALL

FINE = '#usda 1.0\ndef RenderSettings "S"\n{\n    uniform int2 resolution = (0, 10)\n}\n'
#: FINE with a sublayer that is a FIFO: USD blocks reading it forever.
HANGS = '#usda 1.0\n(\n    subLayers = [@./pipe.usda@]\n)\ndef RenderSettings "S"\n{\n}\n'


def until(condition, within: float) -> bool:  # noqa: ANN001 - a predicate
    deadline = time.monotonic() + within
    while not condition():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.05)
    return True


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
    the answer came only at the lint's time-out (30 s here, 120 s by default),
    its child held meanwhile; and again for every later request, each holding
    one more child."""
    folder = hanging_folder(tmp_path / "shot")
    editor = Editor(tmp_path / "server.log", options={"timeout": 30})
    try:
        uri = editor.open(folder / "shot.usda", FINE)
        assert until(lambda: any(d["code"] == "ST003" for d in diagnostics(editor, uri)), 60)
        (st003,) = [d for d in diagnostics(editor, uri) if d["code"] == "ST003"]
        editor.change(uri, 2, HANGS)
        assert until(lambda: blocked_on_a_fifo(editor.server.pid), 60)
        answer, seconds = code_action(editor, uri, st003)
        assert "error" not in answer and answer["result"] == []
        assert seconds < 10, seconds
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
        assert seconds < 1, seconds
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
