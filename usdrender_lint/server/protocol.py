"""``usdrender-lint server``: the Language Server Protocol over stdio (pygls).

The protocol thread only keeps the documents' text and turns results into
protocol messages; USD runs in a child process (:mod:`.worker`), called from
this server's worker threads, so the server answers while a lint runs.
Diagnostics are published on open, on change and on save: a lint starts at
once for a document whose last lint was quick (changes that arrive meanwhile
wait for it and only the newest is linted), after a short pause for a slow
one, and a newer edit of a slow document cancels its running lint (of a
quick one, once that lint has run SLOW seconds: a document is linted once at
a time, :mod:`.worker`).
"""

from __future__ import annotations

import asyncio
import inspect
import json
import logging
import os
import re
import threading
import time
from collections.abc import Callable, Coroutine, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import TYPE_CHECKING, Any
from urllib.parse import quote, unquote, unquote_to_bytes, urlparse

from lsprotocol import types
from pygls.exceptions import (
    FeatureNotificationError,
    FeatureRequestError,
    JsonRpcException,
    JsonRpcInvalidParams,
    JsonRpcInvalidRequest,
    JsonRpcServerNotInitialized,
)
from pygls.lsp.server import LanguageServer
from pygls.protocol import LanguageServerProtocol
from pygls.uris import from_fs_path, to_fs_path
from pygls.workspace import PositionCodec, ServerTextPosition, TextDocument

from .. import __version__
from ..model import Finding, Severity
from ..paths import is_utf8
from ..records import record
from ..running.documents import Linted, finding_key
from .ranges import Edit, Span, editor_lines, lines_of, spec_line, statement_span, text_edits
from .worker import MAX_CHILDREN, SLOW, LintFailed, Linting, RuleDoc

if TYPE_CHECKING:
    from cattrs import Converter

NAME = "usdrender-lint"
#: source.fixAll for this server: the safe fixes of the document, as --fix applies them.
FIX_ALL = f"{types.CodeActionKind.SourceFixAll.value}.{NAME}"
#: Files whose change means the configuration may have changed: any TOML file,
#: since a configuration may ``extend`` a file of any name.
CONFIG_SUFFIX = ".toml"
USD_TEXT_SUFFIXES = (".usda", ".usd")
#: After an edit of a slow document (its lint took longer than SLOW), seconds
#: the server waits before linting it: a running lint of it is cancelled at once.
DEBOUNCE = 0.2
#: Text this long is presumed slow before its first lint finishes.
LARGE_TEXT = 1_000_000
#: Seconds a lint may take before it is stopped (check's default --timeout).
TIMEOUT = 120.0
#: Seconds a code action request's calls of USD may take in all, at least: the
#: editor waits for its answer (a menu, a light bulb), and a fix of a document
#: USD hangs on answered only at the lint's time-out (120 s), its child held.
ACTION_TIME = 5.0
#: ... or this many times the document's last lint, when longer (a fix lints
#: the stage again as it applies each fix).
ACTION_LINTS = 4.0
#: How often the server checks that the client's process is still alive.
PARENT_POLL = 2.0

_SEVERITY = {
    Severity.ERROR: types.DiagnosticSeverity.Error,
    Severity.WARNING: types.DiagnosticSeverity.Warning,
    Severity.INFO: types.DiagnosticSeverity.Information,
}
_WORD = re.compile(r"[A-Za-z][\w-]*")


def apply_change(
    text: str, change: types.TextDocumentContentChangeEvent, codec: PositionCodec
) -> str:
    """``text`` after one change of a didChange, its range read in the lines as
    the editor numbers them: pygls numbers lines with ``str.splitlines``,
    which also ends one at a form feed or U+2028 in a comment, so an edit
    below one went to the wrong line."""
    if not isinstance(change, types.TextDocumentContentChangePartial):
        return change.text
    lines = editor_lines(text)
    span = codec.range_from_client_units(lines, change.range)

    def offset(line: int, column: int) -> int:
        if line >= len(lines):
            return len(text)
        return sum(map(len, lines[:line])) + min(column, len(lines[line]))

    start = offset(span.start.line, span.start.character)
    end = max(start, offset(span.end.line, span.end.character))
    return text[:start] + change.text + text[end:]


@record(frozen=True)
class Asked:
    """One code action request, for the calls it makes of USD: they share its
    tick (a newer request of a document gives up the older ones' calls) and
    the time by which they must be done (``time.monotonic``)."""

    tick: int
    deadline: float


class Unfit:
    """A client's message whose params do not fit its method."""

    def __init__(self, id_: int | str | None, method: str) -> None:
        self.id = id_
        self.method = method


class EditorProtocol(LanguageServerProtocol):
    """pygls's protocol, answering the requests it leaves unanswered (the
    client would wait for them forever), and applying a document's changes
    where the editor means them. Only pygls's public API: its underscore
    names change between releases."""

    def __init__(self, server: UsdRenderLintServer, converter: Converter) -> None:
        super().__init__(server, converter)
        self.language_server = server
        self.converter = converter

    def structure_message(self, data: dict[str, Any]) -> Any:
        # pygls raises from inside json.loads for a message whose params do not
        # fit: the request went unanswered, a notification popped up an error.
        method = data.get("method")
        if "jsonrpc" in data and isinstance(method, str):
            message_type = self.get_message_type(method)
            if message_type is not None:
                try:
                    return self.converter.structure(data, message_type)
                except Exception:  # noqa: BLE001 - cattrs' errors, a missing key, ...
                    return Unfit(data.get("id"), method)
        return super().structure_message(data)

    def handle_message(self, message: Any) -> None:
        if not isinstance(message, Unfit) and not hasattr(message, "jsonrpc"):
            # JSON, but no message (a list, a number, an object without "jsonrpc").
            self.log(types.MessageType.Error, "ignored a message that is not JSON-RPC")
            return
        if isinstance(message, Unfit):
            why = f"the params of {message.method} do not fit the protocol"
            if message.id is not None:
                self.answer_error(message.id, JsonRpcInvalidParams(why))
            else:
                self.log(types.MessageType.Warning, f"ignored: {why}")
            return
        method = getattr(message, "method", None)
        # A request has a method and an id; a notification has no id.
        request_id = getattr(message, "id", None) if method is not None else None
        server = self.language_server
        if not server.client_initialized and method not in (None, types.INITIALIZE, types.EXIT):
            # Before initialize (pygls failed the request with its traceback, and a
            # notification popped up one): refused, and dropped, as the protocol says.
            if request_id is not None:
                self.answer_error(request_id, JsonRpcServerNotInitialized("initialize first"))
            return
        if request_id is not None and server.shut_down:
            self.answer_error(request_id, JsonRpcInvalidRequest("the server is shut down"))
            return
        if method == types.TEXT_DOCUMENT_DID_CHANGE and not self._whole_text(message.params):
            return
        super().handle_message(message)

    def _whole_text(self, params: types.DidChangeTextDocumentParams) -> bool:
        """Turn the changes into the one whole text they make, for pygls to
        take as it is; False for a document the client never opened (pygls
        raised KeyError, an error popup: there is nothing to change)."""
        document = self.language_server.open_document(params.text_document.uri)
        if document is None:
            return False
        text = document.source
        for change in params.content_changes:
            text = apply_change(text, change, self.workspace.position_codec)
        params.content_changes = [types.TextDocumentContentChangeWholeDocument(text=text)]
        return True

    def log(self, kind: types.MessageType, message: str) -> None:
        self.language_server.window_log_message(types.LogMessageParams(kind, f"{NAME}: {message}"))

    def answer_error(self, request_id: int | str, error: JsonRpcException) -> None:
        """Answer a request with an error, on the writer pygls reads and writes
        through (the stdio one, which frames each message with its length)."""
        answer = {"code": error.code, "message": error.message}
        body = json.dumps({"jsonrpc": "2.0", "id": request_id, "error": answer}).encode()
        if self.writer is None:  # no transport yet: nothing can be said
            return
        written = self.writer.write(b"Content-Length: %d\r\n\r\n" % len(body) + body)
        if inspect.isawaitable(written):
            asyncio.ensure_future(written)


class OneLine(logging.Formatter):
    """pygls's log records on standard error (the editor's log of the server),
    one line each: it logs a client's unreadable message with a traceback."""

    def format(self, record: logging.LogRecord) -> str:
        first = record.getMessage().strip().split("\n", 1)[0]
        cause = record.exc_info[1] if record.exc_info else None
        return f"{NAME}: {first}" + (f": {cause}" if cause is not None else "")


class UsdRenderLintServer(LanguageServer):
    def __init__(self, linting: Linting | None = None) -> None:
        super().__init__(
            NAME,
            __version__,
            protocol_cls=EditorProtocol,
            text_document_sync_kind=types.TextDocumentSyncKind.Incremental,
        )
        self.linting = linting or Linting()
        # A thread per child that may serve a call, and two for the calls that
        # wait meanwhile (a newer lint giving up a hung one, a code action).
        self.executor = ThreadPoolExecutor(
            max_workers=MAX_CHILDREN + 2, thread_name_prefix="usdrender-lint"
        )
        self.rules: dict[str, RuleDoc] = {}
        #: Every code, name and alias, lower-cased, to its rule.
        self.rule_names: dict[str, RuleDoc] = {}
        #: The newest lint asked for, per document (a counter: saves count too).
        self.wanted: dict[str, int] = {}
        self.ticks = 0
        self.seconds: dict[str, float] = {}
        #: The findings of each document's last lint, and the text they were made from.
        self.findings: dict[str, tuple[tuple[Finding, ...], dict[str, str]]] = {}
        #: Whether each document's fixes may be made (Linted.fixes).
        self.can_fix: dict[str, bool] = {}
        #: The text each document's last lint ran out of time (or crashed) on,
        #: by path: a fix of the same text would too, and is not tried (until a
        #: lint of it, after an edit of a layer it composes, say, succeeds).
        self.failed: dict[str, str] = {}
        #: The documents whose edit owes the documents that compose them a lint.
        self.dependents_due: set[str] = set()
        #: The files each open document's stage composed at its last lint (their
        #: :func:`file_key`), by path.
        self.layers: dict[str, frozenset[str]] = {}
        #: What each linted document (the source) publishes on each document URI.
        self.published: dict[str, dict[str, list[types.Diagnostic]]] = {}
        self.ready = threading.Event()
        #: Seconds a lint may take (initializationOptions ``timeout``); None: no limit.
        self.timeout: float | None = TIMEOUT
        self.shut_down = False
        #: The client's initialize request was handled (pygls made the workspace).
        self.client_initialized = False
        #: The lints (and other work) running beside the protocol.
        self.tasks: set[asyncio.Future[None]] = set()
        #: The process's exit status: 1 when the client said exit without shutdown
        #: (the protocol's rule), else 0.
        self.exit_status = 0

    def spawn(self, work: Coroutine[Any, Any, None]) -> None:
        """Run ``work`` beside the protocol, not in a handler pygls awaits: the
        loop cancels it when the editor goes, which in a handler wrote
        CancelledError's traceback to the editor's log; a failure is one line."""
        task = asyncio.ensure_future(work)
        self.tasks.add(task)  # the loop holds tasks weakly only
        task.add_done_callback(self._finished)

    def _finished(self, task: asyncio.Future[None]) -> None:
        self.tasks.discard(task)
        error = None if task.cancelled() else task.exception()
        if isinstance(error, Exception):
            self.report_server_error(error, FeatureNotificationError)

    def report_server_error(self, error: Exception, source: Any) -> None:
        """A notification's handler failed, or a message could not be read:
        one line in the editor's log, where pygls popped up "Error in server:"
        with Python's exception. (A failed request's answer says why.)"""
        if source is FeatureRequestError:
            return
        if isinstance(error, ValueError):  # json.loads's JSONDecodeError
            what = f"ignored a message that is not JSON: {error}"
        else:
            what = f"internal error: {getattr(error, 'message', None) or error}"
        self.window_log_message(types.LogMessageParams(types.MessageType.Error, f"{NAME}: {what}"))

    def settings_changed(self, settings: Any) -> None:
        """The editor's settings changed (ours under our name, as Neovim's
        ``settings`` and VS Code's hold them, or alone): a new ``configuration``
        re-lints every open document with it."""
        settings = settings if isinstance(settings, dict) else {}
        ours = settings.get(NAME, settings)
        if not isinstance(ours, dict) or "configuration" not in ours:
            return
        configuration = editor_configuration(ours)
        if configuration == self.linting.configuration:
            return
        self.linting.reconfigure(configuration)
        if self.ready.is_set():
            for uri in self.open_uris():
                self.spawn(self.lint(uri))

    # -- documents -----------------------------------------------------------------

    def open_uris(self) -> list[str]:
        """The URIs of the open documents, as the client names them."""
        return [document.uri for document in list(self.workspace.text_documents.values())]

    def open_document(self, uri: str) -> TextDocument | None:
        """The open document the client names ``uri``, or None. pygls keys its
        documents by the URI decoded, where a client may send it encoded
        (VS Code: ``file:///my%20shot%20%C3%A9.usda``)."""
        return self.workspace.text_documents.get(unquote(uri))

    def uri_of(self, path: str) -> str:
        """The URI to publish on for the file ``path``: the client's own for an
        open document, else the file's."""
        for uri in self.open_uris():
            if usd_path(uri) == path:
                return uri
        return file_uri(path)

    def texts(self) -> dict[str, str]:
        """The text of every open USD document, by path."""
        found = {}
        for document in list(self.workspace.text_documents.values()):
            path = usd_path(document.uri)
            if path is not None:
                found[path] = document.source
        return found

    def version_of(self, uri: str) -> int | None:
        document = self.open_document(uri)
        return document.version if document is not None else None

    async def start_linting(self) -> None:
        loop = asyncio.get_running_loop()
        try:
            docs = await loop.run_in_executor(self.executor, self.linting.start)
        except LintFailed as failed:
            if not self.shut_down:  # else shutdown ended the child as it started
                self.window_log_message(
                    types.LogMessageParams(types.MessageType.Error, f"{NAME}: {failed.reason}")
                )
            return
        self.rules = {rule.code: rule for rule in docs}
        for rule in docs:
            for word in (rule.code, rule.name, *rule.aliases):
                self.rule_names[word.lower()] = rule
        self.ready.set()

    async def lint(self, uri: str, *, dependents: bool = True) -> None:
        """Lint the document and publish its diagnostics, unless a newer lint
        of it is asked for meanwhile; then (``dependents``) the other open
        documents that name its file (a sublayer or reference of theirs)."""
        path = usd_path(uri)
        if path is None or self.open_document(uri) is None:
            return
        self.ticks += 1
        tick = self.wanted[uri] = self.ticks
        if dependents:
            # Owed until a lint of it is shown: a newer lint asked for meanwhile
            # (closing a document it names asks for one) may not lint them.
            self.dependents_due.add(uri)
        if not await self._make_way(uri, path, tick):
            return
        loop = asyncio.get_running_loop()
        texts = self.texts()
        version = self.version_of(uri)
        try:
            linted, layers = await loop.run_in_executor(
                self.executor, self._lint_in_child, path, tick, texts
            )
        except LintFailed as failed:
            if failed.cancelled:
                return
            linted, layers = Linted(error=failed.reason), frozenset()
            if self.wanted.get(uri) == tick and path in texts:
                self.failed[path] = texts[path]
        else:
            if self.wanted.get(uri) == tick:
                self.failed.pop(path, None)
        if self.wanted.get(uri) != tick or self.open_document(uri) is None:
            return
        self.seconds[path] = linted.seconds
        self.layers[path] = layers
        self.findings[uri] = (linted.findings, texts)
        self.can_fix[uri] = linted.fixes
        self.publish(uri, self.diagnostics(uri, path, linted, texts), version)
        if uri in self.dependents_due:
            self.dependents_due.discard(uri)
            self._lint_dependents(path, texts)
        # A layer its stage composed changed while it ran (an edit, an open, a
        # close): that layer's lint went by this document's older layers, which
        # may not have composed it, so did not lint it again.
        now = self.texts()
        if any(texts.get(layer) != now.get(layer) for layer in linted.layers - {path}):
            self.spawn(self.lint(uri, dependents=False))

    def _lint_in_child(
        self, path: str, tick: int, texts: dict[str, str]
    ) -> tuple[Linted, frozenset[str]]:
        """The document's lint, and the :func:`file_key` of each file its stage
        composed (found here, off the protocol thread: a file on a network
        share may take a while to resolve)."""
        linted: Linted = self.linting.call("lint", path, tick, (path,), texts, self.timeout)
        return linted, frozenset(map(file_key, linted.layers))

    async def _make_way(self, uri: str, path: str, tick: int) -> bool:
        """Cancel the document's running lint where it pays, and wait out a burst of
        edits on a slow one; False when a newer lint was asked for meanwhile."""
        document = self.open_document(uri)
        text = document.source if document is not None else ""
        expected = self.seconds.get(path, SLOW * 2 if len(text) > LARGE_TEXT else 0.0)
        # A slow document's running lint is cancelled at once; a quick one's
        # only when it turns out slow (USD hangs on it, say): else it ends soon.
        if self.linting.cancel(path, tick, running_for=0.0 if expected >= SLOW else SLOW):
            self.window_log_message(
                types.LogMessageParams(
                    types.MessageType.Log, f"{NAME}: a newer edit cancelled the lint of {path}"
                )
            )
        if expected >= SLOW:
            await asyncio.sleep(DEBOUNCE)
            return self.wanted.get(uri) == tick
        return True

    def _lint_dependents(self, path: str, texts: dict[str, str]) -> None:
        """Lint again the other open documents whose stage composed ``path``'s
        file at their last lint (through any chain of sublayers and
        references), or that name it (it may be new to them)."""
        for other in self._dependents(path, texts):
            self.spawn(self.lint(self.uri_of(other), dependents=False))

    def _dependents(self, path: str, texts: dict[str, str]) -> list[str]:
        name, key = os.path.basename(path), file_key(path)
        return [
            other
            for other, text in texts.items()
            if other != path and (name in text or key in self.layers.get(other, ()))
        ]

    def forget(self, uri: str) -> None:
        """A closed document: its running lint stops, its diagnostics go, on it
        and elsewhere; the open documents whose findings were shown on it are linted again
        (they now show them as related information, with the file's text)."""
        self.wanted.pop(uri, None)
        self.dependents_due.discard(uri)
        self.findings.pop(uri, None)
        self.can_fix.pop(uri, None)
        path = usd_path(uri)
        if path is not None:
            self.layers.pop(path, None)
            self.failed.pop(path, None)
            # Its running lint is pointless now, and every other lint waits for it.
            self.ticks += 1
            self.linting.cancel(path, self.ticks)
        own = self.published.pop(uri, {})
        # Cleared at once, whatever other documents' lints found on it: the
        # editor no longer shows it, and their next lints show no finding on it.
        shown_there = [
            source for source, found in self.published.items() if found.pop(uri, None) is not None
        ]
        self.text_document_publish_diagnostics(
            types.PublishDiagnosticsParams(uri=uri, diagnostics=[], version=None)
        )
        for target in set(own) - {uri}:
            self._publish_merged(target, self.version_of(target))
        # Its file is what their stages compose now, not the unsaved text.
        relint = set(shown_there)
        if path is not None:
            relint.update(self.uri_of(other) for other in self._dependents(path, self.texts()))
        for source in sorted(relint):
            self.spawn(self.lint(source, dependents=False))

    # -- diagnostics ---------------------------------------------------------------

    def diagnostics(
        self, uri: str, path: str, linted: Linted, texts: dict[str, str]
    ) -> dict[str, list[types.Diagnostic]]:
        """The lint's diagnostics by the URI they are published on: the
        document's, and those of other open documents whose layers hold findings."""
        text = texts.get(path, "")
        found: dict[str, list[types.Diagnostic]] = {uri: []}
        if linted.error is not None:
            span = statement_span(text, 1)
            found[uri].append(
                types.Diagnostic(
                    range=self.range(text, span),
                    message=linted.error,
                    severity=types.DiagnosticSeverity.Error,
                    source=NAME,
                )
            )
            return found
        index: dict[str, int] | None = None
        open_path = opened_as(texts)
        for finding in linted.findings:
            layer = open_path(finding.location.layer or path)
            if layer == path or layer in texts:
                target = uri if layer == path else self.uri_of(layer)
                target_text = texts[layer]
                span = statement_span(target_text, finding.location.line, finding.location.column)
                found.setdefault(target, []).append(
                    self.diagnostic(finding, self.range(target_text, span))
                )
                continue
            # Another file, not open: shown where the document brings the object in.
            if index is None:
                from ..layers.usda_text import index_usda

                index = index_usda(text)
            line = spec_line(text, finding.location.path, index)
            related_line = max((finding.location.line or 1) - 1, 0)
            related = types.DiagnosticRelatedInformation(
                location=types.Location(
                    uri=file_uri(layer),
                    range=types.Range(
                        types.Position(related_line, 0), types.Position(related_line, 0)
                    ),
                ),
                message=f"the opinion is in {layer}"
                + (f", line {finding.location.line}" if finding.location.line else ""),
            )
            found[uri].append(
                self.diagnostic(finding, self.range(text, statement_span(text, line)), [related])
            )
        return found

    def diagnostic(
        self,
        finding: Finding,
        range_: types.Range,
        related: list[types.DiagnosticRelatedInformation] | None = None,
    ) -> types.Diagnostic:
        rule = self.rules.get(finding.code)
        fix = finding.fix
        return types.Diagnostic(
            range=range_,
            severity=_SEVERITY[finding.severity],
            code=finding.code,
            code_description=types.CodeDescription(href=rule.url) if rule and rule.url else None,
            source=NAME,
            message=finding.message,
            related_information=related,
            data={
                "name": finding.name,
                "path": finding.location.path,
                "profile": finding.profile,
                "profileReason": finding.profile_reason,
                "fix": {"description": fix.description, "safe": fix.safe} if fix else None,
                "key": list(finding_key(finding)),
            },
        )

    def range(self, text: str, span: Span) -> types.Range:
        lines = lines_of(text)
        codec = self.workspace.position_codec

        def position(at: tuple[int, int]) -> types.Position:
            return codec.position_to_client_units(lines, ServerTextPosition(*at))

        return types.Range(position(span.start), position(span.end))

    def publish(
        self, source: str, found: dict[str, list[types.Diagnostic]], version: int | None
    ) -> None:
        """Publish what the lint of ``source`` found on each URI, beside what
        the lints of other documents found there."""
        # A lint that began while another document was open publishes nothing
        # on it once it is closed.
        found = {
            target: diagnostics
            for target, diagnostics in found.items()
            if target == source or self.open_document(target) is not None
        }
        before = self.published.get(source, {})
        self.published[source] = found
        for target in set(before) | set(found):
            self._publish_merged(target, version if target == source else self.version_of(target))

    def _publish_merged(self, target: str, version: int | None) -> None:
        """Publish on ``target`` what every document's lint found there."""
        merged: list[types.Diagnostic] = []
        seen: set[tuple] = set()
        for published in self.published.values():
            for diagnostic in published.get(target, ()):
                key = (
                    diagnostic.range.start.line,
                    diagnostic.range.start.character,
                    diagnostic.code,
                    diagnostic.message,
                )
                if key not in seen:
                    seen.add(key)
                    merged.append(diagnostic)
        self.text_document_publish_diagnostics(
            types.PublishDiagnosticsParams(uri=target, diagnostics=merged, version=version)
        )

    # -- code actions --------------------------------------------------------------

    async def code_actions(self, params: types.CodeActionParams) -> list[types.CodeAction]:
        uri = params.text_document.uri
        path = usd_path(uri)
        if path is None or self.open_document(uri) is None:
            return []
        only = params.context.only
        texts = self.texts()
        version = self.version_of(uri)
        asked = self.asked(path)
        actions: list[types.CodeAction] = []
        if _wants(only, types.CodeActionKind.QuickFix):
            for diagnostic in params.context.diagnostics:
                if _ours(diagnostic):
                    source = self._linted_by(uri, diagnostic) or path
                    actions.extend(await self._quick_fixes(source, diagnostic, texts, asked))
        fix_all = await self._fix_all(uri, path, only, version, texts, asked)
        if fix_all is not None:
            actions.append(fix_all)
        if self.version_of(uri) != version:
            return []  # the text changed meanwhile: these edits are for the old one
        return actions

    def _linted_by(self, uri: str, diagnostic: types.Diagnostic) -> str | None:
        """The path of the open document whose lint found ``diagnostic``, shown
        on ``uri``: a shot's finding in an open sublayer is shown on the layer,
        whose own stage may not have it to fix."""
        key = _key_of(diagnostic)
        for source in (uri, *self.published):
            if any(_key_of(d) == key for d in self.published.get(source, {}).get(uri, ())):
                return usd_path(source)
        return None

    def asked(self, path: str) -> Asked:
        """A code action request on the document ``path``: its calls of USD
        may take ACTION_TIME seconds in all (ACTION_LINTS of its last lint
        when longer), never more than a lint may."""
        self.ticks += 1
        budget = max(ACTION_TIME, ACTION_LINTS * self.seconds.get(path, 0.0))
        if self.timeout is not None:
            budget = min(budget, self.timeout)
        return Asked(self.ticks, time.monotonic() + budget)

    async def _fix_all(
        self,
        uri: str,
        path: str,
        only: Sequence[str] | None,
        version: int | None,
        texts: dict[str, str],
        asked: Asked,
    ) -> types.CodeAction | None:
        """The action that applies every safe fix, when the document's last lint
        found one."""
        linted = self.findings.get(uri)
        if linted is None or not any(f.fix is not None and f.fix.safe for f in linted[0]):
            return None
        if not self.can_fix.get(uri, True):
            return None  # config `variants`: no fix is made (Documents.fix)
        title = f"{NAME}: apply every safe fix"
        if _wants(only, FIX_ALL, explicit=True):
            edit = await self._fix_edit(path, None, False, texts, asked)
            return None if edit is None else types.CodeAction(title=title, kind=FIX_ALL, edit=edit)
        if only is None and self._resolves_edits():
            # Asked for every action (a light bulb, a menu): the fix-all's edit
            # is made only if it is chosen (codeAction/resolve).
            data = {"uri": uri, "version": version}
            return types.CodeAction(title=title, kind=FIX_ALL, data=data)
        return None

    def _resolves_edits(self) -> bool:
        """Whether the client resolves a code action's edit when it is chosen."""
        document = self.client_capabilities.text_document
        action = document.code_action if document else None
        support = action.resolve_support if action else None
        return support is not None and "edit" in support.properties

    async def resolve_code_action(self, action: types.CodeAction) -> types.CodeAction:
        """The edit of a fix-all offered without one (see :meth:`code_actions`)."""
        data = action.data if isinstance(action.data, dict) else {}
        uri = data.get("uri")
        path = usd_path(uri) if isinstance(uri, str) else None
        if path is None or self.version_of(str(uri)) != data.get("version"):
            return action  # the text changed since: no edit (the client asks again)
        action.edit = await self._fix_edit(path, None, False, self.texts(), self.asked(path))
        return action

    async def _quick_fixes(
        self, path: str, diagnostic: types.Diagnostic, texts: dict[str, str], asked: Asked
    ) -> list[types.CodeAction]:
        data: dict[str, Any] = diagnostic.data or {}
        code, object_path, message = data["key"]
        actions = []
        fix = data.get("fix")
        if fix:
            safe = bool(fix.get("safe"))
            edit = await self._fix_edit(path, (code, object_path, message), not safe, texts, asked)
            if edit is not None:
                label = "" if safe else " (unsafe: check the result)"
                actions.append(
                    types.CodeAction(
                        title=f"Fix {code}: {fix.get('description')}{label}",
                        kind=types.CodeActionKind.QuickFix,
                        diagnostics=[diagnostic],
                        edit=edit,
                        is_preferred=safe,
                    )
                )
        if object_path and code in self.rules:
            text = await self._call("suppress", path, (path, code, object_path), texts, asked)
            if (
                isinstance(text, str)
                and path in texts
                and self._still_current({path: (texts[path], text)}, texts)
            ):
                prim = object_path.split(".")[0]
                actions.append(
                    types.CodeAction(
                        title=f"Suppress {code} on {prim} (customData)",
                        kind=types.CodeActionKind.QuickFix,
                        diagnostics=[diagnostic],
                        edit=self.workspace_edit({path: (texts[path], text)}),
                    )
                )
        return actions

    async def _fix_edit(
        self,
        path: str,
        target: tuple | None,
        unsafe: bool,
        texts: dict[str, str],
        asked: Asked,
    ) -> types.WorkspaceEdit | None:
        changed = await self._call("fixes", path, (path, target, unsafe), texts, asked)
        if changed:
            # A layer the stage composed by a path through a symlink is the open
            # document of that file: the edit is the document's.
            open_path = opened_as(texts)
            changed = {open_path(layer): edit for layer, edit in changed.items()}
        if not changed or not self._still_current(changed, texts):
            return None
        return self.workspace_edit(changed)

    def _still_current(self, changed: dict[str, tuple[str, str]], texts: dict[str, str]) -> bool:
        """Whether each open document an edit is for (or was, when it was made)
        holds the text it was made from: an edit that came in meanwhile made it
        an edit of the older text, which the editor would apply to the newer."""
        now = self.texts()
        return all(
            now.get(path) == before
            for path, (before, _) in changed.items()
            if path in now or path in texts
        )

    async def _call(
        self,
        method: str,
        path: str,
        args: tuple,
        texts: dict[str, str],
        asked: Asked | None = None,
    ) -> Any:
        """``Documents.method(*args)`` in a child; None when it failed, or (a
        code action's call, ``asked``) was not made: no time is left, or the
        lint of the document's text ran out of time (USD hangs on it)."""
        loop = asyncio.get_running_loop()
        timeout = self.timeout
        if asked is None:
            self.ticks += 1
            tick = self.ticks
        else:
            left = asked.deadline - time.monotonic()
            if left <= 0 or (path in texts and self.failed.get(path) == texts[path]):
                return None
            tick, timeout = asked.tick, left if timeout is None else min(timeout, left)
        try:
            return await loop.run_in_executor(
                self.executor, self.linting.call, method, path, tick, args, texts, timeout
            )
        except LintFailed:
            return None

    def workspace_edit(self, changed: dict[str, tuple[str, str]]) -> types.WorkspaceEdit:
        changes = {}
        for path, (before, after) in changed.items():
            changes[self.uri_of(path)] = [
                types.TextEdit(range=self.range(before, edit.span), new_text=edit.text)
                for edit in text_edits(before, after)
            ]
        return types.WorkspaceEdit(changes=changes)

    # -- hover ---------------------------------------------------------------------

    def hover(self, params: types.HoverParams) -> types.Hover | None:
        uri = params.text_document.uri
        document = self.open_document(uri)
        if document is None or not self.rules:
            return None
        position = params.position
        shown: list[RuleDoc] = []
        word = self._suppression_word(document.source, position)
        if word is not None and word.lower() in self.rule_names:
            shown.append(self.rule_names[word.lower()])
        for published in self.published.values():
            for diagnostic in published.get(uri, ()):
                if _contains(diagnostic.range, position) and diagnostic.code in self.rules:
                    rule = self.rules[str(diagnostic.code)]
                    if rule not in shown:
                        shown.append(rule)
        if not shown:
            return None
        return types.Hover(
            contents=types.MarkupContent(
                kind=types.MarkupKind.Markdown, value="\n\n---\n\n".join(map(rule_markdown, shown))
            )
        )

    def _suppression_word(self, text: str, position: types.Position) -> str | None:
        """The quoted word under the cursor when it is an entry of a customData
        ``usdrender_lint`` suppression (``string[] ignore = ["SE003"]``). Only
        the lines up to the cursor's are split (a document may be 15 MB)."""
        lines = text.split("\n", position.line + 1)[: position.line + 1]
        if len(lines) <= position.line:
            return None
        line = lines[position.line]
        column = self.workspace.position_codec.position_from_client_units(
            [line], types.Position(0, position.character)
        ).character
        for match in _WORD.finditer(line):
            if match.start() <= column <= match.end():
                quoted = match.start() > 0 and line[match.start() - 1] in "\"'"
                if not quoted:
                    return None
                above = "".join(lines[max(0, position.line - 6) :])
                return match.group() if "usdrender_lint" in above or "ignore" in line else None
        return None

    # -- configuration and files ---------------------------------------------------

    async def files_changed(self, paths: list[str]) -> None:
        """Files changed on disk: a configuration file makes every open
        document be linted with the configuration read again; a layer, with
        the layer read again (its lint reloads changed files)."""
        if any(p.endswith(CONFIG_SUFFIX) for p in paths):
            await self._call("forget_configuration", "", (), self.texts())
        for uri in self.open_uris():
            if usd_path(uri) is not None:
                self.spawn(self.lint(uri))

    def close(self) -> None:
        self.linting.close()
        self.executor.shutdown(wait=False, cancel_futures=True)


def rule_markdown(rule: RuleDoc) -> str:
    head = f"**{rule.code} {rule.name}** ({rule.severity}; fix: {rule.fix})"
    # explain's text starts with the same facts, unformatted.
    doc = rule.doc.split("\n", 1)[1] if rule.doc.startswith(rule.code) else rule.doc
    link = f"\n\n[{rule.code} on the documentation site]({rule.url})" if rule.url else ""
    return f"{head}\n\n{doc.strip()}{link}"


def fs_path(uri: str) -> str | None:
    """pygls's ``to_fs_path``, where a name's bytes that are not UTF-8 (a
    folder ``d%E9``) come back as Python names them (surrogate escapes: the
    file's real name), not as U+FFFD."""
    path = to_fs_path(uri)
    if path is not None and "\ufffd" in path and os.name == "posix":
        path = os.fsdecode(unquote_to_bytes(urlparse(uri).path))
    return path


def file_uri(path: str) -> str:
    """pygls's ``from_fs_path``, for a name that is not UTF-8 too (its bytes
    percent-encoded, as ``pathlib.Path.as_uri`` writes them)."""
    if is_utf8(path):
        return from_fs_path(path) or path
    return "file://" + quote(os.fsencode(path))


def usd_path(uri: str) -> str | None:
    """The file path of a USD text document's URI (None: not one we lint)."""
    if not uri.startswith("file:"):
        return None
    path = fs_path(uri)
    if path is None or not path.lower().endswith(USD_TEXT_SUFFIXES):
        return None
    return os.path.abspath(path)


def file_key(path: str) -> str:
    """What a file is, by whichever path reaches it: the editor may name a
    document by a symlink's path (its workspace folder is reached through one)
    where a stage composes it by the resolved path, or the other way round
    (USD keeps a layer's path as the asset path gave it). As running/roots.py's
    file_key compares files; that module imports USD, which the server does not."""
    return os.path.normcase(os.path.realpath(path))


def opened_as(texts: dict[str, str]) -> Callable[[str], str]:
    """For a layer's path, the path of the open document (of ``texts``) that is
    its file, else the layer's: a stage may compose a document by a path on the
    other side of a symlink (that layer then holds the document's text). Each
    file is looked up once (a lint may have many findings in closed layers)."""
    documents: dict[str, str] | None = None
    found: dict[str, str] = {}

    def open_path(layer: str) -> str:
        nonlocal documents
        if layer in texts:
            return layer
        if layer not in found:
            if documents is None:
                documents = {file_key(other): other for other in texts}
            found[layer] = documents.get(file_key(layer), layer)
        return found[layer]

    return open_path


def _key_of(diagnostic: types.Diagnostic) -> tuple[Any, ...] | None:
    """The finding key a diagnostic of this server carries (a list once sent)."""
    data = diagnostic.data if isinstance(diagnostic.data, dict) else {}
    key = data.get("key")
    return tuple(key) if isinstance(key, (list, tuple)) else None


def _ours(diagnostic: types.Diagnostic) -> bool:
    """Whether a diagnostic is one this server published (with its finding's key
    and fix): the client sends back what it holds, which may be another version's."""
    data = diagnostic.data
    if diagnostic.source != NAME or not isinstance(data, dict):
        return False
    key, fix = data.get("key"), data.get("fix")
    return (
        isinstance(key, (list, tuple))
        and len(key) == 3
        and isinstance(key[0], str)
        and (fix is None or isinstance(fix, dict))
    )


def _wants(only: Sequence[str] | None, kind: str, *, explicit: bool = False) -> bool:
    """Whether a code action request that asks for ``only`` kinds wants ``kind``
    (source actions only when asked for: clients list them in their menus)."""
    if only is None:
        return not explicit
    return any(kind == k or kind.startswith(f"{k}.") for k in only)


def _contains(range_: types.Range, position: types.Position) -> bool:
    start, end = range_.start, range_.end
    after_start = (position.line, position.character) >= (start.line, start.character)
    return after_start and (position.line, position.character) <= (end.line, end.character)


# -- the server --------------------------------------------------------------------------


def build(linting: Linting | None = None) -> UsdRenderLintServer:
    server = UsdRenderLintServer(linting)
    _serve_lifecycle(server)
    _serve_documents(server)
    _serve_actions(server)
    return server


def editor_timeout(options: dict[str, Any], default: float | None) -> float | None:
    """initializationOptions ``timeout``, read as ``check --timeout``: seconds,
    0 for no limit; anything else leaves ``default``."""
    timeout = options.get("timeout")
    if isinstance(timeout, bool) or not isinstance(timeout, int | float) or timeout < 0:
        return default
    return float(timeout) if timeout > 0 else None


def _serve_lifecycle(server: UsdRenderLintServer) -> None:
    @server.feature(types.INITIALIZE)
    def initialize(ls: UsdRenderLintServer, params: types.InitializeParams) -> None:
        ls.client_initialized = True
        options = params.initialization_options
        options = options if isinstance(options, dict) else {}
        ls.timeout = editor_timeout(options, ls.timeout)
        if "configuration" in options:
            ls.linting.configuration = editor_configuration(options)

    @server.feature(types.INITIALIZED)
    def initialized(ls: UsdRenderLintServer, params: types.InitializedParams) -> None:
        watch_client(ls)
        capabilities = ls.client_capabilities.workspace
        watched = capabilities.did_change_watched_files if capabilities else None
        if watched is not None and watched.dynamic_registration:
            patterns = [f"**/*{CONFIG_SUFFIX}", "**/*.usd*"]
            options = types.DidChangeWatchedFilesRegistrationOptions(
                watchers=[types.FileSystemWatcher(glob_pattern=p) for p in patterns]
            )
            registration = types.Registration(
                id=f"{NAME}-files",
                method=types.WORKSPACE_DID_CHANGE_WATCHED_FILES,
                register_options=options,
            )
            ls.client_register_capability(types.RegistrationParams([registration]))
        ls.spawn(start(ls))

    async def start(ls: UsdRenderLintServer) -> None:
        await ls.start_linting()
        for uri in ls.open_uris():
            ls.spawn(ls.lint(uri))

    @server.feature(types.SHUTDOWN)
    def shutdown(ls: UsdRenderLintServer, params: Any) -> None:
        ls.shut_down = True
        ls.close()

    @server.feature(types.EXIT)
    def exit_(ls: UsdRenderLintServer, params: Any) -> None:
        # pygls ends its loop with the status and then swallows it (serve says it).
        ls.exit_status = 0 if ls.shut_down else 1


def _serve_documents(server: UsdRenderLintServer) -> None:
    @server.feature(types.TEXT_DOCUMENT_DID_OPEN)
    def did_open(ls: UsdRenderLintServer, params: types.DidOpenTextDocumentParams) -> None:
        if ls.ready.is_set():
            ls.spawn(ls.lint(params.text_document.uri))

    @server.feature(types.TEXT_DOCUMENT_DID_CHANGE)
    def did_change(ls: UsdRenderLintServer, params: types.DidChangeTextDocumentParams) -> None:
        if ls.ready.is_set():
            ls.spawn(ls.lint(params.text_document.uri))

    @server.feature(types.TEXT_DOCUMENT_DID_SAVE)
    def did_save(ls: UsdRenderLintServer, params: types.DidSaveTextDocumentParams) -> None:
        path = fs_path(params.text_document.uri) or ""
        if path.endswith(CONFIG_SUFFIX):
            ls.spawn(ls.files_changed([path]))
        elif ls.ready.is_set():
            ls.spawn(ls.lint(params.text_document.uri))

    @server.feature(types.TEXT_DOCUMENT_DID_CLOSE)
    def did_close(ls: UsdRenderLintServer, params: types.DidCloseTextDocumentParams) -> None:
        ls.forget(params.text_document.uri)

    @server.feature(types.WORKSPACE_DID_CHANGE_WATCHED_FILES)
    def watched(ls: UsdRenderLintServer, params: types.DidChangeWatchedFilesParams) -> None:
        ls.spawn(ls.files_changed([fs_path(change.uri) or "" for change in params.changes]))

    @server.feature(types.WORKSPACE_DID_CHANGE_CONFIGURATION)
    async def settings_changed(
        ls: UsdRenderLintServer, params: types.DidChangeConfigurationParams
    ) -> None:
        ls.settings_changed(params.settings)


def editor_configuration(options: dict[str, Any]) -> str | dict[str, Any] | None:
    """The editor's ``configuration`` option: a configuration file's path (``~``
    expands), which every document is linted with, or a table of settings laid
    over each one's nearest (as --config FILE and --config 'KEY = VALUE'); a bad
    table is each lint's one error. Anything else: none."""
    configuration = options.get("configuration")
    if isinstance(configuration, str) and configuration:
        return os.path.expanduser(configuration)
    return configuration if isinstance(configuration, dict) else None


def _serve_actions(server: UsdRenderLintServer) -> None:
    @server.feature(
        types.TEXT_DOCUMENT_CODE_ACTION,
        types.CodeActionOptions(
            code_action_kinds=[types.CodeActionKind.QuickFix, FIX_ALL], resolve_provider=True
        ),
    )
    async def code_action(
        ls: UsdRenderLintServer, params: types.CodeActionParams
    ) -> list[types.CodeAction]:
        return await ls.code_actions(params)

    @server.feature(types.CODE_ACTION_RESOLVE)
    async def code_action_resolve(
        ls: UsdRenderLintServer, params: types.CodeAction
    ) -> types.CodeAction:
        return await ls.resolve_code_action(params)

    @server.feature(types.TEXT_DOCUMENT_HOVER)
    def hover(ls: UsdRenderLintServer, params: types.HoverParams) -> types.Hover | None:
        return ls.hover(params)


def watch_client(server: UsdRenderLintServer) -> None:
    """End the server when the client's process (initialize's processId) is
    gone without closing the connection (the protocol asks servers to)."""
    pid = server.process_id
    if not pid:
        return

    def watch() -> None:
        while True:
            time.sleep(PARENT_POLL)
            try:
                os.kill(pid, 0)
            except ProcessLookupError:
                server.close()
                # The protocol loop waits in a read no one will answer.
                os._exit(0)
            except PermissionError:
                pass  # alive, as another user

    threading.Thread(target=watch, name="usdrender-lint-client-watch", daemon=True).start()


def serve() -> None:
    log = logging.StreamHandler()
    log.setFormatter(OneLine())
    logging.getLogger("pygls").addHandler(log)
    logging.getLogger("pygls").propagate = False
    server = build()
    try:
        server.start_io()
    finally:
        server.close()
    if server.exit_status:
        raise SystemExit(server.exit_status)


__all__ = ["Edit", "build", "serve"]
