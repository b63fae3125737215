"""The layers fixes edit: as read from disk, and as the accepted fixes left them.

Each layer of the stage's own layer stack is read once when fixing starts: its
bytes (to write over them only if they are unchanged), its text (a ``.usda``
or text ``.usd``: the text every later edit is spliced into) and Sdf's export
of it (what the next fix's change is measured against). After a fix, the
layers it touched are either committed (a text layer gets the minimal text
edit of :mod:`.text_edits`) or put back as they were before it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping

from pxr import Sdf, Usd

from ..layers.files import layer_identifier, layer_real_path
from ..layers.writing import DiskState, write_problem
from ..paths import display_path, layer_file
from ..records import record
from .text_edits import CannotEdit, canonical, edit_text


@record
class LayerSource:
    """One layer's file and its state for fixing."""

    layer: Sdf.Layer
    #: The file as read when fixing started (None: not a readable file).
    disk: DiskState | None
    #: Sdf's export of the layer as the accepted fixes left it.
    canonical: str
    #: A text layer's text, as the accepted fixes left it (None: a crate file).
    text: str | None
    #: Why it may not be written (None: it may).
    problem: str | None
    #: The text as read (None: a crate file).
    original_text: str | None = None
    #: Whether the text was checked to be what USD read.
    verified: bool = False
    #: Sdf's export of the layer as read.
    original_canonical: str = ""

    def __post_init__(self) -> None:
        self.original_canonical = self.original_canonical or self.canonical

    @property
    def changed(self) -> bool:
        """Whether the accepted fixes changed it (a fix tried and undone does not)."""
        if self.text is not None:
            return self.text != self.original_text
        return self.canonical != self.original_canonical


class Sources:
    """The editable layers of one stage. ``in_memory`` (--fix-to): nothing is
    written, so any layer may change in memory and no text is kept."""

    def __init__(
        self,
        stage: Usd.Stage,
        *,
        in_memory: bool = False,
        texts: Mapping[str, str] | None = None,
        texts_only: bool = False,
        writing: bool = True,
        excluded: Callable[[str], bool] | None = None,
    ) -> None:
        self.stage = stage
        self.in_memory = in_memory
        #: Layers' unsaved text in an editor, by real path: edited instead of the file.
        self.texts = texts or {}
        #: Only those texts may change (FixOptions.texts_only).
        self.texts_only = texts_only
        #: False for --diff: a read-only file may still be shown as a patch.
        self.writing = writing
        #: FixOptions.excluded.
        self.excluded = excluded
        self.known: dict[str, LayerSource] = {}
        for layer in stage.GetLayerStack(includeSessionLayers=False):
            self.known[layer_identifier(layer)] = self._read(layer)

    def _read(self, layer: Sdf.Layer) -> LayerSource:
        exported = layer.ExportToString()
        if self.in_memory:
            return LayerSource(layer, None, exported, None, None)
        unsaved = self.texts.get(layer_real_path(layer))
        if unsaved is not None:
            # The editor's buffer: its text is what fixes edit, and nothing is written.
            return LayerSource(layer, None, exported, unsaved, None, unsaved)
        if self.texts_only:
            shown = display_path(layer_real_path(layer) or layer.identifier)
            why = f"{shown} is a file, and fixes of standard input's text write no file"
            return LayerSource(layer, None, exported, None, why)
        problem = write_problem(layer, self.writing) or self._excluded(layer)
        disk = None
        text = None
        if layer_real_path(layer) and problem is None:
            try:
                disk = DiskState.read(layer_real_path(layer))
            except OSError as exc:
                problem = (
                    f"{display_path(layer_real_path(layer))} cannot be read: {exc.strerror or exc}"
                )
        if disk is not None and not disk.is_crate:
            try:
                text = disk.data.decode("utf-8")
            except UnicodeDecodeError:
                problem = f"{display_path(disk.path)} is not UTF-8 text"
        return LayerSource(layer, disk, exported, text, problem, text)

    def _excluded(self, layer: Sdf.Layer) -> str | None:
        return excluded_reason(self.stage, layer, self.excluded)

    def __iter__(self):
        return iter(self.known.values())

    def get(self, layer: Sdf.Layer) -> LayerSource | None:
        return self.known.get(layer_identifier(layer))

    def problem(self, layer: Sdf.Layer) -> str | None:
        """Why fixes may not edit ``layer`` (None: they may). A text layer whose
        text is no longer what USD read is not edited."""
        source = self.get(layer)
        if source is None:
            return None if self.in_memory else "it is outside the stage's layer stack"
        if source.problem is None and source.text is not None and not source.verified:
            source.verified = True
            if canonical(source.text) != source.canonical:
                source.problem = f"{_shown(layer)} changed on disk after USD read it"
        return source.problem

    def commit(self, touched: Iterable[Sdf.Layer]) -> str | None:
        """Accept what a fix did to ``touched``: a text layer gets the edit into its
        text. Returns why it cannot be accepted (the caller rolls back)."""
        pending: list[tuple[LayerSource, str | None, str]] = []
        for layer in touched:
            source = self.get(layer)
            after = layer.ExportToString()
            if source is None:
                pending.append((LayerSource(layer, None, after, None, None), None, after))
                continue
            if after == source.canonical:
                continue
            text: str | None = None
            if source.text is not None:
                try:
                    text = edit_text(source.text, source.canonical, after)
                except CannotEdit as exc:
                    return f"the change cannot be written as a text edit of {_shown(layer)}: {exc}"
            pending.append((source, text, after))
        if not pending:
            return "the fix changed nothing"
        for source, text, after in pending:
            source.canonical = after
            if text is not None:
                source.text = text
            self.known.setdefault(layer_identifier(source.layer), source)
        return None

    def checkpoint(self) -> dict[str, tuple[LayerSource, str, str | None]]:
        """The state of every known layer, for :meth:`back_to`."""
        return {key: (s, s.canonical, s.text) for key, s in self.known.items()}

    def back_to(self, checkpoint: dict, touched: Iterable[Sdf.Layer]) -> None:
        """Undo everything since ``checkpoint`` (a fix committed, then rejected)."""
        self.known = {key: source for key, (source, _, _) in checkpoint.items()}
        for source, exported, text in checkpoint.values():
            source.canonical, source.text = exported, text
        self.rollback(touched)

    def rollback(self, touched: Iterable[Sdf.Layer]) -> None:
        """Put every layer in ``touched`` back as the accepted fixes left it."""
        session = self.stage.GetSessionLayer()
        for layer in touched:
            source = self.get(layer)
            if source is not None:
                restore(layer, source.canonical)
            elif layer == session:
                layer.Clear()
            elif layer_real_path(layer) and not layer.anonymous:
                layer.Reload(True)

    def discard(self) -> None:
        """Forget in-memory edits: a later open of a layer in this process must
        read its file, not the registry's edited copy."""
        self.stage.GetSessionLayer().Clear()  # in memory, fixes may override from there
        for layer in self.stage.GetUsedLayers():
            # A package's member (pkg.usdz[inner.usda]) is read from the package's file.
            file = layer_file(layer_real_path(layer))
            if layer.dirty and not layer.anonymous and file is not None and file.is_file():
                layer.Reload(True)


def restore(layer: Sdf.Layer, text: str) -> None:
    """Make ``layer``'s content what Sdf's export ``text`` describes."""
    copy = Sdf.Layer.CreateAnonymous(".usda")
    copy.ImportFromString(text)
    layer.TransferContent(copy)


def _shown(layer: Sdf.Layer) -> str:
    return display_path(layer_real_path(layer) or layer_identifier(layer))


def excluded_reason(
    stage: Usd.Stage, layer: Sdf.Layer, excluded: Callable[[str], bool] | None
) -> str | None:
    """Why fixes leave alone a layer the stage composes that the configuration
    leaves out of linting (the root was named: it is fixed)."""
    path = layer_real_path(layer)
    if excluded is None or layer == stage.GetRootLayer() or not path:
        return None
    if not excluded(path):
        return None
    return (
        f"{display_path(path)} is left out of linting by the configuration (exclude, "
        "extend-exclude or .gitignore), so --fix leaves it alone; fix it where it is linted"
    )
