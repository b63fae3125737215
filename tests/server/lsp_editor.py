"""An editor's side of a language server session over raw JSON-RPC (the
server's standard input and output), for tests that drive a real server hard
or through a patched one: what it sent, and what the server last published."""

from __future__ import annotations

import json
import queue
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any


def until(condition, within: float = 30.0) -> bool:  # noqa: ANN001 - a predicate
    """Whether ``condition()`` held within ``within`` seconds (polled every 50 ms)."""
    deadline = time.monotonic() + within
    while not condition():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.05)
    return True


def _frame(message: dict[str, Any]) -> bytes:
    data = json.dumps(message).encode()
    return b"Content-Length: %d\r\n\r\n" % len(data) + data


def read_message(stream) -> dict:  # noqa: ANN001 - the server's standard output
    """The next message; EOFError once the server closed its output. (A loop
    that took the end for a blank line spun a reader thread on one core for the
    rest of the test worker's life, slowing every later test.)"""
    length = 0
    while True:
        raw = stream.readline()
        if not raw:
            raise EOFError("the server closed its output")
        line = raw.strip()
        if line.startswith(b"Content-Length:"):
            length = int(line.split(b":")[1])
        elif not line and length:
            return json.loads(stream.read(length))


class Editor:
    """An editor's side of a session: what it sent, and the diagnostics the
    server last published on each URI (read on a thread)."""

    def __init__(
        self,
        log: Path,
        command: tuple[str, ...] = ("-m", "usdrender_lint", "server"),
        options: dict[str, Any] | None = None,
    ):
        self.log = log.open("wb")
        self.server = subprocess.Popen(
            [sys.executable, "-X", "faulthandler", *command],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=self.log,
        )
        assert self.server.stdin is not None and self.server.stdout is not None
        self.lock = threading.Lock()
        #: The last publication on each URI: (its version, its diagnostics).
        self.published: dict[str, tuple[int | None, list[dict]]] = {}
        #: How many publications each URI had.
        self.publications: dict[str, int] = {}
        self.answers: queue.Queue[dict] = queue.Queue()
        stdout = self.server.stdout

        def read() -> None:
            while True:
                try:
                    message = read_message(stdout)
                except (EOFError, ValueError, OSError):
                    return
                if message.get("method") == "textDocument/publishDiagnostics":
                    params = message["params"]
                    with self.lock:
                        self.published[params["uri"]] = (
                            params.get("version"),
                            params["diagnostics"],
                        )
                        self.publications[params["uri"]] = (
                            self.publications.get(params["uri"], 0) + 1
                        )
                elif "id" in message and "method" not in message:
                    self.answers.put(message)

        threading.Thread(target=read, daemon=True).start()
        self.ids = 1
        initialize: dict[str, Any] = {"capabilities": {}}
        if options is not None:
            initialize["initializationOptions"] = options
        self.request("initialize", initialize)
        self.notify("initialized", {})

    def send(self, message: dict[str, Any]) -> None:
        assert self.server.stdin is not None
        self.server.stdin.write(_frame({"jsonrpc": "2.0", **message}))
        self.server.stdin.flush()

    def notify(self, method: str, params: dict[str, Any]) -> None:
        self.send({"method": method, "params": params})

    def request(self, method: str, params: dict[str, Any] | None) -> dict:
        return self.answer(self.ask(method, params))

    def ask(self, method: str, params: dict[str, Any] | None) -> int:
        """Send a request, not waiting for its answer (see :meth:`answer`)."""
        self.ids += 1
        self.send({"id": self.ids, "method": method, "params": params})
        return self.ids

    def answer(self, id_: int) -> dict:
        answer = self.answers.get(timeout=60)
        assert answer["id"] == id_, answer
        return answer

    def open(self, path: Path, text: str) -> str:
        item = {"uri": path.as_uri(), "languageId": "usda", "version": 1, "text": text}
        self.notify("textDocument/didOpen", {"textDocument": item})
        return path.as_uri()

    def change(self, uri: str, version: int, text: str) -> None:
        self.notify(
            "textDocument/didChange",
            {
                "textDocument": {"uri": uri, "version": version},
                "contentChanges": [{"text": text}],
            },
        )

    def close(self, uri: str) -> None:
        self.notify("textDocument/didClose", {"textDocument": {"uri": uri}})

    def messages(self, uri: str) -> tuple[int | None, set[str]]:
        """The version and the messages of the last diagnostics on ``uri``."""
        with self.lock:
            version, diagnostics = self.published.get(uri, (None, []))
            return version, {d["message"] for d in diagnostics}

    def count(self, uri: str) -> int:
        with self.lock:
            return self.publications.get(uri, 0)

    def end(self) -> None:
        try:
            self.request("shutdown", None)
            self.notify("exit", {})
            assert self.server.stdin is not None
            self.server.stdin.close()
            try:
                self.server.wait(timeout=60)
            except subprocess.TimeoutExpired:
                self.server.send_signal(signal.SIGABRT)
                self.server.wait()
                raise
        finally:
            if self.server.poll() is None:
                self.server.kill()
                self.server.wait()
