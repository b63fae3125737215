"""Opening a stage: every payload loaded, USD's diagnostics turned into
ST001 findings' messages (``file:line:col`` where USD gives one)."""

from __future__ import annotations

import os
import re
import stat
from collections.abc import Iterable

from pxr import Ar, Sdf, Tf, Usd

from ..api.resolve import USD_NAMESPACE as _NAMESPACE
from ..layers.crate import crate_structure_problem, is_crate
from ..layers.files import NOT_REGULAR, layer_identifier, layer_real_path, lfs_pointer_problem
from ..model import NAMELESS_PROPERTY
from ..paths import display_path, usd_path
from ..records import record
from . import layer_words
from .plugins import register_plugins
from .walks import names_an_empty_variant

STAGE_OPEN_FAILED_CODE = "ST001"
#: Why a file of no bytes that is not named .usda cannot be opened.
EMPTY_FILE = "the file is empty (0 bytes): it holds no USD layer"
STAGE_OPEN_FAILED_NAME = "stage-open-failed"
USD_EXTENSIONS = (".usd", ".usda", ".usdc", ".usdz")


@record(frozen=True)
class StageOpenResult:
    stage: Usd.Stage | None
    #: One line per error USD posted when the stage could not be opened.
    errors: tuple[str, ...] = ()


def open_stage(path: str, session_layer: Sdf.Layer | None = None) -> StageOpenResult:
    """Open a stage with every payload loaded, keeping USD's diagnostics off stderr.
    ``session_layer`` (e.g. the fixer's --fix-to layer) replaces the anonymous one.

    usd-core turns every Tf error posted during ``Open`` into an exception and
    the stage handle is lost (catalog, ST001); its lines carry ``file:line:col``.
    """
    register_plugins()  # its problems are the run's, not this file's ST001
    with Tf.DiagnosticTrap() as trap:
        # Held open for the stage: it reads the layers the check read.
        held: list[Sdf.Layer] = []
        root, corrupt = _checked_root(path, held)
        trap.Clear()
        if corrupt is not None:
            return StageOpenResult(None, (corrupt,))
        try:
            if session_layer is None:
                stage = Usd.Stage.Open(usd_path(path), Usd.Stage.LoadAll)
            else:
                root = root or Sdf.Layer.FindOrOpen(usd_path(path))  # raises USD's error
                stage = Usd.Stage.Open(root, session_layer, Usd.Stage.LoadAll) if root else None
            errors: tuple[str, ...] = ()
        except Tf.ErrorException as exc:
            stage = None
            errors = crate_unreadable(exc, path) or tuple(error_lines(exc, path))
        except Exception as exc:  # noqa: BLE001 - any failure to open is a finding
            stage = None
            errors = (f"{type(exc).__name__}: {exc}",)
        trap.Clear()
    if stage is None and path.lower().endswith(".usdz"):
        problem = _package_problem(path)
        errors = ((problem,) if problem else ()) + errors
    if stage is None:
        pointer = lfs_pointer_problem(path)
        errors = (pointer,) if pointer else errors  # USD's own words do not say it
    if stage is None and _is_empty(path) and not path.lower().endswith(".usda"):
        # USD names no cause for these ("bad arguments to mmap()", "Failed to
        # open layer"); an empty .usda is not a valid text layer, as on stdin.
        errors = (EMPTY_FILE,)
    if stage is None and not errors:
        errors = (f"USD could not open {path}",)
    return StageOpenResult(stage, errors)


def _is_empty(path: str) -> bool:
    try:
        return os.path.getsize(path) == 0 and os.path.isfile(path)
    except OSError:
        return False


def _checked_root(path: str, held: list[Sdf.Layer]) -> tuple[Sdf.Layer | None, str | None]:
    """The root layer of ``path`` (None when Sdf cannot read it: the stage's
    open says why) and :func:`arcs_problem` of it."""
    try:
        root = Sdf.Layer.FindOrOpen(usd_path(path))
        if root is None:
            return None, None
        return root, arcs_problem(root, usd_path(path), held=held)
    except (Tf.ErrorException, UnicodeDecodeError):
        return None, None  # the stage's open reports what it cannot read


def arcs_problem(
    root: Sdf.Layer,
    asset: str | bytes,
    *,
    external: bool = True,
    held: list[Sdf.Layer] | None = None,
) -> str | None:
    """Why a layer ``root`` reaches through sublayers (and, ``external``,
    references and payloads, variants' included) must not be read by USD: a
    crate whose structure claims more than its file holds (minutes and GBs in
    USD's reader, layers/crate.py), checked before Sdf opens it; or None.
    Every path that composes a stage checks so, and answers alike (ST001).
    ``asset``: the root's path as USD takes it (usd_path), for the resolver
    context the stage will have; ``held`` gets the layers read, so that the
    caller's stage does not read them again. An arc to a named pipe or a
    device is refused likewise (:func:`arc_file_problem`): USD's open of it
    would wait forever."""
    if not root.subLayerPaths and (not external or _without_external_arcs(root)):
        return None  # it names no layer: nothing to resolve, no walk of its specs
    context = Ar.GetResolver().CreateDefaultContextForAsset(asset)
    seen = {layer_identifier(root)}
    held = held if held is not None else []
    queue = [root]
    with Ar.ResolverContextBinder(context):
        while queue:
            anchor = queue.pop()
            asset_paths: Iterable[str] = anchor.subLayerPaths
            if external and not _without_external_arcs(anchor) and _safe_to_walk(anchor):
                asset_paths = (*asset_paths, *anchor.GetCompositionAssetDependencies())
            for asset_path in dict.fromkeys(asset_paths):
                problem = arc_file_problem(anchor, asset_path)
                if problem is not None:
                    return problem
                try:
                    layer = Sdf.Layer.FindOrOpenRelativeToLayer(anchor, asset_path)
                except Tf.ErrorException:
                    continue  # the composition reports a layer it cannot read
                if layer is not None and layer_identifier(layer) not in seen:
                    seen.add(layer_identifier(layer))
                    held.append(layer)
                    queue.append(layer)
    return None


def _safe_to_walk(layer: Sdf.Layer) -> bool:
    """Whether Sdf's walk of the layer's specs cannot abort the process
    (engine/walks.py); composing such a layer is safe."""
    return not names_an_empty_variant(layer)


def _without_external_arcs(layer: Sdf.Layer) -> bool:
    """Whether the layer's file provably has no arc (from its bytes, without a
    walk of its specs); never for a layer with unsaved edits (an editor's text)."""
    file = layer_real_path(layer)
    return bool(file) and not layer.dirty and layer_words.without_external_arcs(file)


#: What a layer's file that is not a regular file is, and why USD is not handed it.
_SPECIAL_FILE = "a named pipe or a device, whose open can wait forever"


def arc_file_problem(anchor: Sdf.Layer, asset_path: str) -> str | None:
    """:func:`file_problem` of the file an arc of ``anchor`` names, checked
    before USD opens it."""
    if "`" in asset_path:  # an expression: resolved by the stage alone
        return None
    try:
        file = Sdf.ComputeAssetPathRelativeToLayer(anchor, asset_path)
    except Tf.ErrorException:
        return None
    return file_problem(file) if file else None


def file_problem(file: str) -> str | None:
    """Why USD must not read the layer file ``file`` (one line naming it), or
    None: a corrupt crate (layers/crate.py), or a file that is neither a
    regular file nor a folder (a named pipe, a device), refused as a root is
    (files.NOT_REGULAR). A path that names no file (missing, a package's
    member) is USD's to report."""
    try:
        mode = os.stat(file).st_mode
    except (OSError, ValueError):
        return None
    if stat.S_ISDIR(mode):
        return None
    if not stat.S_ISREG(mode):
        return f"{display_path(file)}: {NOT_REGULAR} ({_SPECIAL_FILE})"
    problem = crate_structure_problem(file)
    return f"{display_path(file)}: {problem}" if problem else None


def _package_problem(path: str) -> str | None:
    """Why a ``.usdz`` is not a package USD reads; USD itself says only
    "Failed to open layer" for these."""
    import zipfile  # only for a .usdz USD could not open

    try:
        with zipfile.ZipFile(path) as archive:
            entries = archive.infolist()
    except (zipfile.BadZipFile, OSError, ValueError):
        return "not a zip archive (a .usdz is an uncompressed zip whose first file is a layer)"
    if not entries:
        return "the .usdz package is empty"
    first = entries[0].filename
    if not first.lower().endswith((".usd", ".usda", ".usdc")):
        return f"the first file in the .usdz package, {first!r}, is not a USD layer"
    return None


def error_lines(exc: Tf.ErrorException, path: str) -> Iterable[str]:
    # USD names the file whole: a line break in its name ends no line of the error.
    names = sorted(
        {name for name in (path, os.path.abspath(path)) if len(f"x{name}x".splitlines()) > 1},
        key=len,
        reverse=True,
    )
    undecodable_said = False
    for arg in exc.args:
        try:
            text = getattr(arg, "commentary", None) or str(arg)
        except UnicodeDecodeError:
            # USD quotes the offending text, and Python cannot decode the quote.
            if undecodable_said:
                continue  # each such error would be told the same way
            undecodable_said = True
            text = _undecodable_error(path)
        text = str(text).strip()
        for number, name in enumerate(names):
            text = text.replace(name, f"\0{number}\0")
        for line in text.splitlines():
            if line.strip():
                # An object's address ("stage @x@ <0x55d1...>") differs from run to run.
                line = re.sub(_ADDRESS, "", line.strip())
                line = re.sub(_PEGTL_EOF, "Expected end of file at", _NAMESPACE.sub("", line))
                for number, name in enumerate(names):
                    line = line.replace(f"\0{number}\0", name)
                yield line


#: (Pattern text: re compiles it at first use, not at every start-up.)
_ADDRESS = r" ?<0x[0-9a-fA-F]+>"
#: The grammar failing on text where the layer should have ended, worded as
#: the parser's other errors are ("Expected } at '...'").
_PEGTL_EOF = r"parse error matching pegtl::internal::eof at"
#: The sources of the usda parser's errors (pxr/usd/sdf).
_TEXT_PARSER = ("textParserHelpers.h", "textFileFormat.cpp", "textFileFormatParser.cpp")
#: Where SdfLayer fails to open a layer file (pxr/usd/sdf/layer.cpp): the
#: source file and the function, as Tf.Error names them.
_LAYER_OPEN = ("layer.cpp", "SdfLayer::_OpenLayerAndUnlockRegistry")
_QUOTED_LAYER = r"@([^@]+)@"
#: The sources of the crate reader's errors: the reader, and the LZ4 and
#: integer decompression it reads the structural sections with.
_CRATE_READER = ("crateFile.cpp", "fastCompression.cpp", "integerCoding.cpp")


def crate_unreadable(exc: Tf.ErrorException, path: str) -> tuple[str, ...]:
    """One fixed line when the crate reader (``pxr/usd/sdf/crateFile.cpp`` and
    the decompression it uses) failed on the structure of a crate, else ().
    What usd-core 26.11 says then differs between runs of one file (it reads
    the sections on several threads and may read a buffer a failed
    decompression left unset), so the finding says that the file is corrupt,
    the same every time, and names the layer when it is not the linted file."""
    crate = None
    for arg in exc.args:
        source = str(getattr(arg, "sourceFileName", "") or "")
        if source.endswith(_CRATE_READER):
            quoted = re.search(_QUOTED_LAYER, str(getattr(arg, "commentary", "") or ""))
            crate = quoted.group(1) if quoted else path
            break
    if crate is None or not is_crate(crate):
        return ()  # e.g. a text file named .usdc: USD's "bootstrap section corrupt" says it
    if os.path.abspath(crate) == os.path.abspath(path):
        return ("USD cannot read the structure of this crate file: the file is corrupt",)
    return (f"USD cannot read the structure of the crate {display_path(crate)}: it is corrupt",)


def corruption(exc: Tf.ErrorException, path: str) -> str | None:
    """The ST001 message for a USD error that says the layer's data is corrupt
    (found only when a value or spec is read), or None for any other error:
    a crate value it cannot unpack ("Corrupt asset", or any error of the crate
    reader, pxr/usd/sdf/crateFile.cpp), a layer opened only for a value (a
    value clip's manifest) that does not parse or is no layer, or a property
    with no name (which no layer parser writes: UsdStage fails a verification
    on it)."""
    for arg in exc.args:
        commentary = str(getattr(arg, "commentary", "") or "")
        source = str(getattr(arg, "sourceFileName", "") or "")
        if "Corrupt asset" in commentary:
            return next(iter(error_lines(exc, path)), commentary)
        if source.endswith("crateFile.cpp"):
            return f"USD cannot read a value of the file: {commentary.strip()}; the file is corrupt"
        if source.endswith(_TEXT_PARSER):
            # A layer USD opens only when a value is read (a value clip's, its
            # manifest) does not parse: the stage cannot be read in full.
            line = next(iter(error_lines(exc, path)), commentary.strip())
            return f"a layer USD reads for a value does not parse: {line}"
        if source.endswith(_LAYER_OPEN[0]) and str(getattr(arg, "sourceFunction", "")).endswith(
            _LAYER_OPEN[1]
        ):
            # Such a layer that is no layer at all (a file of no USD format, a
            # folder): SdfLayer refuses it before any parser reads it.
            line = next(iter(error_lines(exc, path)), commentary.strip())
            return f"a layer USD reads for a value cannot be opened: {line}"
        if "propName.IsEmpty()" in commentary:
            return NAMELESS_PROPERTY
    return None


def _undecodable_error(path: str) -> str:
    """Say what USD said where Python cannot decode its words: where a layer
    stops being UTF-8 (usd-core 26.11's usda parser rejects invalid UTF-8
    anywhere in the file, comments included), or the parse error of a text
    layer whose name is not UTF-8 (USD's message quotes the name)."""
    try:
        with open(path, "rb") as handle:
            data = handle.read()
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        column = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        return (
            f"{path}:{line}:{column}: invalid UTF-8 (byte 0x{data[exc.start]:02x}); "
            "USD's parser rejects the file"
        )
    except OSError:
        return _UNDECODABLE
    return _unnamed_parse_error(path, text) or _UNDECODABLE


_UNDECODABLE = "USD reported an error whose message is not valid UTF-8"


def _unnamed_parse_error(path: str, text: str) -> str | None:
    """USD's parse errors of a text layer's ``text``, parsed again in a layer
    with no name (its errors then read ":LINE:COLUMN: ..."), each given
    ``path``; None when the text is no text layer or parses. (USD parsed it
    once already and answered: parsing it again is as safe.)"""
    if not text.startswith("#usda"):
        return None
    try:
        Sdf.Layer.CreateAnonymous(".usda").ImportFromString(text)
    except Tf.ErrorException as exc:
        found = [str(getattr(arg, "commentary", "") or "").strip() for arg in exc.args]
        placed = [
            f"{os.path.abspath(path)}{line}" for line in found if re.match(r":\d+:\d+: ", line)
        ]
        return "\n".join(placed) or None
    return None


class OutOfMemory(MemoryError):
    """USD (``std::bad_alloc``) or Python (MemoryError) could not allocate while a
    file was linted: the process's memory, not the file, is the problem, so the
    file is one the tool could not lint (exit 2), never an ST001 finding."""


#: How a USD error says that an allocation failed (the C++ exception it caught).
_BAD_ALLOC = "std::bad_alloc"


def out_of_memory(error: BaseException | Iterable[str]) -> bool:
    """Whether an exception (or the lines of USD's errors) says memory ran out."""
    if isinstance(error, MemoryError):
        return True
    if isinstance(error, BaseException):
        return isinstance(error, Tf.ErrorException) and _BAD_ALLOC in str(error)
    return any(_BAD_ALLOC in line for line in error)


def out_of_memory_message() -> str:
    """Why a file could not be linted when memory ran out, with the process's
    data limit where one is set (a worker's share of the machine: workers.cap_memory),
    or the user's address-space limit (``ulimit -v``) where that is the smaller."""
    try:
        import resource
    except ImportError:  # not POSIX: no per-process limit to name
        limit = space = None
    else:
        limit, space = (
            None if soft == resource.RLIM_INFINITY else soft
            for soft in (
                resource.getrlimit(resource.RLIMIT_DATA)[0],
                resource.getrlimit(resource.RLIMIT_AS)[0],
            )
        )
    if space is not None and (limit is None or space <= limit):
        return (
            "out of memory: reading the file needs more than the address-space limit "
            f"(ulimit -v) of {_amount(space)} allows: raise it"
        )
    if limit is None:
        return "out of memory: reading the file needs more memory than the machine could give"
    return (
        "out of memory: reading the file needs more than the "
        f"{_amount(limit)} this process may allocate"
    )


def _amount(size: int) -> str:
    return f"{size / 2**30:.1f} GiB" if size >= 2**30 else f"{size // 2**20} MiB"


def position_from_error(text: str) -> tuple[str, int, int | None] | None:
    """(file, line, column) of the first ``file.usda:LINE[:COL]`` in USD's
    message: its parser errors start ``/path/file.usda:LINE:COL:``."""
    parts = text.split(":")
    for index, (first, second) in enumerate(zip(parts, parts[1:], strict=False)):
        if first.endswith(USD_EXTENSIONS) and second.strip().isdigit():
            third = parts[index + 2].strip() if index + 2 < len(parts) else ""
            return (
                ":".join(parts[: index + 1]),
                int(second),
                int(third) if third.isdigit() else None,
            )
    return None


def without_position(message: str) -> str:
    """USD's message without its leading ``/abs/file.usda:LINE:COL:``: the
    finding's location carries them (shown relative to where the report is
    read), and a message must not carry the machine's absolute paths."""
    position = position_from_error(message)
    if position is None:
        return message
    file, line, column = position
    prefix = f"{file}:{line}:" + (f"{column}:" if column is not None else "")
    if not message.startswith(prefix):
        return message
    return message[len(prefix) :].strip() or message
