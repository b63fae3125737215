"""The process that runs USD for the language server, and the server's handle on it.

USD runs in a child process so that a document that crashes it (a corrupt
crate behind a reference) or hangs it (a FIFO on a sublayer path) costs that
document's lint, never the server: the server kills a child that runs past its
time limit, reports the crash or the time-out as one diagnostic on that
document, and the next lint starts in a new child. The child keeps USD, the
rules and the documents' layers loaded between lints (that is what makes a
re-lint after a keystroke fast), and a spare child is started beside it, so
that cancelling a long lint (killing its child, when a newer edit makes it
pointless) costs no start-up. While every serving child has been held by
a call for BUSY_LIMIT seconds, the spare becomes one more serving child (up to
MAX_CHILDREN; a new spare starts), so that documents that hang USD, or take
long, do not hold up the others until their time-out; a serving child beyond
the warm one ends once another is idle too. While all MAX_CHILDREN are busy,
a call that waits gives up a call past its limit (STUCK seconds, longer for a
document whose lints take long), said on its document as a time-out is. A
document holds one lint at a time: a newer lint of it waits for the running
one, and gives it up (its child killed) once it has run SLOW seconds, before
it starts; so does a newer code action request's call (a fix, a suppression)
of a document with an older one's.

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
        #: Why its call was given up for another's (see Linting._give_up_stuck).
        self.given_up: str | None = None
        #: A configuration file changed while another child read it again.
        self.stale_configuration = False

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
        if self.given_up is not None:
            return LintFailed(self.given_up)
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


#: Seconds every serving child may be held by its call before a call waiting
#: for one is served by the spare instead: a document that hangs USD (a FIFO on
#: a sublayer path) held every other document's lint until its time-out.
BUSY_LIMIT = 1.0
#: The most children that serve calls at once (besides the spare): two
#: documents that hung USD held the two there were, and every other document's
#: lint waited for their time-out.
MAX_CHILDREN = 4
#: Seconds a call may hold a child, at least, before a call that waits for one
#: while all MAX_CHILDREN are busy gives it up: four documents that hang USD (a
#: stalled share, a FIFO) held every child, and every other document's lint
#: waited for their time-out (120 s). A lint that is only slow may be given up
#: too: long enough for most first lints, short enough for an editor's wait.
STUCK = 4.0
#: ... or this many times as long as the document's last lint took, when longer.
STUCK_LINTS = 4.0
#: A lint that took longer than this is "slow" (the server waits out a burst of
#: edits before it lints a slow document again); a newer lint of a document
#: gives up the running one once it has run this long.
SLOW = 0.25


class Linting:
    """The server's lints in child processes: a warm one, a spare and, while
    every serving child has been busy for BUSY_LIMIT seconds, more (up to
    MAX_CHILDREN).

    Called from the server's worker threads, never its protocol thread. A call
    takes an idle child (the warm one first); when all are busy it waits for
    one. :meth:`cancel` kills the child while it lints an older version of a
    document; the call waiting on it raises :class:`LintFailed` (cancelled).
    """

    def __init__(self) -> None:
        #: The editor's ``configuration`` (initializationOptions), for the children.
        self.configuration: str | dict[str, Any] | None = None
        self._state = threading.Condition()
        #: The children that serve calls, the warm one first; the others serve
        #: while those before them are held up, and end once another is idle.
        self._children: list[Child] = []
        self._spare: Child | None = None
        #: Each busy child's call: (path, version, when it started, whether a lint).
        self._running: dict[Child, tuple[str, int, float, bool]] = {}
        #: Per document, the version below which a lint that waits for a child
        #: is pointless: a newer one was asked for (or the document closed).
        self._outdated: dict[str, int] = {}
        #: Per document, the newest code action request's version (see :meth:`call`).
        self._newest_action: dict[str, int] = {}
        #: Per document, the seconds its last lint that answered took.
        self._took: dict[str, float] = {}
        #: The children given up for a waiting call, until their call ends.
        self._giving_up: set[Child] = set()
        self._closed = False

    def start(self) -> tuple[RuleDoc, ...]:
        """Start the children; the rules' documentation (waits for the first)."""
        while True:
            child = self._acquire("", 0)
            try:
                # A child that cannot start stays: each call says why (Child.ready).
                return child.ready()
            except LintFailed as failed:
                # The editor's settings came in as it started (Neovim sends them
                # right after initialized): reconfigure ended it, and the server,
                # told the linter could not start, never linted a document.
                if not failed.cancelled:
                    raise
            finally:
                self._release(child, failed=False)

    def _fill(self) -> None:
        """Drop dead children (the next serving one, warm, before the spare);
        keep a serving child and a spare."""
        for child in list(self._children):
            if child not in self._running and not child.alive:
                child.close()
                self._children.remove(child)
        if not self._children:
            child, self._spare = self._spare or Child(self.configuration), None
            if not child.alive:  # the spare died too (killed from outside)
                child.close()
                child = Child(self.configuration)
            self._children.append(child)
        if self._spare is None:
            self._spare = Child(self.configuration)

    def _acquire(self, path: str, version: int, *, lint: bool = False) -> Child:
        # A code action's call (a fix, a suppression) of a document: the editor
        # asks again as the cursor moves (VS Code cancels the older request),
        # and each call on a document USD hangs on held a child until its
        # time-out, until every child was held and no document was linted.
        action = not lint and bool(path)
        with self._state:
            if action:
                self._newest_action[path] = max(self._newest_action.get(path, 0), version)
            while True:
                if self._closed:
                    raise LintFailed("the server is shutting down", cancelled=True)
                if lint and version < self._outdated.get(path, 0):
                    # Edits typed while a lint runs queued a lint each, and each
                    # text was linted in turn before the newest was shown.
                    raise LintFailed("outdated by a newer edit", cancelled=True)
                if action and version < self._newest_action.get(path, 0):
                    raise LintFailed("outdated by a newer code action", cancelled=True)
                if lint or action:
                    wait = self._give_up_older(path, version, lint=lint)
                    if wait is not None:
                        self._state.wait(wait)
                        continue
                self._fill()
                for child in self._children:
                    if child not in self._running:
                        self._running[child] = (path, version, time.monotonic(), lint)
                        return child
                if len(self._children) < MAX_CHILDREN:
                    held = max(self._running[child][2] for child in self._children)
                    wait = held + BUSY_LIMIT - time.monotonic()
                    if wait <= 0:
                        assert self._spare is not None  # _fill keeps one
                        self._children.append(self._spare)
                        self._spare = None
                        continue
                else:
                    wait = self._give_up_stuck()
                self._state.wait(wait)

    def _give_up_older(self, path: str, version: int, *, lint: bool) -> float | None:
        """For a lint (``lint``; else a code action's call) of ``path`` at
        ``version``: None when no older call of that kind of the document runs;
        else the seconds to wait for it (it ends, or is given up). Without
        this, a lint asked for before the running one turned out slow (an edit
        or a save as USD hangs on the document) took another child: two such
        documents held every child until their time-out."""
        now, wait = time.monotonic(), None
        for child, (running, older, started, linting) in self._running.items():
            if linting == lint and running == path and older < version:
                if now - started >= SLOW:
                    child.kill(cancelled=True)  # its call ends, and _release wakes us
                    left = BUSY_LIMIT
                else:
                    left = started + SLOW - now
                wait = left if wait is None else min(wait, left)
        return wait

    def _give_up_stuck(self) -> float:
        """Every serving child is busy, MAX_CHILDREN of them, and a call waits
        for one: give up the call that has held its child past its limit
        (STUCK seconds, or STUCK_LINTS times its document's last lint) the
        longest; its child ends, and the waiting call takes the spare. One
        at a time, and only for a call that waits: the work is bounded. The
        seconds to wait before looking again."""
        if self._giving_up:
            return BUSY_LIMIT  # its call ends, and _release wakes us

        def due(child: Child) -> float:
            path, _, started, _ = self._running[child]
            return started + max(STUCK, STUCK_LINTS * self._took.get(path, 0.0))

        now = time.monotonic()
        stuck = min(self._children, key=due)
        if due(stuck) > now:
            return due(stuck) - now
        held = now - self._running[stuck][2]
        # Said on that document, as a time-out is; it is not linted again by
        # itself (it would give up another's lint in turn).
        stuck.given_up = (
            f"USD had not finished after {held:.0f} s while other documents waited "
            f"(all {MAX_CHILDREN} of the linter's processes were busy); the lint was "
            "stopped: edit or save the document to lint it again"
        )
        stuck.kill()
        self._giving_up.add(stuck)
        return BUSY_LIMIT

    def _release(self, child: Child, *, failed: bool) -> None:
        ended = []
        with self._state:
            call = self._running.pop(child, None)
            self._giving_up.discard(child)
            if call is not None and call[3] and not failed:
                self._took[call[0]] = time.monotonic() - call[2]
            given_up = child.given_up is not None  # killed, even if it answered first
            if failed or child.cancelled or given_up or child not in self._children:
                # It crashed, ran out of time or was cancelled (or was replaced
                # meanwhile): the next call takes another. A cancel that landed
                # as the call's answer came in killed it all the same, and the
                # kill may not have taken yet: handed out, it failed the next
                # call as "cancelled", and that document's lint was never shown.
                child.kill()
                ended.append(child)
                if child in self._children:
                    self._children.remove(child)
            idle = [each for each in self._children if each not in self._running]
            for extra in idle[1:]:
                # One idle child is enough (the warmest: the first).
                self._children.remove(extra)
                ended.append(extra)
            self._state.notify_all()
        for each in ended:
            each.close()

    def call(
        self,
        method: str,
        path: str,
        version: int,
        args: tuple,
        texts: dict[str, str],
        timeout: float | None,
    ) -> Any:
        """``Documents.method(*args)`` in a child. ``version``: a lint's tick,
        or a code action request's (one for each of its calls: a newer
        request's call gives up the older requests' calls of the document)."""
        child = self._acquire(path, version, lint=method == "lint")
        failed = True
        try:
            if method == "forget_configuration":
                with self._state:
                    for other in self._children:
                        if other is not child:
                            other.stale_configuration = True
            elif child.stale_configuration:
                child.call("forget_configuration", (), texts, timeout)
            child.stale_configuration = False
            answer = child.call(method, args, texts, timeout)
            failed = False
            return answer
        finally:
            self._release(child, failed=failed)

    def cancel(self, path: str, version: int, *, running_for: float = 0.0) -> bool:
        """Stop the running lints of ``path`` at a version older than
        ``version`` that have run ``running_for`` seconds at least, and those
        that wait for a child; True when a running one was stopped."""
        stopped = False
        with self._state:
            self._outdated[path] = max(self._outdated.get(path, 0), version)
            self._state.notify_all()
            now = time.monotonic()
            for child, (running, older, started, lint) in self._running.items():
                # Not a code action's call: a save, or another document's lint,
                # lints the document again with its text unchanged, and stopped
                # the fix being made (the editor was offered none).
                if lint and running == path and older < version and now - started >= running_for:
                    child.kill(cancelled=True)
                    stopped = True
        return stopped

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
            self._state.notify_all()
        self._end_children()

    def _end_children(self) -> None:
        """End every child, the calls running in them cancelled: such a call
        closes its child as it returns (:meth:`_release`). Its socket closed
        under the call's wait, a new child's socket could take its number
        before the wait saw the child die, and the wait went on for that one
        until the time-out (the server's exit waited as long)."""
        with self._state:
            children = [*self._children, *([self._spare] if self._spare is not None else [])]
            self._children, self._spare = [], None
            running = set(self._running)
        for child in running:
            child.kill(cancelled=True)
        for child in children:
            if child not in running:
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
