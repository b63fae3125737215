"""The server stays up whatever a document does to USD, answers while a long
lint runs, cancels a lint a newer edit outdates, and ends cleanly: on
shutdown and exit, and when its client's process dies."""

from __future__ import annotations

import asyncio
import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest
import pytest_lsp
from cli_support import (
    blocked_on_a_fifo,
    blocked_on_fifos,
    command,
    descendants,
    hanging_stage,
    is_running,
    signalled,
    until_usd_loads,
)
from lsp_editor import read_message
from lsprotocol import types
from pytest_lsp import ClientServerConfig, LanguageClient
from test_protocol import change, diagnostics_of, make_client, open_document, published_versions

from usdrender_lint.server.protocol import SLOW

in_server_loop = pytest.mark.asyncio(loop_scope="module")

pytestmark = pytest.mark.heavy(seconds=55)


SERVER = ClientServerConfig(
    server_command=[sys.executable, "-m", "usdrender_lint", "server"], client_factory=make_client
)


@pytest_lsp.fixture(scope="module", config=SERVER)
async def client(lsp_client: LanguageClient, tmp_path_factory: pytest.TempPathFactory):
    root = tmp_path_factory.mktemp("robust")
    await lsp_client.initialize_session(
        types.InitializeParams(
            capabilities=types.ClientCapabilities(),
            root_uri=root.as_uri(),
            initialization_options={"timeout": 2},
        )
    )
    # Ready: a first document is linted.
    await diagnostics_of(lsp_client, open_document(lsp_client, root / "a.usda", "#usda 1.0\n"), 1)
    yield
    await lsp_client.shutdown_session()


FINE = '#usda 1.0\ndef RenderSettings "S"\n{\n    uniform int2 resolution = (0, 10)\n}\n'


def hanging_document(folder: Path) -> tuple[Path, str]:
    """A document whose sublayer is a FIFO: its lint never ends by itself."""
    path = hanging_stage(folder)
    return path, path.read_text()


async def its_lint_hangs(client: LanguageClient) -> None:
    """Until the server's child waits on the FIFO (a fixed pause is too short
    on a loaded machine, and the lint's 2 s time-out must not have passed)."""
    server = client._server
    assert server is not None
    async with asyncio.timeout(60):
        while not blocked_on_a_fifo(server.pid):
            await asyncio.sleep(0.01)


@in_server_loop
async def test_a_newer_edit_cancels_the_running_lint(client: LanguageClient, tmp_path: Path):
    path, text = hanging_document(tmp_path)
    uri = open_document(client, path, text)
    await its_lint_hangs(client)
    # A newer edit cancels a quick document's lint once it has run SLOW seconds.
    await asyncio.sleep(SLOW + 0.05)
    started = time.perf_counter()
    hover = await client.text_document_hover_async(
        types.HoverParams(types.TextDocumentIdentifier(uri), types.Position(1, 5))
    )
    assert hover is None
    answered = time.perf_counter() - started
    change(client, uri, 2, FINE)
    found = await diagnostics_of(client, uri, 2)
    assert "SE001" in {d.code for d in found}
    assert any("a newer edit cancelled the lint" in m.message for m in client.log_messages)
    assert published_versions[uri] == 2  # version 1's lint never published
    assert answered < 1.0  # the protocol thread did not wait for the lint
    client.text_document_did_close(
        types.DidCloseTextDocumentParams(types.TextDocumentIdentifier(uri))
    )


@in_server_loop
async def test_a_document_that_hangs_usd_costs_that_document(
    client: LanguageClient, tmp_path: Path
):
    path, text = hanging_document(tmp_path)
    uri = open_document(client, path, text)
    found = await diagnostics_of(client, uri, 1)
    assert [d.message for d in found] == [
        "USD did not finish within 2 s (the time-out of check); the lint was stopped"
    ]
    assert found[0].severity == types.DiagnosticSeverity.Error
    client.text_document_did_close(
        types.DidCloseTextDocumentParams(types.TextDocumentIdentifier(uri))
    )
    # The next document is linted as usual.
    other = open_document(client, tmp_path / "fine.usda", FINE)
    assert "SE001" in {d.code for d in await diagnostics_of(client, other, 1)}


@in_server_loop
async def test_a_document_that_crashes_usd_costs_that_document(
    client: LanguageClient, tmp_path: Path
):
    path, text = hanging_document(tmp_path)
    uri = open_document(client, path, text)
    await its_lint_hangs(client)
    # As USD would crash on it: the child that lints it dies of a signal.
    server = client._server
    assert server is not None
    killed = descendants(server.pid)
    for pid in killed:
        os.kill(pid, signal.SIGSEGV)
    found = await diagnostics_of(client, uri, 1)
    assert [d.message for d in found] == ["USD crashed while linting this document (signal 11)"]
    # The spare child dies too, killed here as no crash would kill it: the next
    # lint could take it while it is still dying and be told that it crashed.
    deadline = time.monotonic() + 30
    while any(is_running(pid) for pid in killed) and time.monotonic() < deadline:
        await asyncio.sleep(0.05)
    change(client, uri, 2, FINE)
    assert "SE001" in {d.code for d in await diagnostics_of(client, uri, 2)}


def _frame(message: str) -> bytes:
    data = message.encode()
    return b"Content-Length: %d\r\n\r\n" % len(data) + data


INITIALIZE = '{"jsonrpc":"2.0","id":1,"method":"initialize","params":{"capabilities":{}}}'
INITIALIZED = '{"jsonrpc":"2.0","method":"initialized","params":{}}'
EXIT = '{"jsonrpc":"2.0","method":"exit"}'


def _serve(*messages: str) -> subprocess.CompletedProcess[bytes]:
    """The server run to its end over ``messages``, framed, on its standard input."""
    return subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "server"],
        input=b"".join(_frame(message) for message in messages),
        capture_output=True,
        timeout=60,
    )


def test_the_server_ends_when_its_client_dies(tmp_path: Path):
    """The client's process (initialize's processId) ends without closing the
    server's input: the server and its USD children end within a few seconds."""
    # A stand-in client process that exits at once; the server's stdin stays open.
    client = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(1)"])
    server = subprocess.Popen(
        [sys.executable, "-m", "usdrender_lint", "server"],
        stdin=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
    )
    assert server.stdin is not None
    server.stdin.write(
        _frame(
            '{"jsonrpc":"2.0","id":1,"method":"initialize","params":'
            f'{{"processId":{client.pid},"capabilities":{{}}}}}}'
        )
        + _frame('{"jsonrpc":"2.0","method":"initialized","params":{}}')
    )
    server.stdin.flush()
    time.sleep(0.5)
    children = descendants(server.pid)
    client.wait()
    assert server.wait(timeout=30) == 0
    deadline = time.time() + 10
    while any(Path(f"/proc/{pid}").exists() for pid in children) and time.time() < deadline:
        time.sleep(0.1)
    assert not any(Path(f"/proc/{pid}/status").exists() for pid in children)
    server.stdin.close()


def test_shutdown_and_exit_end_the_server_with_status_0():
    server = _serve(
        INITIALIZE,
        INITIALIZED,
        '{"jsonrpc":"2.0","id":2,"method":"shutdown"}',
        EXIT,
    )
    assert server.returncode == 0
    assert b'"id": 2' in server.stdout and b'"result": null' in server.stdout


def test_a_request_after_shutdown_is_answered_invalid_request():
    """pygls dropped it: the client waited for an answer that never came."""
    server = _serve(
        INITIALIZE,
        INITIALIZED,
        '{"jsonrpc":"2.0","id":2,"method":"shutdown"}',
        '{"jsonrpc":"2.0","id":3,"method":"textDocument/hover","params":'
        '{"textDocument":{"uri":"file:///a.usda"},"position":{"line":0,"character":0}}}',
        EXIT,
    )
    assert server.returncode == 0
    (answer,) = [m for m in _messages(server.stdout) if m.get("id") == 3]
    assert answer["error"]["code"] == -32600  # InvalidRequest


def test_a_message_whose_params_do_not_fit_is_answered_invalid_params():
    """A request whose params lack what its method needs went unanswered (a
    traceback on standard error); such a notification popped up an error."""
    server = _serve(
        INITIALIZE,
        INITIALIZED,
        '{"jsonrpc":"2.0","id":2,"method":"textDocument/codeAction","params":'
        '{"textDocument":{"uri":"file:///a.usda"}}}',
        '{"jsonrpc":"2.0","method":"textDocument/didChange","params":'
        '{"textDocument":{"uri":"file:///a.usda","version":2}}}',
        '{"jsonrpc":"2.0","id":3,"method":"shutdown"}',
        EXIT,
    )
    assert server.returncode == 0
    messages = _messages(server.stdout)
    (answer,) = [m for m in messages if m.get("id") == 2]
    assert answer["error"]["code"] == -32602  # InvalidParams
    assert "textDocument/codeAction" in answer["error"]["message"]
    assert not [m for m in messages if m.get("method") == "window/showMessage"]
    (logged,) = [m for m in messages if m.get("method") == "window/logMessage"]
    assert "textDocument/didChange" in logged["params"]["message"]
    assert b"Traceback" not in server.stderr


def test_a_message_before_initialize_is_refused_without_a_traceback():
    """A request was failed with an internal error carrying pygls's traceback,
    and a notification popped up "Error in server: The workspace is not available"."""
    server = _serve(
        '{"jsonrpc":"2.0","id":1,"method":"textDocument/hover","params":'
        '{"textDocument":{"uri":"file:///a.usda"},"position":{"line":0,"character":0}}}',
        '{"jsonrpc":"2.0","method":"textDocument/didOpen","params":{"textDocument":'
        '{"uri":"file:///a.usda","languageId":"usda","version":1,"text":"#usda 1.0"}}}',
        '{"jsonrpc":"2.0","id":2,"method":"initialize","params":{"capabilities":{}}}',
        INITIALIZED,
        '{"jsonrpc":"2.0","id":3,"method":"shutdown"}',
        EXIT,
    )
    assert server.returncode == 0
    messages = _messages(server.stdout)
    (refused,) = [m for m in messages if m.get("id") == 1]
    assert refused["error"]["code"] == -32002  # ServerNotInitialized
    assert "data" not in refused["error"]
    assert not [m for m in messages if m.get("method") == "window/showMessage"]
    assert "result" in next(m for m in messages if m.get("id") == 2)


def test_an_unreadable_message_is_one_line_in_the_log_not_an_error_popup():
    """Malformed JSON, JSON that is no message, and a change to a document the
    client never opened each popped up "Error in server: <Python's exception>"
    (window/showMessage), with a traceback on standard error."""
    hover = (
        '{"jsonrpc":"2.0","id":2,"method":"textDocument/hover","params":'
        '{"textDocument":{"uri":"file:///a.usda"},"position":{"line":0,"character":0}}}'
    )
    server = _serve(
        INITIALIZE,
        INITIALIZED,
        "{not json}",
        "[1, 2]",
        '{"jsonrpc":"2.0","method":"textDocument/didChange","params":{"textDocument":'
        '{"uri":"file:///never-opened.usda","version":2},"contentChanges":[{"text":"x"}]}}',
        hover,
        '{"jsonrpc":"2.0","id":3,"method":"shutdown"}',
        EXIT,
    )
    assert server.returncode == 0
    messages = _messages(server.stdout)
    assert not [m for m in messages if m.get("method") == "window/showMessage"]
    logged = [m["params"]["message"] for m in messages if m.get("method") == "window/logMessage"]
    assert logged == [
        "usdrender-lint: ignored a message that is not JSON: "
        "Expecting property name enclosed in double quotes: line 1 column 2 (char 1)",
        "usdrender-lint: ignored a message that is not JSON-RPC",
    ]
    assert "result" in next(m for m in messages if m.get("id") == 2)  # still serving
    assert b"Traceback" not in server.stderr
    assert all(line.startswith(b"usdrender-lint: ") for line in server.stderr.splitlines())


def _opened(path: Path, text: str) -> bytes:
    item = {"uri": path.as_uri(), "languageId": "usda", "version": 1, "text": text}
    return _frame(
        json.dumps(
            {"jsonrpc": "2.0", "method": "textDocument/didOpen", "params": {"textDocument": item}}
        )
    )


@pytest.mark.parametrize("ending", ["exit", "closed"])
def test_the_editor_leaving_during_a_lint_writes_no_traceback(tmp_path: Path, ending: str):
    """The editor said exit without shutdown, or closed the pipe (it quit or
    crashed), while a lint ran: the loop cancelled the handler that awaited it
    and CancelledError's traceback went to the editor's log."""
    server = subprocess.Popen(
        [sys.executable, "-m", "usdrender_lint", "server"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    assert server.stdin is not None and server.stdout is not None and server.stderr is not None
    server.stdin.write(
        _frame('{"jsonrpc":"2.0","id":1,"method":"initialize","params":{"capabilities":{}}}')
        + _frame('{"jsonrpc":"2.0","method":"initialized","params":{}}')
        + _opened(tmp_path / "a.usda", "#usda 1.0\n")
    )
    server.stdin.flush()
    # Ready: the first document's diagnostics are out.
    while read_message(server.stdout).get("method") != "textDocument/publishDiagnostics":
        pass
    server.stdin.write(_opened(*hanging_document(tmp_path)))
    server.stdin.flush()
    deadline = time.time() + 60  # until a USD child waits on the FIFO
    while not blocked_on_a_fifo(server.pid) and time.time() < deadline:
        time.sleep(0.1)
    if ending == "exit":
        server.stdin.write(_frame('{"jsonrpc":"2.0","method":"exit"}'))
    server.stdin.close()
    assert server.wait(timeout=60) == (1 if ending == "exit" else 0)
    assert b"Traceback" not in server.stderr.read()
    server.stdout.close()


class _Session:
    """A server with the default time-out (120 s), spoken to over raw JSON-RPC,
    its messages read on a thread."""

    def __init__(self, folder: Path) -> None:
        import queue
        import threading

        self.server = subprocess.Popen(
            [sys.executable, "-m", "usdrender_lint", "server"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
        )
        assert self.server.stdin is not None and self.server.stdout is not None
        self.stdin = self.server.stdin
        self.received: queue.Queue[dict] = queue.Queue()
        stdout = self.server.stdout

        def read() -> None:
            while True:
                try:
                    self.received.put(read_message(stdout))
                except (EOFError, ValueError, OSError):
                    return

        threading.Thread(target=read, daemon=True).start()
        self.send(INITIALIZE, INITIALIZED)
        self.open(folder / "a.usda", "#usda 1.0\n")
        self.published(folder / "a.usda")

    def send(self, *messages: str | bytes) -> None:
        for message in messages:
            self.stdin.write(message if isinstance(message, bytes) else _frame(message))
        self.stdin.flush()

    def open(self, path: Path, text: str) -> None:
        self.send(_opened(path, text))

    def published(self, path: Path, within: float = 30.0) -> None:
        """Wait for diagnostics on ``path``: fails after ``within`` seconds."""
        import queue

        deadline = time.time() + within
        while time.time() < deadline:
            try:
                message = self.received.get(timeout=max(deadline - time.time(), 0.01))
            except queue.Empty:
                break
            diagnostics = message.get("method") == "textDocument/publishDiagnostics"
            if diagnostics and message["params"]["uri"] == path.as_uri():
                return
        raise AssertionError(f"no diagnostics for {path.name} within {within:g} s")

    def hang(self, folder: Path) -> Path:
        """Open a document whose lint hangs, until USD waits on its FIFO."""
        path, text = hanging_document(folder)
        self.open(path, text)
        deadline = time.time() + 60
        while not blocked_on_a_fifo(self.server.pid) and time.time() < deadline:
            time.sleep(0.1)
        return path

    def end(self) -> None:
        self.send('{"jsonrpc":"2.0","id":2,"method":"shutdown"}', EXIT)
        self.stdin.close()
        self.server.wait(timeout=60)


def test_closing_a_document_whose_lint_hangs_stops_that_lint(tmp_path: Path):
    """Closing it left its lint running to the time-out (120 s by default),
    and every other document's lint waited behind it."""
    session = _Session(tmp_path)
    try:
        path = session.hang(tmp_path)
        closed = {"textDocument": {"uri": path.as_uri()}}
        session.send(
            json.dumps({"jsonrpc": "2.0", "method": "textDocument/didClose", "params": closed})
        )
        session.open(tmp_path / "fine.usda", FINE)
        session.published(tmp_path / "fine.usda")
    finally:
        session.end()


def test_a_document_is_linted_while_another_hangs_usd(tmp_path: Path):
    """A document open while another one's lint hangs USD (still open, its
    time-out 120 s away) is linted meanwhile, in another child: it waited for
    the time-out (measured in Neovim: 21 s with a 20 s time-out, 0.1 s now)."""
    session = _Session(tmp_path)
    try:
        session.hang(tmp_path)
        session.open(tmp_path / "fine.usda", FINE)
        session.published(tmp_path / "fine.usda", within=30.0)
        # And again, as the spare that served it is replaced meanwhile.
        session.open(tmp_path / "fine2.usda", FINE)
        session.published(tmp_path / "fine2.usda", within=30.0)
    finally:
        session.end()


def test_a_document_is_linted_while_two_others_hang_usd(tmp_path: Path):
    """Two documents whose lints hang USD held both children the server had,
    and every other document's lint waited for their time-out (120 s)."""
    session = _Session(tmp_path)
    try:
        for name in ("one", "two"):
            folder = tmp_path / name
            folder.mkdir()
            session.open(*hanging_document(folder))
        deadline = time.time() + 60  # until both children wait on their FIFO
        while blocked_on_fifos(session.server.pid) < 2 and time.time() < deadline:
            time.sleep(0.1)
        assert blocked_on_fifos(session.server.pid) == 2
        session.open(tmp_path / "fine.usda", FINE)
        session.published(tmp_path / "fine.usda", within=30.0)
    finally:
        session.end()


def test_a_newer_lint_of_a_document_gives_up_its_hung_lint_before_it_starts(tmp_path: Path):
    """A lint asked for before the document's running lint turned out to hang
    (a save or an edit right after opening it) took another child: the document
    held two until the time-out, and two such documents held every child."""
    import threading

    from usdrender_lint.server import worker

    path = str(hanging_stage(tmp_path))
    linting = worker.Linting()
    outcome: dict[int, object] = {}

    def lint(version: int) -> None:
        try:
            outcome[version] = linting.call("lint", path, version, (path,), {}, 60.0)
        except worker.LintFailed as failed:
            outcome[version] = failed

    threads = [threading.Thread(target=lint, args=(version,)) for version in (1, 2)]
    try:
        linting.start()
        threads[0].start()
        deadline = time.time() + 60  # until its child waits on the FIFO
        while not blocked_on_a_fifo(os.getpid()) and time.time() < deadline:
            time.sleep(0.05)
        threads[1].start()  # asked for by the protocol, with no cancel of its own
        threads[0].join(10)
        given_up = outcome.get(1)
        assert isinstance(given_up, worker.LintFailed) and given_up.cancelled, given_up
        deadline = time.time() + 60  # the newer lint hangs in its turn, alone
        while not blocked_on_a_fifo(os.getpid()) and time.time() < deadline:
            time.sleep(0.05)
        assert blocked_on_fifos(os.getpid()) == 1
    finally:
        linting.close()
        for thread in threads:
            if thread.ident is not None:  # started
                thread.join(60)


def _messages(stdout: bytes) -> list[dict]:
    """The JSON-RPC messages of the server's output."""
    import json

    found = []
    while stdout:
        head, _, rest = stdout.partition(b"\r\n\r\n")
        length = int(head.split(b"Content-Length:")[1].split(b"\r\n")[0])
        found.append(json.loads(rest[:length]))
        stdout = rest[length:]
    return found


def test_exit_without_shutdown_ends_the_server_with_status_1():
    """The protocol's rule; pygls swallowed the status and the server said 0."""
    server = _serve(
        INITIALIZE,
        INITIALIZED,
        EXIT,
    )
    assert server.returncode == 1


def test_the_editor_s_timeout_reads_as_check_s() -> None:
    from usdrender_lint.server.protocol import editor_timeout

    assert editor_timeout({"timeout": 0}, 120.0) is None  # no limit, as --timeout 0
    assert editor_timeout({"timeout": 30}, 120.0) == 30.0
    for ignored in ({}, {"timeout": -1}, {"timeout": "5"}, {"timeout": True}):
        assert editor_timeout(ignored, 120.0) == 120.0


def test_a_child_that_cannot_start_says_why_on_every_call(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A rule plugin that fails to load: the editor's diagnostic said "USD crashed
    # while linting this document (exit status 0)" after the first message.
    from usdrender_lint.server.worker import Child, LintFailed

    site = tmp_path / "site"
    site.mkdir()
    (site / "broken_rules.py").write_text("import not_a_module_anywhere\n")
    info = site / "broken-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: broken\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text("[usdrender_lint.rules]\nbroken = broken_rules:RULES\n")
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(site), os.environ.get("PYTHONPATH", "")]))
    child = Child()
    try:
        for _ in range(2):
            with pytest.raises(
                LintFailed, match="cannot start: RegistryError: rule plugin 'broken'"
            ):
                child.call("lint", (str(tmp_path / "a.usda"),), {}, 60)
    finally:
        child.close()


def test_a_cancel_that_lands_as_a_lint_answers_never_fails_the_next_lint(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Closing a document as its lint answered killed that child after its
    answer came in; the kill not yet taken (a loaded machine), the child went to
    the next call, which failed as "cancelled", so the next document's
    diagnostics never came (seen once in CI)."""
    from usdrender_lint.server import worker

    first, second = tmp_path / "first.usda", tmp_path / "second.usda"
    for path in (first, second):
        path.write_text(FINE)
    linting = worker.Linting()
    killed: list[worker.Child] = []
    real_call = worker.Child.call

    def answered_then_cancelled(child, method, args, texts, timeout):
        answer = real_call(child, method, args, texts, timeout)
        if args == (str(first),) and not killed:
            linting.cancel(str(first), 2)  # the editor closes the document
            killed.append(child)
        return answer

    monkeypatch.setattr(worker.Child, "call", answered_then_cancelled)
    # The kill has not taken when the next call looks for a child.
    monkeypatch.setattr(
        worker.Child, "alive", property(lambda c: c in killed or c.process.poll() is None)
    )
    try:
        linting.start()
        linting.call("lint", str(first), 1, (str(first),), {}, 60.0)
        linted = linting.call("lint", str(second), 3, (str(second),), {}, 60.0)
        assert killed and linted.error is None
        assert "SE001" in {f.code for f in linted.findings}  # resolution (0, 10)
    finally:
        linting.close()


def _signal_a_server_on_a_terminal(signum: int, wait: Callable[[int], None]) -> tuple[int, str]:
    """:func:`signalled` for the server reading a terminal, as when run by hand."""
    import pty

    leader, follower = pty.openpty()
    try:
        return signalled(command("server"), signum, wait, stdin=follower)
    finally:
        os.close(leader)
        os.close(follower)


@pytest.mark.parametrize(
    ("signum", "status", "said"),
    [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")],
)
def test_ctrl_c_or_sigterm_ends_the_server_at_once(signum: int, status: int, said: str) -> None:
    """Run by hand in a terminal, the server waits on it: Ctrl-C (the signal to
    the terminal's process group) ends it with the command's line and status; it
    hung before, deaf to any signal but SIGKILL."""
    # Started, reading the terminal.
    status_and_said = _signal_a_server_on_a_terminal(signum, lambda pid: time.sleep(3.0))
    assert status_and_said == (status, f"usdrender-lint: {said}\n")


@pytest.mark.skipif(not Path("/proc/self/maps").exists(), reason="reads /proc/PID/maps")
def test_sigterm_while_the_server_imports_usd_ends_it() -> None:
    """A signal that lands while the server imports USD (its start on a slow
    machine): the exception the handler raised was swallowed by USD's C++ and
    the signals that followed ignored, so the server read the terminal forever
    (after USD's own lines about the module it failed to set up)."""
    status_and_said = _signal_a_server_on_a_terminal(signal.SIGTERM, until_usd_loads)
    assert status_and_said == (143, "usdrender-lint: terminated\n")


def test_a_signal_lost_in_the_import_stops_the_server_before_it_serves(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The same, made certain: the signal came (the handler's record of it) and
    its exception is gone; the server raises it again instead of serving."""
    from usdrender_lint import server
    from usdrender_lint.running import interrupts
    from usdrender_lint.server import protocol

    served: list[str] = []
    monkeypatch.setattr(interrupts, "_received", signal.SIGTERM)
    monkeypatch.setattr(protocol, "serve", lambda: served.append("serve"))
    monkeypatch.setattr(server, "_end_on_signals", lambda: served.append("handlers"))
    with pytest.raises(interrupts.Stopped) as stopped:
        server.main()
    assert stopped.value.exit_status == 143
    assert served == []
