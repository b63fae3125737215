"""The process that runs USD for the language server, and the server's handle on it.

USD runs in a child process so that a document that crashes it (a corrupt
crate behind a reference) or hangs it (a FIFO on a sublayer path) costs that
document's lint, never the server: the server kills a child that runs past its
time limit, reports the crash or the time-out as one diagnostic on that
document, and the next lint starts in a new child. The child keeps USD, the
rules and the documents' layers loaded between lints (that is what makes a
re-lint after a keystroke fast), and a spare child is started beside it, so
that cancelling a long lint (killing its child, when a newer edit makes it
pointless) costs no start-up.

The child runs :func:`main` with FD: FD is its end of a
socket pair, over which ``multiprocessing.connection`` carries pickled calls
of :class:`~.documents.Documents` methods and their answers. Its standard
output goes to standard error (the server's standard output is the protocol).
"""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time
from multiprocessing.connection import Connection
from typing import Any

from ..records import record

_CHILD = "from usdrender_lint.server.worker import main; main()"
#: Seconds the child may take to start (import USD and the rules).
START_TIMEOUT = 120.0


class LintFailed(Exception):
    """The child could not answer: it crashed, ran past its time limit or was
    cancelled. ``reason`` is one line for the document's diagnostic."""

    def __init__(self, reason: str, *, cancelled: bool = False) -> None:
        super().__init__(reason)
        self.reason = reason
        self.cancelled = cancelled


@record(frozen=True)
class RuleDoc:
    """A registered rule's documentation, for hover (the server imports no USD)."""

    code: str
    name: str
    aliases: tuple[str, ...]
    severity: str
    summary: str
    doc: str
    fix: str
    #: Its page on the documentation site (None: a plugin's rule, which has none there).
    url: str | None


class Child:
    """One worker process and the documents' texts it holds."""

    def __init__(self, configuration: str | dict[str, Any] | None = None) -> None:
        import json
        import socket

        ours, theirs = socket.socketpair()
        self.process = subprocess.Popen(
            # Not ``-m``: the child's classes must pickle under this module's name.
            [sys.executable, "-c", _CHILD, str(theirs.fileno()), json.dumps(configuration)],
            pass_fds=[theirs.fileno()],
            stdin=subprocess.DEVNULL,
            stdout=sys.stderr.fileno(),
        )
        theirs.close()
        self.connection = Connection(ours.detach())
        #: The text each open document has in the child (by identity).
        self.texts: dict[str, str] = {}
        self.rules: tuple[RuleDoc, ...] | None = None
        #: Why it could not start: said again on each call, not as a crash.
        self.start_failure: LintFailed | None = None
        self.cancelled = False

    def ready(self, timeout: float = START_TIMEOUT) -> tuple[RuleDoc, ...]:
        """Wait for the child to have started; the rules' documentation."""
        if self.start_failure is not None:
            raise self.start_failure
        if self.rules is None:
            try:
                self.rules = self._receive(timeout)
            except LintFailed as failed:
                self.start_failure = failed
                raise
        return self.rules

    def call(self, method: str, args: tuple, texts: dict[str, str], timeout: float | None) -> Any:
        """``Documents.method(*args)`` in the child, after giving it ``texts``
        (the open documents). Raises :class:`LintFailed`."""
        self.ready()
        changes: dict[str, str | None] = {
            path: text for path, text in texts.items() if self.texts.get(path) is not text
        }
        changes.update({path: None for path in self.texts if path not in texts})
        try:
            self.connection.send((method, args, changes))
        except OSError:
            raise self._failure() from None
        self.texts = dict(texts)
        return self._receive(timeout)

    def _receive(self, timeout: float | None) -> Any:
        try:
            if not self.connection.poll(timeout):
                self.kill()
                raise LintFailed(
                    f"USD did not finish within {timeout:g} s (the time-out of check); "
                    "the lint was stopped"
                )
            status, value = self.connection.recv()
        except (EOFError, OSError):
            raise self._failure() from None
        if status == "error":
            raise LintFailed(value)
        return value

    def _failure(self) -> LintFailed:
        code = self.process.wait()
        if self.cancelled:
            return LintFailed("cancelled by a newer edit", cancelled=True)
        how = f"signal {-code}" if code < 0 else f"exit status {code}"
        return LintFailed(f"USD crashed while linting this document ({how})")

    def kill(self, *, cancelled: bool = False) -> None:
        self.cancelled = self.cancelled or cancelled
        if self.process.poll() is None:
            self.process.kill()

    def close(self) -> None:
        """End the child (it holds nothing to save; a child still starting would
        only see the closed socket once USD is imported)."""
        self.connection.close()
        self.kill()
        self.process.wait()

    @property
    def alive(self) -> bool:
        return self.process.poll() is None


class Linting:
    """The server's lints, one at a time, in a child process (with a spare).

    Called from the server's worker threads, never its protocol thread.
    :meth:`cancel` kills the child while it works on an older version of a
    document; the call waiting on it raises :class:`LintFailed` (cancelled).
    """

    def __init__(self) -> None:
        #: The editor's ``configuration`` (initializationOptions), for the children.
        self.configuration: str | dict[str, Any] | None = None
        self._lock = threading.Lock()
        self._state = threading.Lock()
        self._active: Child | None = None
        self._spare: Child | None = None
        #: (path, version, child, when it started) of the call running now.
        self._running: tuple[str, int, Child, float] | None = None
        self._closed = False

    def start(self) -> tuple[RuleDoc, ...]:
        """Start the children; the rules' documentation (waits for the first)."""
        with self._lock:
            return self._child().ready()

    def _child(self) -> Child:
        with self._state:
            if self._active is None or not self._active.alive:
                if self._active is not None:
                    self._active.close()
                self._active, self._spare = self._spare or Child(self.configuration), None
                if not self._active.alive:  # the spare died too (killed from outside)
                    self._active.close()
                    self._active = Child(self.configuration)
            if self._spare is None:
                self._spare = Child(self.configuration)
            return self._active

    def call(
        self,
        method: str,
        path: str,
        version: int,
        args: tuple,
        texts: dict[str, str],
        timeout: float | None,
    ) -> Any:
        with self._lock:
            if self._closed:
                raise LintFailed("the server is shutting down", cancelled=True)
            child = self._child()
            with self._state:
                self._running = (path, version, child, time.monotonic())
            try:
                return child.call(method, args, texts, timeout)
            except LintFailed:
                # It crashed, ran out of time or was cancelled: the spare takes over.
                child.kill()
                with self._state:
                    if self._active is child:
                        self._active = None
                child.close()
                raise
            finally:
                with self._state:
                    self._running = None

    def cancel(self, path: str, version: int, *, running_for: float = 0.0) -> bool:
        """Stop the running call if it works on ``path`` at a version older
        than ``version`` and has run ``running_for`` seconds at least; True
        when one was stopped."""
        with self._state:
            running = self._running
            if running is None or running[0] != path or running[1] >= version:
                return False
            if time.monotonic() - running[3] < running_for:
                return False
            running[2].kill(cancelled=True)
            return True

    def reconfigure(self, configuration: str | dict[str, Any] | None) -> None:
        """Lint with the editor's new ``configuration`` from now on: the children,
        which read it as they start, are replaced (a call running in one ends
        cancelled, and the next call starts a new one)."""
        with self._state:
            self.configuration = configuration
        self._end_children()

    def close(self) -> None:
        with self._state:
            self._closed = True
        self._end_children()

    def _end_children(self) -> None:
        """End both children, the call running in one cancelled."""
        with self._state:
            children = [c for c in (self._active, self._spare) if c is not None]
            self._active = self._spare = None
            running = self._running
        if running is not None:
            running[2].kill(cancelled=True)
        for child in children:
            child.close()


# -- the child ------------------------------------------------------------------------


def _rule_docs(registry) -> tuple[RuleDoc, ...]:
    from ..explain import rule_info
    from ..model import INTERNAL_ERROR_RULE

    infos = [(rule_info(rule), getattr(rule, "aliases", ())) for rule in registry.rules]
    infos.append((INTERNAL_ERROR_RULE, ()))
    return tuple(
        RuleDoc(
            i.code,
            i.name,
            tuple(a),
            str(i.severity),
            i.summary,
            i.doc,
            i.fix,
            i.url,
        )
        for i, a in infos
    )


def _watch_parent(parent: int) -> None:
    """End this process when the server is gone (a lint in progress would
    otherwise run to its end before the closed socket is seen)."""
    while True:
        time.sleep(1.0)
        if os.getppid() != parent:
            os._exit(0)


def serve(connection: Connection, configuration: str | dict[str, Any] | None = None) -> None:
    """Answer the server's calls until it closes the connection."""
    from ..engine import plugin_notes
    from ..running.documents import Documents

    threading.Thread(target=_watch_parent, args=(os.getppid(),), daemon=True).start()
    try:
        documents = Documents(configuration=configuration)
        # Standard error is the editor's log of the server.
        for line in plugin_notes():
            print(f"usdrender-lint: {line}", file=sys.stderr, flush=True)
        connection.send(("ok", _rule_docs(documents.registry)))
    except Exception as exc:  # noqa: BLE001 - said to the server, which reports it
        connection.send(("error", f"the linter cannot start: {type(exc).__name__}: {exc}"))
        return
    while True:
        try:
            method, args, texts = connection.recv()
        except (EOFError, OSError):
            return
        try:
            documents.update(texts)
            answer: tuple[str, Any] = ("ok", getattr(documents, method)(*args))
        except Exception as exc:  # noqa: BLE001 - one document's failure, said as such
            answer = ("error", f"internal error: {type(exc).__name__}: {exc}")
        connection.send(answer)


def main() -> None:
    import json

    connection = Connection(int(sys.argv[1]))
    configuration = json.loads(sys.argv[2]) if len(sys.argv) > 2 else None
    # The protocol is on the server's standard output; this process's stray
    # output (USD's, a rule's print) goes to standard error.
    os.dup2(2, 1)
    serve(connection, configuration)
