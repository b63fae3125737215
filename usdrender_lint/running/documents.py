"""The editor's documents as USD sees them, linted as ``check`` lints the file.

Each open document is a layer whose identifier is the document's own path
(``Sdf.Layer.New`` with that identifier, or the layer already open under it),
filled with the editor's unsaved text by ``ImportFromString``. USD resolves a
layer's relative asset paths against its identifier
(``SdfComputeAssetPathRelativeToLayer``), so ``@./shot_cam.usda@`` in the
buffer reaches the file beside the document exactly as it would from the saved
file, and every stage that opens the path (the document's own, or one of
another open document that references it) finds this layer in USD's layer
registry: unsaved documents compose with each other and with the files on disk.

A lint goes through the pipeline's own pieces: the configuration found from the
document's folder (:func:`~usdrender_lint.running.pipeline.prepare`, as
``check`` finds it), the linter it builds, and the report's per-path ignores
(``Prepared.finish``). Fixes go through the fixer ``--fix`` uses, editing the
buffers' text instead of the files. Nothing here knows the protocol: the language
server's worker process (``server/worker.py``) serves it, ``check -`` lints
standard input's text with it (``standard_input.py``), and the benchmark drives it
in-process.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Mapping
from contextlib import suppress
from typing import TYPE_CHECKING, Any

from pxr import Ar, Pcp, Sdf, Tf, Usd, Vt

from ..config import (
    FileState,
    Stamps,
    config_candidates,
    file_state,
    is_racy,
    stamped_read,
    stamps_hold,
    unchanged,
)
from ..engine import register_plugins
from ..engine.linter import open_failure_findings
from ..engine.stage import (
    EMPTY_FILE,
    STAGE_OPEN_FAILED_CODE,
    STAGE_OPEN_FAILED_NAME,
    error_lines,
    open_stage,
)
from ..layers.crate import is_crate
from ..layers.files import layer_identifier, layer_real_path
from ..layers.nesting import nesting_problem
from ..model import IGNORE_KEY, Finding, Location, Report, Severity
from ..paths import usd_path
from ..records import record
from ..registry import Registry, build_registry
from .discovery import Exclusions, force_excluded
from .pipeline import (
    Prepared,
    Request,
    RequestError,
    excluded_from_linting,
    folder_exclusions,
    prepare,
)
from .roots import file_key

if TYPE_CHECKING:
    from ..fixing import FixRun

#: (code, object path, message): how a quick fix names the finding it fixes.
FindingKey = tuple[str, str | None, str]


def finding_key(finding: Finding) -> FindingKey:
    return (finding.code, finding.location.path, finding.message)


@record(frozen=True)
class Linted:
    """One document's lint: its findings (in any layer), or why it could not
    be linted at all (a configuration error)."""

    findings: tuple[Finding, ...] = ()
    error: str | None = None
    seconds: float = 0.0
    #: The files of the layers its stage composed (an edit to any of them, open
    #: or closed, can change its findings).
    layers: frozenset[str] = frozenset()
    #: Whether its fixes may be made: not under a configuration that sets
    #: ``variants``, which ``check --fix`` refuses (see :meth:`Documents.fix`).
    fixes: bool = True


@record
class _Config:
    prepared: Prepared
    #: The state (config.file_state) of the configuration files read (those it extends
    #: too) and of those the search for one looked at, when they were read.
    stamps: Stamps


class Documents:
    """The open documents (by absolute path) and their layers. ``prepared``: the
    one preparation every document is linted with (``check -``), instead of each
    folder's own configuration."""

    def __init__(
        self,
        registry: Registry | None = None,
        prepared: Prepared | None = None,
        configuration: str | Mapping[str, Any] | None = None,
    ) -> None:
        register_plugins()  # before a document's first USD call (engine/plugins.py)
        self._registry = prepared.registry if prepared is not None else registry
        self._prepared = prepared
        #: The editor's ``configuration``: a file every document is linted with, or
        #: settings laid over each one's nearest (as ``--config`` gives either).
        self._configuration = configuration
        self.texts: dict[str, str] = {}
        self._layers: dict[str, Sdf.Layer] = {}
        #: The text each layer holds now (a fix or a reload makes it stale).
        self._imported: dict[str, str] = {}
        #: USD's error lines about a document's text it cannot read (its layer keeps
        #: the last good text).
        self._parse_errors: dict[str, tuple[str, ...]] = {}
        self._stages: dict[str, Usd.Stage] = {}
        self._configs: dict[str, _Config] = {}
        #: Each layer file's state when a lint last looked at it (config.file_state).
        self._file_states: dict[str, FileState] = {}
        #: The layers a stage opened for an open document's file by another path
        #: (one of the two through a symbolic link), by that path: USD keeps a
        #: layer per path as the asset path gives it, not per file (the layer
        #: registry's lookup, pxr/usd/sdf/layerRegistry.cpp), so the stage
        #: composed the file, never the document's unsaved text. Each holds
        #: the document's text too: (the document's path, the layer).
        self._aliases: dict[str, tuple[str, Sdf.Layer]] = {}
        #: The text each of those layers holds now.
        self._alias_texts: dict[str, str] = {}
        #: Each composed layer's file (roots.file_key), by its path: found once
        #: (a stage may compose thousands, each lint; on a network share each
        #: costs a lookup per folder), again once a document opens or closes.
        self._file_keys: dict[str, str] = {}

    @property
    def registry(self) -> Registry:
        if self._registry is None:
            self._registry = build_registry()
        return self._registry

    # -- the editor's state -------------------------------------------------------------

    def update(self, texts: dict[str, str | None]) -> None:
        """Set the text of documents; None closes one (its layer is the file's again),
        and so does the text an editor shows for a binary ``.usd`` (it is linted
        from its file, as ``check`` lints it)."""
        if any((text is None) == (path in self.texts) for path, text in texts.items()):
            self._file_keys.clear()  # a symlink may have moved since
        for path, text in texts.items():
            if text is not None and not _shows_a_crate(path, text):
                self.texts[path] = text
                continue
            self.texts.pop(path, None)
            for alias, (document, held) in list(self._aliases.items()):
                if document == path:  # the file's text again, for the stages holding it
                    del self._aliases[alias]
                    self._alias_texts.pop(alias, None)
                    with Tf.DiagnosticTrap() as trap:
                        with suppress(Tf.ErrorException):
                            held.Reload(True)
                        trap.Clear()
            self._imported.pop(path, None)
            self._parse_errors.pop(path, None)
            self._stages.pop(path, None)
            layer = self._layers.pop(path, None)
            if layer is None or layer.expired:
                continue
            reloaded = False
            if os.path.isfile(path):
                with Tf.DiagnosticTrap() as trap:
                    try:
                        reloaded = layer.Reload(True)  # a stage still holding it sees the file
                    except Tf.ErrorException:
                        layer.Clear()
                        reloaded = True
                    trap.Clear()
            if not reloaded:
                # A layer made for the text (its file held another, or none):
                # USD reloads no file into it, and the stages that held it went
                # on composing the closed document's unsaved text. They go, and
                # with them the layer: the next stages read the file.
                self._stages = {
                    other: stage
                    for other, stage in self._stages.items()
                    if layer not in stage.GetUsedLayers()
                }

    def forget_configuration(self) -> None:
        """A configuration file changed: read the configuration again."""
        self._configs.clear()

    # -- linting ------------------------------------------------------------------------

    def lint(self, path: str) -> Linted:
        """Lint the document at ``path`` as ``check`` lints it (no --fail-on)."""
        started = time.perf_counter()
        # A stage opened by this lint reads its layers from now on (_reload_files).
        began = time.time_ns()
        try:
            prepared = self._prepare(path)
            excluded = _excluded(prepared, path)  # reads the configurations above it too
        except RequestError as exc:
            return Linted(error=str(exc))
        if excluded:
            return Linted(seconds=time.perf_counter() - started)
        self._sync()
        parse_error = self._parse_errors.get(path)
        if parse_error is not None:
            severity = prepared.linter.severities.get(STAGE_OPEN_FAILED_CODE, Severity.ERROR)
            findings = tuple(open_failure_findings(path, parse_error, severity, self.texts))
        else:
            findings = self._lint_stage(prepared, path, began)
        return Linted(
            findings,
            seconds=time.perf_counter() - started,
            layers=self._layers_of(path),
            fixes=not prepared.settings.variants,
        )

    def _layers_of(self, path: str) -> frozenset[str]:
        stage = self._stages.get(path)
        if stage is None:
            return frozenset()
        return frozenset(filter(None, map(layer_real_path, stage.GetUsedLayers())))

    def _lint_stage(self, prepared: Prepared, path: str, began: int) -> tuple[Finding, ...]:
        stage = self._stages.get(path)
        if stage is not None:
            lost = self._lost_files(stage)
            if lost:
                # USD keeps the layer it read while a stage holds it: every stage
                # that composed the file goes, and a new one finds it missing (ST002).
                self._stages = {
                    other: held
                    for other, held in self._stages.items()
                    if not lost & set(map(layer_real_path, held.GetUsedLayers()))
                }
                stage = None
            elif _misses_files(stage):
                stage = None  # the file may be there now: only a new stage looks
        if stage is None:
            stage = open_stage(path).stage
        if stage is None:
            # The engine says why (a sublayer USD cannot read, ...), as check does.
            result = prepared.linter.lint_path(path, full_composition=True)
        else:
            self._stages[path] = stage
            self._reload_files(stage, began)
            # A document's text may add a sublayer that is another's by another
            # path in turn: each round shares at least one text, or ends.
            for _ in range(len(self.texts) + 1):
                if not self._share_texts(stage):
                    break
            texts = self._layer_texts()
            combinations = prepared.spec.variant_combinations
            if combinations is None:
                result = prepared.linter.run_stage(stage, path, texts=texts).result
            else:  # config `variants`: other selections too, as check lints them
                from ..engine.variants import VariantExplorer

                explorer = VariantExplorer(prepared.linter, combinations)
                result = explorer.run_stage(stage, path, texts=texts).result
        if result.status != "linted":
            location = Location(path, None, path)
            message = result.error or "the document could not be linted"
            failed = Finding(
                STAGE_OPEN_FAILED_CODE, STAGE_OPEN_FAILED_NAME, Severity.ERROR, message, location
            )
            return (failed,)
        return prepared.finish(Report((result,))).findings

    def _share_texts(self, stage: Usd.Stage) -> bool:
        """Give the layers the stage opened for an open document's file by
        another path the document's text; True when one took a new text."""
        if not self.texts:
            return False
        documents = {self._file_key(path): path for path in self.texts}
        shared = False
        for layer in stage.GetUsedLayers():
            if not _own_file(layer):
                continue
            real = layer_real_path(layer)
            if not real or real in self.texts:
                continue
            if real in self._aliases:
                document: str | None = self._aliases[real][0]
            else:
                document = documents.get(self._file_key(real))
            if document is None:
                continue
            self._aliases[real] = (document, layer)
            shared = self._import_alias(real) or shared
        return shared

    def _layer_texts(self) -> dict[str, str]:
        """The unsaved text of each layer by its path: the documents', and the
        layers that hold one's text by another path (``_aliases``)."""
        aliases = {alias: self.texts.get(doc) for alias, (doc, _) in self._aliases.items()}
        return {**{a: t for a, t in aliases.items() if t is not None}, **self.texts}

    def _file_key(self, path: str) -> str:
        key = self._file_keys.get(path)
        if key is None:
            key = self._file_keys[path] = file_key(path)
        return key

    def _import_alias(self, alias: str) -> bool:
        """Import its document's text into the layer of ``alias`` (see
        ``_aliases``) unless it holds it; True when it did. A text USD cannot
        parse leaves the layer as it was: the document's own lint says why."""
        document, layer = self._aliases[alias]
        text = self.texts.get(document)
        if text is None or self._alias_texts.get(alias) is text:
            return False
        with Tf.DiagnosticTrap() as trap:
            with suppress(Tf.ErrorException):
                layer.ImportFromString(text)
            trap.Clear()
        self._alias_texts[alias] = text
        return True

    def _lost_files(self, stage: Usd.Stage) -> set[str]:
        """The files of the layers the stage composed that are gone from disk
        (deleted, or renamed) and are no open document."""
        lost = set()
        for layer in stage.GetUsedLayers():
            if not _own_file(layer):
                continue
            real = layer_real_path(layer)
            if real and real not in self.texts and not os.path.exists(real):
                lost.add(real)
        return lost

    def _reload_files(self, stage: Usd.Stage, began: int) -> None:
        """Read again the layers on disk whose files changed since USD read them.
        A reload without force compares the file's modification time alone
        (SdfLayer::_Reload, pxr/usd/sdf/layer.cpp), so a file rewritten with its
        time kept (set back, or within one tick of a coarse clock) would keep
        its old content: a file whose size, change time or inode changed since
        the last lint is read again whatever its time says. A stamp taken within
        a clock tick of the file's change cannot prove that (config.stat_state):
        taken here, before the reload, it carries the file's digest; a layer
        first seen was read as its stage opened, before it, so one changed
        within a tick of this lint's start is read again."""
        for layer in stage.GetUsedLayers():
            real = layer_real_path(layer)
            if layer.anonymous or layer.dirty or real in self.texts or real in self._aliases:
                continue
            force = False
            if real is not None:
                state = file_state(real)
                if real in self._file_states:
                    force = not unchanged(real, self._file_states[real], state)
                else:
                    force = is_racy(file_state(real, read_ns=began))
                self._file_states[real] = state
            # Gone or unreadable: the composition reports it.
            with Tf.DiagnosticTrap() as trap:
                with suppress(Tf.ErrorException):
                    layer.Reload(force)
                trap.Clear()

    def _prepare(self, path: str) -> Prepared:
        """The pipeline's preparation of a check of ``path``: its configuration
        (searched from its folder), rules and linter; read again when the
        configuration file (or one it extends) changed."""
        if self._prepared is not None:
            return self._prepared
        folder = os.path.dirname(path)
        config = self._configs.get(folder)
        if config is not None and not stamps_hold(config.stamps):
            config = None  # a file changed: the one found, or one it extends
        if config is None:
            given = self._configuration
            request = Request(
                (path,),
                config=given if isinstance(given, str) else None,
                config_overrides=(given,) if isinstance(given, Mapping) else (),
                jobs=1,
                timeout=None,
                progress=False,
            )
            # The files the search looks at and the editor's file are known
            # before the read: stamped before it (config.stamped_read).
            known = (*config_candidates(path), *((given,) if isinstance(given, str) else ()))
            prepared, stamps = stamped_read(
                known, lambda: prepare(request, self.registry), lambda p: p.settings.sources
            )
            config = self._configs[folder] = _Config(prepared, stamps)
        return config.prepared

    # -- layers -------------------------------------------------------------------------

    def _sync(self) -> None:
        """Make every document's layer hold its text (USD recomposes the stages
        that use it from what changed)."""
        for path, text in self.texts.items():
            if self._imported.get(path) is text:
                continue
            # USD's parser overflows on such nesting, reading the file as the text.
            refused = _refused_text(path, text)
            if refused is None:
                too_deep = nesting_problem(path, text.encode("utf-8", "surrogatepass"))
                refused = (too_deep,) if too_deep is not None else None
            if refused is not None:
                self._parse_errors[path] = refused  # its layer keeps the last text
                self._imported[path] = text
                continue
            layer = self._layers.get(path)
            made = False
            if layer is None:
                # Find gives a weak handle: FindOrOpen holds a layer already open (a
                # stage of another document opened it from its file) for good.
                known = Sdf.Layer.Find(usd_path(path)) and Sdf.Layer.FindOrOpen(usd_path(path))
                layer = known or _saved_layer(path, text)
                if layer is not None and known is None:  # its file holds the same text
                    self._layers[path] = layer
                    self._parse_errors.pop(path, None)
                    self._imported[path] = text
                    continue
                made = layer is None
                usda = Sdf.FileFormat.FindById("usda")
                layer = self._layers[path] = layer or Sdf.Layer.New(usda, usd_path(path))
            with Tf.DiagnosticTrap() as trap:
                try:
                    layer.ImportFromString(text)
                    self._parse_errors.pop(path, None)
                except Tf.ErrorException as exc:
                    self._parse_errors[path] = _parse_error(exc, path)
                    if made:
                        # An empty layer of the file's name would stand in for the
                        # file in the other documents' stages, which then compose
                        # nothing where check fails to read it: let it go.
                        del self._layers[path]
                trap.Clear()
            self._imported[path] = text
        for alias in self._aliases:
            self._import_alias(alias)

    # -- edits --------------------------------------------------------------------------

    def fixes(
        self, path: str, target: FindingKey | None, unsafe: bool
    ) -> dict[str, tuple[str, str]]:
        """The text of each layer before and after the fixes ``--fix`` would
        apply to the document's stage (``unsafe``: ``--unsafe-fixes`` too), by
        real path; only the fix of the finding ``target`` when given. Only the
        layers that change (a document's buffer, or a file of its layer stack)."""
        return self.fix(path, target, unsafe)[1]

    def fix(
        self, path: str, target: FindingKey | None, unsafe: bool, *, texts_only: bool = False
    ) -> tuple[FixRun, dict[str, tuple[str, str]]]:
        """:meth:`fixes`, with what the fixer did (each fix applied or not, and
        why); ``texts_only``: only the documents' texts change (``check -``)."""
        from ..fixing import FixOptions, FixRun
        from ..fixing.session import StageFixer

        prepared = self._prepare(path)
        # check --fix refuses a configuration that sets variants (its fixes would
        # be made under the current selections only), and so do the validation
        # plugins (running/stage_lints.CheckLinters.fixable): the editor too.
        if _excluded(prepared, path) or prepared.settings.variants:
            return FixRun(), {}
        self._sync()
        if path in self._parse_errors:
            return FixRun(), {}
        keep: Callable[[Finding], bool] = prepared.is_reported
        if target is not None:

            def keep(finding: Finding) -> bool:
                return finding_key(finding) == target and prepared.is_reported(finding)

        options = FixOptions(
            unsafe=unsafe,
            write=False,
            texts=self._layer_texts(),
            texts_only=texts_only,
            excluded=excluded_from_linting(prepared),
        )
        fixer = StageFixer(prepared.linter, path, options, keep)
        dirty = {p: layer.dirty for p, layer in self._layers.items()}
        try:
            fixer.run()
        finally:
            # The fixer puts the layers it edited back as their files hold them, and
            # reads again every layer with unsaved edits its stage used: those
            # documents' layers get their text again before the next lint.
            edited = {layer_real_path(x.layer) for x in fixer.sources or ()}
            for p, layer in self._layers.items():
                if p in edited or layer.dirty != dirty[p]:
                    self._imported.pop(p, None)
            self._alias_texts.clear()  # as read again: the next sync imports them
        changed = {}
        for source in fixer.sources or ():
            if source.changed and source.text is not None and source.original_text is not None:
                changed[layer_real_path(source.layer)] = (source.original_text, source.text)
        return fixer.result, changed

    def suppress(self, path: str, code: str, object_path: str) -> str | None:
        """The document's text with ``code`` added to the customData suppression
        of the prim of ``object_path`` (None where it cannot be written)."""
        from ..engine.suppress import ignore_entries
        from ..fixing.text_edits import CannotEdit, edit_text

        self._sync()
        stage = self._stages.get(path)
        layer = self._layers.get(path)
        text = self.texts.get(path)
        if stage is None or layer is None or text is None or path in self._parse_errors:
            return None
        if not Sdf.Path.IsValidPathString(object_path):
            return None
        if not any(rule.code == code for rule in self.registry.rules):
            return None  # UL000 (a rule that raised) is no rule a suppression names
        prim_path = Sdf.Path(object_path).GetPrimPath()
        prim = stage.GetPrimAtPath(prim_path)
        entries = ignore_entries(prim) if prim else None
        if entries is None or code in entries:
            return None  # no such prim, or a malformed suppression the user must mend
        dictionary, _, key = IGNORE_KEY.partition(":")
        before = layer.ExportToString()
        try:
            spec = layer.GetPrimAtPath(prim_path) or Sdf.CreatePrimInLayer(layer, prim_path)
            data = dict(spec.customData)
            ours = dict(data.get(dictionary) or {})
            ours[key] = Vt.StringArray([*entries, code])
            data[dictionary] = ours
            spec.SetInfo("customData", data)
            after = layer.ExportToString()
        finally:
            self._imported.pop(path, None)  # the next lint imports the text again
        try:
            return edit_text(text, before, after)
        except CannotEdit:
            return None


def _misses_files(stage: Usd.Stage) -> bool:
    """Whether the stage's composition could not find a sublayer, reference or
    payload (USD looks for it only when a stage is opened)."""
    missing = (Pcp.ErrorInvalidSublayerPath, Pcp.ErrorInvalidAssetPath)
    return any(isinstance(error, missing) for error in stage.GetCompositionErrors())


def _excluded(prepared: Prepared, path: str) -> bool:
    """Config ``force-exclude``: a document ``check .`` would skip is neither
    linted nor fixed (the same as ``check --force-exclude -`` of its text)."""
    return force_excluded(path, Exclusions.of(prepared.settings), folder_exclusions(prepared))


def _own_file(layer: Sdf.Layer) -> bool:
    """Whether the layer is a file of its own: not anonymous, not in a package."""
    return not layer.anonymous and not Ar.IsPackageRelativePath(
        usd_path(layer_identifier(layer))  # a name that is not UTF-8 goes as its bytes
    )


def _saved_layer(path: str, text: str) -> Sdf.Layer | None:
    """The layer of a ``.usda`` whose file holds ``text``, opened from the file.
    USD reads a file several times faster than it imports the same text into a
    layer (``ImportFromString`` applies the content spec by spec: 3.4 s of CPU
    against 0.6 s for a 100k-prim document, and the stage then composes in 1.3 s
    against 0.7 s), and a document is usually opened as saved."""
    if not path.endswith(".usda"):
        return None  # a text .usd opens with the usd format, which finds no lines
    try:
        with open(path, encoding="utf-8", newline="") as handle:
            if handle.read() != text:
                return None
    except (OSError, UnicodeDecodeError):
        return None
    with Tf.DiagnosticTrap() as trap:
        try:
            layer = Sdf.Layer.FindOrOpen(usd_path(path))
        except Tf.ErrorException:
            layer = None  # the import below reports USD's error
        trap.Clear()
    return layer


#: The bytes a text layer starts with; USD refuses a file without them before its
#: parser runs (``SdfUsdaFileFormat::_ReadFromAsset``, pxr/usd/sdf/usdaFileFormat.cpp),
#: where ``ImportFromString`` parses any text, or accepts one.
USDA_COOKIE = "#usda"
#: Why the same function refuses a file that starts with a byte-order mark.
USDA_BOM = (
    "Asset starts with UTF-8 BOM which is not supported, please convert the file to UTF-8 "
    "without the BOM."
)


def _shows_a_crate(path: str, text: str) -> bool:
    """Whether ``text`` is an editor's view of the binary crate at ``path``: a
    ``.usd`` file may be either format, and a crate's bytes decoded as text are
    no layer (USD refused them, where ``check`` reads the file)."""
    return path.lower().endswith(".usd") and not text.startswith(USDA_COOKIE) and is_crate(path)


def _refused_text(path: str, text: str) -> tuple[str, ...] | None:
    """USD's error lines about the file ``path`` holding ``text`` when its format
    check refuses the file (no ``#usda`` first), as ``check`` of the file gets
    them; None when the text goes to the parser."""
    if text.startswith(USDA_COOKIE):
        return None
    failed = f"Failed to open layer @{path}@"  # UsdStage::Open, pxr/usd/usd/stage.cpp
    if not path.lower().endswith(".usda"):
        # .usd: neither the crate nor the text format reads it.
        return (failed,) if text else (EMPTY_FILE,)
    why = f"<{path}> is not a valid usda layer"
    if text.startswith("\ufeff"):
        why += f": {USDA_BOM}"
    return (why, failed)


def _parse_error(exc: Tf.ErrorException, path: str) -> tuple[str, ...]:
    """USD's error lines about a document's text, as it gives them about a file
    (engine.linter.open_failure_findings reads both): a layer imported from a
    string has no file name in USD's message (``:3:3: Expected ...``), so the
    document's path is put there."""
    lines = [f"{path}{line}" if line.startswith(":") else line for line in error_lines(exc, path)]
    return tuple(lines) or (f"USD cannot read {path}",)
