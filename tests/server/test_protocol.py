"""``usdrender-lint server`` driven over stdio by pytest-lsp's client: the
protocol as an editor speaks it (initialize, open, change, diagnostics, code
actions, hover, configuration changes, shutdown).

One server serves the module (it starts USD in a child process: a start per
test would cost more than the tests).
"""

from __future__ import annotations

import asyncio
import fnmatch
import json
import os
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest
import pytest_lsp
from lsprotocol import types
from pygls.protocol import default_converter
from pytest_lsp import ClientServerConfig, LanguageClient, client_capabilities
from pytest_lsp.client import DEFAULT_CLIENT_FEATURES, register_lsp_features

from usdrender_lint.server.ranges import Edit, Span, apply_edits

REPO = Path(__file__).resolve().parents[2]
BROKEN_SHOT = REPO / "examples" / "broken_shot" / "shot.usda"

pytestmark = [
    pytest.mark.asyncio(loop_scope="module"),
    pytest.mark.heavy(seconds=27),
]


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("workspace")
    shutil.copy(BROKEN_SHOT, root / "shot.usda")
    (root / "cams.usda").write_text(
        '#usda 1.0\ndef Xform "rig"\n{\n    def Camera "cam"\n    {\n    }\n}\n'
    )
    return root


#: The version of the document each URI's last diagnostics were published for.
published_versions: dict[str, int | None] = {}
#: How many times diagnostics were published for each URI.
publications: dict[str, int] = {}
#: Every capability the server registered with the client.
registrations: list[types.Registration] = []
#: Every publication, in order: (URI, its diagnostics).
history: list[tuple[str, list[types.Diagnostic]]] = []


def make_client() -> LanguageClient:
    """pytest-lsp's client, which also records the version of each publication
    and accepts the server's registration of file watchers."""

    def publish(client: LanguageClient, params: types.PublishDiagnosticsParams) -> None:
        client.diagnostics[params.uri] = params.diagnostics
        published_versions[params.uri] = params.version
        publications[params.uri] = publications.get(params.uri, 0) + 1
        history.append((params.uri, list(params.diagnostics)))

    def register(client: LanguageClient, params: types.RegistrationParams) -> None:
        registrations.extend(params.registrations)

    client = LanguageClient(converter_factory=default_converter)
    features = {
        **DEFAULT_CLIENT_FEATURES,
        types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS: publish,
        types.CLIENT_REGISTER_CAPABILITY: register,
    }
    register_lsp_features(client, features)
    return client


SERVER = ClientServerConfig(
    server_command=[sys.executable, "-m", "usdrender_lint", "server"], client_factory=make_client
)


async def start_session(client: LanguageClient, root: Path, name: str) -> None:
    """Initialize the session as VS Code does, with ``root`` its one workspace folder."""
    params = types.InitializeParams(
        capabilities=client_capabilities("visual-studio-code"),
        root_uri=root.as_uri(),
        workspace_folders=[types.WorkspaceFolder(uri=root.as_uri(), name=name)],
    )
    await client.initialize_session(params)


@pytest_lsp.fixture(scope="module", config=SERVER)
async def client(lsp_client: LanguageClient, workspace: Path):
    await start_session(lsp_client, workspace, "shots")
    yield
    await lsp_client.shutdown_session()


async def diagnostics_of(client: LanguageClient, uri: str, version: int) -> list:
    """The diagnostics published for ``uri`` at ``version`` (waits for them)."""
    async with asyncio.timeout(60):
        while published_versions.get(uri) != version or uri not in client.diagnostics:
            await client.wait_for_notification(types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
        return list(client.diagnostics[uri])


def open_document(client: LanguageClient, path: Path, text: str | None = None) -> str:
    uri = path.as_uri()
    client.text_document_did_open(
        types.DidOpenTextDocumentParams(
            types.TextDocumentItem(
                uri=uri, language_id="usda", version=1, text=text or path.read_text()
            )
        )
    )
    return uri


def close_documents(client: LanguageClient, *uris: str) -> None:
    for uri in uris:
        client.text_document_did_close(
            types.DidCloseTextDocumentParams(types.TextDocumentIdentifier(uri))
        )


def change(client: LanguageClient, uri: str, version: int, text: str) -> None:
    client.text_document_did_change(
        types.DidChangeTextDocumentParams(
            text_document=types.VersionedTextDocumentIdentifier(uri=uri, version=version),
            content_changes=[types.TextDocumentContentChangeWholeDocument(text=text)],
        )
    )


async def quick_actions(
    client: LanguageClient, uri: str, diagnostic: types.Diagnostic
) -> list[types.CodeAction]:
    """The code actions offered on one diagnostic, as a light bulb asks for them."""
    actions = await client.text_document_code_action_async(
        types.CodeActionParams(
            text_document=types.TextDocumentIdentifier(uri),
            range=diagnostic.range,
            context=types.CodeActionContext(diagnostics=[diagnostic]),
        )
    )
    return list(actions or [])


async def file_changed_until(
    client: LanguageClient,
    path: Path,
    kind: types.FileChangeType,
    uri: str,
    settled: Callable[[dict[str, types.Diagnostic]], bool],
) -> dict[str, types.Diagnostic]:
    """Tell the server ``path`` changed on disk, as the editor's file watcher
    does; the diagnostics of ``uri``, by code, once ``settled`` says they are."""
    client.workspace_did_change_watched_files(
        types.DidChangeWatchedFilesParams([types.FileEvent(uri=path.as_uri(), type=kind)])
    )
    async with asyncio.timeout(60):
        while True:
            await client.wait_for_notification(types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
            found = {d.code: d for d in client.diagnostics[uri]}
            if settled(found):
                return found


async def fix_all_actions(client: LanguageClient, uri: str) -> list[types.CodeAction]:
    """The source.fixAll actions of a document, as an editor asks on save."""
    actions = await client.text_document_code_action_async(
        types.CodeActionParams(
            text_document=types.TextDocumentIdentifier(uri),
            range=types.Range(types.Position(0, 0), types.Position(0, 0)),
            context=types.CodeActionContext(
                diagnostics=[], only=[types.CodeActionKind.SourceFixAll]
            ),
        )
    )
    return list(actions or [])


def apply(text: str, edits: list[types.TextEdit]) -> str:
    return apply_edits(
        text,
        [
            Edit(
                Span(
                    (e.range.start.line, e.range.start.character),
                    (e.range.end.line, e.range.end.character),
                ),
                e.new_text,
            )
            for e in edits
        ],
    )


async def test_open_publishes_the_findings_of_check(client: LanguageClient, workspace: Path):
    path = workspace / "shot.usda"
    uri = open_document(client, path)
    found = await diagnostics_of(client, uri, 1)
    by_code = {d.code: d for d in found}
    assert set(by_code) == {"CA004", "SE007", "CA003", "SE003", "PR004"}
    camera = by_code["CA004"]
    line = path.read_text().splitlines()[camera.range.start.line]
    assert line.strip() == "rel camera = </World/camRig>"
    assert camera.range.start.character == line.index("rel")
    assert camera.range.end.character == len(line)
    assert camera.severity == types.DiagnosticSeverity.Error
    assert by_code["SE007"].severity == types.DiagnosticSeverity.Warning
    assert camera.code_description.href.endswith("/rules/CA004-camera-target-not-camera/")
    assert camera.source == "usdrender-lint"
    assert camera.data["profile"] == "generic"
    assert camera.data["fix"] == {
        "description": "retarget camera to </World/camRig/shotCam>",
        "safe": True,
    }
    # The same findings as check on the saved file, line for line.
    checked = subprocess.run(
        [
            sys.executable,
            "-m",
            "usdrender_lint",
            "check",
            "--no-cache",
            "--format",
            "json",
            str(path),
        ],
        capture_output=True,
        text=True,
    )
    import json

    report = json.loads(checked.stdout)
    expected = {(f["code"], f["line"]) for f in report["files"][0]["findings"]}
    assert {(d.code, d.range.start.line + 1) for d in found} == expected


async def test_a_change_relints_the_unsaved_text(client: LanguageClient, workspace: Path):
    path = workspace / "shot.usda"
    uri = path.as_uri()
    text = path.read_text().replace("(0.75, 0.25, 0.25, 0.75)", "(0.25, 0.25, 0.75, 0.75)")
    change(client, uri, 2, text)
    found = await diagnostics_of(client, uri, 2)
    assert "SE003" not in {d.code for d in found}
    # Back as it was on disk.
    change(client, uri, 3, path.read_text())
    assert "SE003" in {d.code for d in await diagnostics_of(client, uri, 3)}


async def test_a_reference_resolves_from_the_document_folder(
    client: LanguageClient, workspace: Path
):
    path = workspace / "new_shot.usda"  # never saved: no file on disk
    text = (
        "#usda 1.0\n"
        'def Xform "World" (\n    references = @./cams.usda@</rig>\n)\n{\n}\n'
        'def RenderSettings "S"\n{\n    rel camera = </World/cam>\n'
        "    uniform int2 resolution = (0, 10)\n}\n"
    )
    uri = open_document(client, path, text)
    found = await diagnostics_of(client, uri, 1)
    codes = {d.code for d in found}
    # The camera target exists only through the reference: no CA003.
    assert "CA003" not in codes
    resolution = next(d for d in found if d.code == "SE001")
    assert resolution.range.start.line == 9
    client.text_document_did_close(
        types.DidCloseTextDocumentParams(types.TextDocumentIdentifier(uri))
    )


async def test_a_parse_error_is_one_diagnostic_at_usds_line(
    client: LanguageClient, workspace: Path
):
    path = workspace / "broken.usda"
    text = '#usda 1.0\ndef Scope "Lights"\n{\n    float x = \n}\n'
    uri = open_document(client, path, text)
    found = await diagnostics_of(client, uri, 1)
    assert len(found) == 1
    (error,) = found
    assert error.code == "ST001"
    assert error.range.start.line == 3  # USD says line 4
    assert "Expected" in error.message
    client.text_document_did_close(
        types.DidCloseTextDocumentParams(types.TextDocumentIdentifier(uri))
    )


async def test_a_text_without_the_usda_header_gets_the_files_diagnostic(
    client: LanguageClient, workspace: Path
):
    """USD refuses such a file before parsing it; the editor says what check says."""
    path = workspace / "headless.usda"
    text = 'def Scope "Render"\n{\n}\n'
    uri = open_document(client, path, text)
    (error,) = await diagnostics_of(client, uri, 1)
    assert error.code == "ST001"
    assert error.message.endswith("headless.usda> is not a valid usda layer")
    path.write_text(text)
    checked = subprocess.run(
        [
            str(Path(sys.executable).parent / "usdrender-lint"),
            "check",
            "--format",
            "json",
            str(path),
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    (finding,) = json.loads(checked.stdout)["files"][0]["findings"]
    assert (finding["code"], finding["line"]) == ("ST001", None)
    assert error.message.endswith(finding["message"].rsplit("/", 1)[-1])
    client.text_document_did_close(
        types.DidCloseTextDocumentParams(types.TextDocumentIdentifier(uri))
    )


async def test_quick_fix_and_fix_all_give_the_fix_result(
    client: LanguageClient, workspace: Path, tmp_path: Path
):
    path = workspace / "shot.usda"
    uri = path.as_uri()
    text = path.read_text()
    found = await diagnostics_of(client, uri, 3)
    camera = next(d for d in found if d.code == "CA004")
    actions = await quick_actions(client, uri, camera)
    titles = [a.title for a in actions]
    fix = next(a for a in actions if a.title.startswith("Fix CA004"))
    assert fix.kind == types.CodeActionKind.QuickFix and fix.is_preferred
    fixed = apply(text, fix.edit.changes[uri])
    assert "rel camera = </World/camRig/shotCam>" in fixed
    assert len(fix.edit.changes[uri]) == 1  # one minimal edit
    assert any(t.startswith("Suppress CA004 on /Render/PrimarySettings") for t in titles)

    # The unsafe fix is labelled so.
    window = next(d for d in found if d.code == "SE003")
    actions = await quick_actions(client, uri, window)
    unsafe = next(a for a in actions if a.title.startswith("Fix SE003"))
    assert "unsafe" in unsafe.title and not unsafe.is_preferred

    # Fix all: exactly what check --fix writes.
    (fix_all,) = await fix_all_actions(client, uri)
    assert fix_all.kind == "source.fixAll.usdrender-lint"
    # Asked for every action, it comes without its edit, made when it is chosen.
    offered = await quick_actions(client, uri, camera)
    (lazy,) = [a for a in offered if a.kind == "source.fixAll.usdrender-lint"]
    assert lazy.edit is None
    resolved = await client.code_action_resolve_async(lazy)
    assert resolved.edit == fix_all.edit
    copy = tmp_path / "shot.usda"
    shutil.copy(path, copy)
    subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "check", "--no-cache", "--fix", str(copy)],
        capture_output=True,
    )
    assert apply(text, fix_all.edit.changes[uri]) == copy.read_text() != text


async def test_suppress_in_custom_data_silences_the_finding(
    client: LanguageClient, workspace: Path
):
    path = workspace / "shot.usda"
    uri = path.as_uri()
    text = path.read_text()
    found = await diagnostics_of(client, uri, 3)
    product = next(d for d in found if d.code == "PR004")
    actions = await quick_actions(client, uri, product)
    suppress = next(a for a in actions if a.title.startswith("Suppress PR004"))
    suppressed = apply(text, suppress.edit.changes[uri])
    assert '"PR004"' in suppressed
    change(client, uri, 4, suppressed)
    assert "PR004" not in {d.code for d in await diagnostics_of(client, uri, 4)}

    # Hover on the code in the suppression: the rule's documentation.
    lines = suppressed.splitlines()
    line = next(i for i, x in enumerate(lines) if '"PR004"' in x)
    hover = await client.text_document_hover_async(
        types.HoverParams(
            text_document=types.TextDocumentIdentifier(uri),
            position=types.Position(line, lines[line].index("PR004") + 2),
        )
    )
    assert hover is not None and "PR004" in hover.contents.value
    assert "## What it does" in hover.contents.value
    change(client, uri, 5, text)
    await diagnostics_of(client, uri, 5)


async def test_hover_on_a_finding_shows_its_rule(client: LanguageClient, workspace: Path):
    uri = (workspace / "shot.usda").as_uri()
    found = await diagnostics_of(client, uri, 5)
    window = next(d for d in found if d.code == "SE003")
    hover = await client.text_document_hover_async(
        types.HoverParams(
            text_document=types.TextDocumentIdentifier(uri), position=window.range.start
        )
    )
    assert hover is not None
    assert hover.contents.value.startswith("**SE003 ")
    assert window.code_description.href in hover.contents.value


async def test_a_configuration_change_relints(client: LanguageClient, workspace: Path):
    uri = (workspace / "shot.usda").as_uri()
    config = workspace / ".usdrender-lint.toml"
    config.write_text('ignore = ["PR004"]\n[severity]\nSE007 = "info"\n')
    found = await file_changed_until(
        client, config, types.FileChangeType.Created, uri, lambda found: "PR004" not in found
    )
    assert found["SE007"].severity == types.DiagnosticSeverity.Information
    config.unlink()


async def test_config_force_exclude_leaves_a_skipped_document_alone(
    client: LanguageClient, workspace: Path
):
    """A project whose configuration excludes reference/ with force-exclude: a
    layer opened there gets no diagnostics and no fix, one in shots/ its findings."""
    project = workspace / "forced"
    for folder in ("reference", "shots"):
        (project / folder).mkdir(parents=True)
        shutil.copy(BROKEN_SHOT, project / folder / "shot.usda")
    (project / ".usdrender-lint.toml").write_text(
        'extend-exclude = ["reference/"]\nforce-exclude = true\n'
    )
    skipped = open_document(client, project / "reference" / "shot.usda")
    kept = open_document(client, project / "shots" / "shot.usda")
    assert await diagnostics_of(client, skipped, 1) == []
    assert {d.code for d in await diagnostics_of(client, kept, 1)} >= {"CA004", "SE003"}
    assert not await fix_all_actions(client, skipped)


async def test_a_change_to_an_extended_configuration_relints(
    client: LanguageClient, workspace: Path
):
    """A configuration may extend a file of any name (a studio's): the server
    watches every TOML file, and a change to that one re-lints the documents."""
    project = workspace / "extending"
    project.mkdir()
    shutil.copy(BROKEN_SHOT, project / "shot.usda")
    studio = workspace / "studio.toml"
    studio.write_text('[severity]\nSE007 = "warning"\n')
    (project / ".usdrender-lint.toml").write_text('extend = "../studio.toml"\n')
    uri = open_document(client, project / "shot.usda")
    found = {d.code: d for d in await diagnostics_of(client, uri, 1)}
    assert found["SE007"].severity == types.DiagnosticSeverity.Warning
    # The client is asked to report a change to any TOML file, studio.toml's too.
    globs = [  # the options arrive as the JSON the server sent
        watcher["globPattern"]
        for registration in registrations
        if registration.method == types.WORKSPACE_DID_CHANGE_WATCHED_FILES
        for watcher in registration.register_options["watchers"]
    ]
    assert any(fnmatch.fnmatch("studio.toml", glob.removeprefix("**/")) for glob in globs), globs
    studio.write_text('[severity]\nSE007 = "info"\n')
    await file_changed_until(
        client,
        studio,
        types.FileChangeType.Changed,
        uri,
        lambda found: found["SE007"].severity == types.DiagnosticSeverity.Information,
    )


LIGHTING = '#usda 1.0\ndef RenderSettings "S"\n{\n    uniform int2 resolution = (0, 10)\n}\n'


async def _lints_settled(
    client: LanguageClient, seen: list, start: int, sublayer: str, root: str
) -> None:
    """Wait until no lint is running: the sublayer's own lint has published
    (its ST003 lies on its own root layer, never on the root's) and then the
    root's, which that lint sets off as a dependent, on both documents."""
    async with asyncio.timeout(60):
        while True:
            own = [
                i
                for i, (uri, found) in enumerate(seen[start:], start)
                if uri == sublayer and any(d.code == "ST003" for d in found)
            ]
            # The root's lint publishes on both documents, one notification each.
            if own and {root, sublayer} <= {uri for uri, _ in seen[own[0] + 1 :]}:
                return
            await client.wait_for_notification(types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)


async def _finding_in_a_sublayer(
    client: LanguageClient, folder: Path
) -> tuple[Path, str, types.Diagnostic]:
    """Open ``root.usda`` in ``folder`` over a sublayer with an SE001: the
    sublayer, the root's URI, and the finding, related to the sublayer's file."""
    lighting = folder / "lighting.usda"
    lighting.write_text(LIGHTING)
    root = open_document(
        client, folder / "root.usda", "#usda 1.0\n(\n    subLayers = [@./lighting.usda@]\n)\n"
    )
    (found,) = [d for d in await diagnostics_of(client, root, 1) if d.code == "SE001"]
    assert [r.location.uri for r in found.related_information or ()] == [lighting.as_uri()]
    return lighting, root, found


async def test_findings_in_another_layer(client: LanguageClient, workspace: Path):
    """A finding in a sublayer: related information on the document while the
    sublayer is not open; on the sublayer's own URI, at its unsaved line, once it is."""
    lighting, root, found = await _finding_in_a_sublayer(client, workspace)
    (related,) = found.related_information or ()
    assert related.location.range.start.line == 3
    assert str(lighting) in related.message

    unsaved = "#usda 1.0\n# a comment the file does not have\n" + LIGHTING.split("\n", 1)[1]
    opened_at = len(history)
    lighting_uri = open_document(client, lighting, unsaved)
    async with asyncio.timeout(60):
        while True:
            await client.wait_for_notification(types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
            on_root = [d for d in client.diagnostics.get(root, []) if d.code == "SE001"]
            on_lighting = [d for d in client.diagnostics.get(lighting_uri, []) if d.code == "SE001"]
            if not on_root and on_lighting:
                break
    (shown,) = on_lighting  # the root's finding and the sublayer's own are one
    assert shown.range.start.line == 4
    await _lints_settled(client, history, opened_at, lighting_uri, root)
    # Closed again: back on the root, as related information; on the closed
    # document, only an empty publication, before any other (whatever order
    # the root's lint publishes its URIs in).
    closed_at = len(history)
    client.text_document_did_close(
        types.DidCloseTextDocumentParams(types.TextDocumentIdentifier(lighting_uri))
    )
    async with asyncio.timeout(60):
        while not [d for d in client.diagnostics.get(root, []) if d.code == "SE001"]:
            await client.wait_for_notification(types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
    after_close = history[closed_at:]
    assert after_close[0] == (lighting_uri, [])
    assert [found for uri, found in after_close if uri == lighting_uri] == [[]]
    client.text_document_did_close(
        types.DidCloseTextDocumentParams(types.TextDocumentIdentifier(root))
    )


async def test_a_quick_fix_edits_the_unsaved_text(client: LanguageClient, workspace: Path):
    path = workspace / "shot.usda"
    uri = path.as_uri()
    unsaved = "#usda 1.0\n# not saved yet\n" + path.read_text().split("\n", 1)[1]
    change(client, uri, 20, unsaved)
    camera = next(d for d in await diagnostics_of(client, uri, 20) if d.code == "CA004")
    assert unsaved.splitlines()[camera.range.start.line].strip().startswith("rel camera")
    actions = await quick_actions(client, uri, camera)
    fix = next(a for a in actions if a.title.startswith("Fix CA004"))
    fixed = apply(unsaved, fix.edit.changes[uri])
    assert fixed == unsaved.replace("</World/camRig>", "</World/camRig/shotCam>", 1)
    change(client, uri, 21, path.read_text())
    await diagnostics_of(client, uri, 21)


async def test_a_save_relints_with_the_files_on_disk(client: LanguageClient, workspace: Path):
    """Saving lints again: a file the document references that changed on disk
    meanwhile is read again (here the camera the settings target disappears)."""
    cams = workspace / "cams.usda"
    path = workspace / "saved.usda"
    text = (
        '#usda 1.0\ndef Xform "World" (\n    references = @./cams.usda@</rig>\n)\n{\n}\n'
        'def RenderSettings "S"\n{\n    rel camera = </World/cam>\n}\n'
    )
    path.write_text(text)
    uri = open_document(client, path, text)
    assert "CA003" not in {d.code for d in await diagnostics_of(client, uri, 1)}
    before = cams.stat().st_mtime
    original = cams.read_text()
    cams.write_text('#usda 1.0\ndef Xform "rig"\n{\n}\n')
    os.utime(cams, (before + 5, before + 5))
    count = publications[uri]
    client.text_document_did_save(
        types.DidSaveTextDocumentParams(types.TextDocumentIdentifier(uri))
    )
    async with asyncio.timeout(60):
        while publications[uri] == count:
            await client.wait_for_notification(types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
    assert "CA003" in {d.code for d in client.diagnostics[uri]}
    cams.write_text(original)
    client.text_document_did_close(
        types.DidCloseTextDocumentParams(types.TextDocumentIdentifier(uri))
    )


async def test_a_layer_rewritten_with_its_time_kept_is_read_again(
    client: LanguageClient, workspace: Path
):
    """A referenced file rewritten with its size and modification time kept
    (its time set back, as a copy that keeps times does, or written within
    one tick of a coarse clock): told by the editor's file watcher, the next
    lint reads it again, as check does (USD's own reload trusts the time alone)."""
    rig = workspace / "kept_rig.usda"
    rig.write_text('#usda 1.0\ndef Xform "rig"\n{\n    def Camera "cam"\n    {\n    }\n}\n')
    path = workspace / "kept_shot.usda"
    text = (
        '#usda 1.0\ndef Xform "World" (\n    references = @./kept_rig.usda@</rig>\n)\n{\n}\n'
        'def RenderSettings "S"\n{\n    rel camera = </World/cam>\n}\n'
    )
    path.write_text(text)
    uri = open_document(client, path, text)
    assert "CA004" not in {d.code for d in await diagnostics_of(client, uri, 1)}
    times = rig.stat()
    rig.write_text(rig.read_text().replace('def Camera "cam"', 'def Xform  "cam"'))
    os.utime(rig, ns=(times.st_atime_ns, times.st_mtime_ns))
    assert rig.stat().st_size == times.st_size
    count = publications[uri]
    client.workspace_did_change_watched_files(
        types.DidChangeWatchedFilesParams(
            [types.FileEvent(uri=rig.as_uri(), type=types.FileChangeType.Changed)]
        )
    )
    async with asyncio.timeout(60):
        while publications[uri] == count:
            await client.wait_for_notification(types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
    assert "CA004" in {d.code for d in client.diagnostics[uri]}
    client.text_document_did_close(
        types.DidCloseTextDocumentParams(types.TextDocumentIdentifier(uri))
    )


async def test_a_document_whose_uri_the_client_encodes_gets_its_diagnostics(
    client: LanguageClient, workspace: Path
):
    """VS Code sends ``file:///my%20shot%20%C3%A9.usda`` for a name with a space
    or a letter outside ASCII; pygls keeps its documents under the URI decoded.
    The diagnostics go on the URI the client sent: on the document, and on
    another open layer (a sublayer so named) that holds a finding."""
    plain = open_document(client, workspace / "shot.usda")
    expected = sorted((d.code, d.range.start.line) for d in await diagnostics_of(client, plain, 1))
    named = workspace / "my shot é.usda"
    shutil.copy(workspace / "shot.usda", named)
    uri = open_document(client, named)
    assert "%20" in uri and "%C3%A9" in uri
    found = await diagnostics_of(client, uri, 1)
    assert sorted((d.code, d.range.start.line) for d in found) == expected
    lighting = workspace / "light é.usda"
    lighting.write_text(LIGHTING)
    lighting_uri = open_document(client, lighting)
    assert "SE001" in {d.code for d in await diagnostics_of(client, lighting_uri, 1)}
    root = open_document(
        client, workspace / "root é.usda", "#usda 1.0\n(\n    subLayers = [@./light é.usda@]\n)\n"
    )
    await diagnostics_of(client, root, 1)
    assert "SE001" in {d.code for d in client.diagnostics[lighting_uri]}
    assert not [d for d in client.diagnostics[root] if d.code == "SE001"]
    close_documents(client, plain, uri, lighting_uri, root)


async def test_a_folder_named_by_bytes_that_are_not_utf8_gets_its_diagnostics(
    client: LanguageClient, workspace: Path
):
    """A project folder with a Latin-1 name (``d\\xe9``): the client sends its
    bytes percent-encoded (``d%E9``). The document gets check's diagnostics, and
    a finding in its sublayer goes on that layer's URI, encoded alike."""
    try:
        folder = workspace / os.fsdecode(b"d\xe9")
        folder.mkdir()
    except (OSError, UnicodeError):
        pytest.skip("the file system takes only UTF-8 names")
    plain = open_document(client, workspace / "shot.usda")
    expected = sorted((d.code, d.range.start.line) for d in await diagnostics_of(client, plain, 1))
    shutil.copy(workspace / "shot.usda", folder / "shot.usda")
    uri = open_document(client, folder / "shot.usda")
    assert "d%E9" in uri
    found = await diagnostics_of(client, uri, 1)
    assert sorted((d.code, d.range.start.line) for d in found) == expected
    _, root, _ = await _finding_in_a_sublayer(client, folder)
    close_documents(client, plain, uri, root)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
async def test_a_sublayer_that_is_a_named_pipe_is_st001_in_the_editor(
    client: LanguageClient, workspace: Path
):
    """A layer names a named pipe as its sublayer: the diagnostic says so at
    once (USD's open of it waited out the time-out)."""
    folder = workspace / "piped"
    folder.mkdir()
    os.mkfifo(folder / "pipe.usda")
    shot = folder / "shot.usda"
    shot.write_text("#usda 1.0\n(\n    subLayers = [@./pipe.usda@]\n)\n")
    uri = open_document(client, shot)
    (st001,) = [d for d in await diagnostics_of(client, uri, 1) if d.code == "ST001"]
    assert st001.message.endswith(
        "pipe.usda: not a regular file (a named pipe or a device, whose open can wait forever)"
    )
    close_documents(client, uri)


@pytest.mark.parametrize("separator", ["\x0c", "\u2028"], ids=["form-feed", "line-separator"])
async def test_a_comment_holding_a_character_python_splits_lines_at_keeps_ranges_and_fixes(
    client: LanguageClient, workspace: Path, tmp_path: Path, separator: str
):
    """Editors end lines at line feeds only: a form feed or U+2028 in a comment
    (which str.splitlines splits at) moved every range after it and turned the
    fix into a broken edit."""
    text = (
        f'#usda 1.0\n# page break:{separator}\ndef Scope "Render"\n{{\n'
        '    def RenderSettings "rs"\n    {\n        uniform bool instantaneousShutter = 1\n'
        "    }\n}\n"
    )
    path = workspace / f"separator-{ord(separator):x}.usda"
    path.write_text(text)
    uri = open_document(client, path)
    found = {d.code: d for d in await diagnostics_of(client, uri, 1)}
    shutter = found["SE007"].range
    assert (shutter.start.line, shutter.start.character) == (6, 8)
    assert shutter.end == types.Position(6, len("        uniform bool instantaneousShutter = 1"))
    (fix_all,) = await fix_all_actions(client, uri)
    copy = tmp_path / path.name
    copy.write_text(text)
    subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "check", "--no-cache", "--fix", str(copy)],
        capture_output=True,
    )
    assert apply(text, fix_all.edit.changes[uri]) == copy.read_text() != text
    close_documents(client, uri)


@pytest.mark.parametrize("separator", ["\x0c", "\u2028", "\x85"])
async def test_a_typed_edit_below_a_character_python_splits_lines_at_lands_on_its_line(
    client: LanguageClient, workspace: Path, separator: str
):
    """An editor sends the range of each edit: below a comment holding a form
    feed, U+2028 or U+0085, the server applied it a line too far down, and the
    document showed a parse error its text does not have."""
    text = (
        f'#usda 1.0\n# page break:{separator} é🎥\ndef Scope "Render"\n{{\n'
        '    def RenderSettings "rs"\n    {\n        rel camera = </nope>\n    }\n}\n'
    )
    path = workspace / f"typed-{ord(separator):x}.usda"
    uri = open_document(client, path, text)
    assert "CA003" in {d.code for d in await diagnostics_of(client, uri, 1)}
    # The camera fixed as typed: </nope> becomes </cam>, and a Camera prim added.
    column = text.split("\n")[6].index("nope")
    client.text_document_did_change(
        types.DidChangeTextDocumentParams(
            text_document=types.VersionedTextDocumentIdentifier(uri=uri, version=2),
            content_changes=[
                types.TextDocumentContentChangePartial(
                    range=types.Range(types.Position(6, column), types.Position(6, column + 4)),
                    text="cam",
                ),
                types.TextDocumentContentChangePartial(
                    range=types.Range(types.Position(9, 0), types.Position(9, 0)),
                    text='def Camera "cam"\n{\n}\n',
                ),
            ],
        )
    )
    found = await diagnostics_of(client, uri, 2)
    assert {d.code for d in found} == {"ST003", "SE015", "CA006"}
    close_documents(client, uri)


async def test_a_binary_usd_document_gets_the_findings_check_gives_its_file(
    client: LanguageClient, workspace: Path
):
    """A .usd is often a crate: the editor shows its bytes as text, which USD
    cannot read, and the document got one error (ST001 "Failed to open layer")
    where check lints the file and finds the shot's defects."""
    from pxr import Sdf

    path = workspace / "crate shot.usd"
    Sdf.Layer.FindOrOpen(str(workspace / "shot.usda")).Export(str(path), args={"format": "usdc"})
    saved = path.read_bytes()
    assert saved.startswith(b"PXR-USDC")
    uri = open_document(client, path, saved.decode("utf-8", "replace"))
    found = await diagnostics_of(client, uri, 1)
    assert {d.code for d in found} == {"CA004", "SE007", "CA003", "SE003", "PR004"}
    assert path.read_bytes() == saved
    close_documents(client, uri)


async def test_a_parse_error_past_non_ascii_text_starts_at_its_word(
    client: LanguageClient, workspace: Path
):
    """USD's parser counts a column in bytes: past "é🎥相机" the range started 8
    characters to the right of the word USD names."""
    line = 'def Scope "abcdefg" ( doc = "é🎥相机" bogus = 1 )'
    uri = open_document(client, workspace / "parse-utf8.usda", f"#usda 1.0\n{line}\n{{\n}}\n")
    (error,) = await diagnostics_of(client, uri, 1)
    assert "bogus" in error.message
    utf16 = len(line[: line.index("bogus")].encode("utf-16-le")) // 2
    assert (error.range.start.line, error.range.start.character) == (1, utf16)
    close_documents(client, uri)


async def test_code_actions_on_a_diagnostic_with_foreign_data_answer_without_an_error(
    client: LanguageClient, workspace: Path
):
    """A client sends back the diagnostics it holds: one whose data this server
    did not write that way (another version's) failed the request with an
    internal error and Python's traceback."""
    uri = open_document(client, workspace / "foreign.usda", BROKEN_SHOT.read_text())
    found = await diagnostics_of(client, uri, 1)
    camera = next(d for d in found if d.code == "CA004")
    for data in ({"key": ["CA004"]}, {"key": ["CA004", None, "m"], "fix": "retarget"}):
        foreign = types.Diagnostic(
            range=camera.range, message=camera.message, source=camera.source, data=data
        )
        actions = await quick_actions(client, uri, foreign)
        assert not [a for a in actions if a.kind == types.CodeActionKind.QuickFix]
    close_documents(client, uri)


async def _until(client: LanguageClient, uri: str, done) -> list[types.Diagnostic]:
    async with asyncio.timeout(60):
        while not done(client.diagnostics.get(uri, [])):
            await client.wait_for_notification(types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
    return list(client.diagnostics.get(uri, []))


PURPOSES = (
    'over "Render"\n{\n    over "rs"\n    {\n'
    "        uniform token[] materialBindingPurposes = %s\n    }\n}\n"
)


def _shot_over(sublayer: str) -> str:
    """A shot with RenderSettings /Render/rs over ``sublayer``."""
    return (
        f'#usda 1.0\n(\n    subLayers = [@./{sublayer}@]\n)\ndef Scope "Render"\n{{\n'
        '    def RenderSettings "rs"\n    {\n    }\n}\n'
    )


async def test_an_edit_two_sublayers_down_and_a_close_relint_the_shot(
    client: LanguageClient, workspace: Path
):
    """The shot's stage composes c.usda through b.usda, which is not open: an
    edit to c re-lints the shot (whose text never names c), and closing c with
    unsaved edits re-lints it with c's file again."""
    folder = workspace / "chain"
    folder.mkdir()
    (folder / "b.usda").write_text("#usda 1.0\n(\n    subLayers = [@./c.usda@]\n)\n")
    bad = "#usda 1.0\n" + PURPOSES % '["full", "bogus"]'
    (folder / "c.usda").write_text(bad)
    shot = open_document(client, folder / "a.usda", _shot_over("b.usda"))
    await diagnostics_of(client, shot, 1)
    layer = open_document(client, folder / "c.usda")
    has_se011 = lambda found: any(d.code == "SE011" for d in found)  # noqa: E731
    await _until(client, layer, has_se011)
    change(client, layer, 2, "#usda 1.0\n" + PURPOSES % '["full", "preview"]')
    await _until(client, layer, lambda found: not has_se011(found))
    # Edited again, then closed unsaved: the shot composes the file, which has SE011.
    change(client, layer, 3, "#usda 1.0\n" + PURPOSES % '["full", ""]')
    await _until(client, layer, lambda found: not has_se011(found))
    close_documents(client, layer)
    found = await _until(client, shot, has_se011)
    (se011,) = [d for d in found if d.code == "SE011"]
    assert "bogus" in se011.message
    close_documents(client, shot)


async def test_a_layer_saved_by_its_resolved_path_relints_the_shot_opened_through_a_link(
    client: LanguageClient, workspace: Path
):
    """The workspace folder is reached through a symlink: the shot, opened by
    the link's path, composes c.usda (through b.usda) by that path, and the
    editor names c by its resolved path. Saving c re-lints the shot: the two
    paths were compared as text, and the shot kept c's old finding."""
    real = workspace / "resolved"
    real.mkdir()
    link = workspace / "through-a-link"
    link.symlink_to(real, target_is_directory=True)
    (real / "b.usda").write_text("#usda 1.0\n(\n    subLayers = [@./c.usda@]\n)\n")
    layer_file = real / "c.usda"
    layer_file.write_text("#usda 1.0\n" + PURPOSES % '["full", "bogus"]')
    has_se011 = lambda found: any(d.code == "SE011" for d in found)  # noqa: E731
    shot = open_document(client, link / "a.usda", _shot_over("b.usda"))
    await _until(client, shot, has_se011)
    layer = open_document(client, layer_file)
    await diagnostics_of(client, layer, 1)
    fixed = "#usda 1.0\n" + PURPOSES % '["full", "preview"]'
    change(client, layer, 2, fixed)
    before = layer_file.stat().st_mtime
    layer_file.write_text(fixed)
    os.utime(layer_file, (before + 5, before + 5))  # a save USD sees on a coarse clock
    client.text_document_did_save(
        types.DidSaveTextDocumentParams(types.TextDocumentIdentifier(layer))
    )
    await _until(client, shot, lambda found: not has_se011(found))
    close_documents(client, layer, shot)


@pytest.mark.parametrize("through_the_link", ["shot", "layer"])
async def test_a_layer_s_unsaved_text_reaches_the_shot_across_a_link(
    client: LanguageClient, workspace: Path, through_the_link: str
):
    """The shot and its sublayer are open by paths on either side of a
    symlink (the editor resolved one of them). USD composes the sublayer by
    the path the shot's asset path gives, so its stage read the file into a
    layer of its own, and the layer's unsaved text never reached the shot:
    without the link, an edit of the layer shows the shot's finding at once."""
    real = workspace / f"resolved-{through_the_link}"
    real.mkdir()
    link = workspace / f"link-{through_the_link}"
    link.symlink_to(real, target_is_directory=True)
    (real / "shot.usda").write_text(_shot_over("layer.usda"))
    fine = "#usda 1.0\n" + PURPOSES % '["full", "preview"]'
    (real / "layer.usda").write_text(fine)
    shot_folder, layer_folder = (link, real) if through_the_link == "shot" else (real, link)
    has_se011 = lambda found: any(d.code == "SE011" for d in found)  # noqa: E731
    shot = open_document(client, shot_folder / "shot.usda")
    assert not has_se011(await diagnostics_of(client, shot, 1))
    layer = open_document(client, layer_folder / "layer.usda")
    assert not has_se011(await diagnostics_of(client, layer, 1))
    change(client, layer, 2, "#usda 1.0\n" + PURPOSES % '["full", "bogus"]')
    # The shot's finding, on the open layer that authors the opinion, at its line.
    found = await _until(client, layer, has_se011)
    (se011,) = [d for d in found if d.code == "SE011"]
    assert "bogus" in se011.message and se011.range.start.line == 5
    change(client, layer, 3, fine)
    await _until(client, layer, lambda found: not has_se011(found))
    assert not has_se011(client.diagnostics.get(shot, []))
    close_documents(client, layer, shot)


@pytest.mark.parametrize("through_the_link", ["shot", "layer"])
async def test_a_fix_of_a_layer_s_unsaved_text_across_a_link_edits_that_document(
    client: LanguageClient, workspace: Path, through_the_link: str
):
    """The shot's SE007, authored by the unsaved text of a sublayer open by a
    path on the other side of a symlink: its fix is an edit of that document
    (the file's path the shot composes is not the document's URI)."""
    real = workspace / f"fix-resolved-{through_the_link}"
    real.mkdir()
    link = workspace / f"fix-link-{through_the_link}"
    link.symlink_to(real, target_is_directory=True)
    (real / "shot.usda").write_text(_shot_over("layer.usda"))
    saved = '#usda 1.0\nover "Render"\n{\n    over "rs"\n    {\n    }\n}\n'
    (real / "layer.usda").write_text(saved)
    shutter = "    {\n        uniform bool instantaneousShutter = 1\n    }"
    unsaved = saved.replace("    {\n    }", shutter)
    shot_folder, layer_folder = (link, real) if through_the_link == "shot" else (real, link)
    shot = open_document(client, shot_folder / "shot.usda")
    await diagnostics_of(client, shot, 1)
    layer = open_document(client, layer_folder / "layer.usda")
    await diagnostics_of(client, layer, 1)
    change(client, layer, 2, unsaved)
    found = await _until(client, layer, lambda ds: any(d.code == "SE007" for d in ds))
    (shutter,) = [d for d in found if d.code == "SE007"]
    actions = await quick_actions(client, layer, shutter)
    (fix,) = [a for a in actions if a.title.startswith("Fix SE007")]
    assert fix.edit is not None and fix.edit.changes is not None
    assert list(fix.edit.changes) == [layer]
    assert "uniform bool disableMotionBlur = 1" in apply(unsaved, fix.edit.changes[layer])
    assert (real / "layer.usda").read_text() == saved
    close_documents(client, layer, shot)


async def test_a_shot_s_finding_shown_on_an_open_layer_offers_its_fix(
    client: LanguageClient, workspace: Path
):
    """The shot's SE007 moves to the open sublayer that authors it; its quick fix
    is the shot's (the layer's own stage, with no RenderSettings, has none)."""
    folder = workspace / "moved"
    folder.mkdir()
    layer_text = (
        '#usda 1.0\nover "Render"\n{\n    over "rs"\n    {\n'
        "        uniform bool instantaneousShutter = 1\n    }\n}\n"
    )
    (folder / "layer.usda").write_text(layer_text)
    shot = open_document(client, folder / "shot.usda", _shot_over("layer.usda"))
    await diagnostics_of(client, shot, 1)
    layer = open_document(client, folder / "layer.usda")
    found = await _until(client, layer, lambda ds: any(d.code == "SE007" for d in ds))
    (shutter,) = [d for d in found if d.code == "SE007"]
    actions = await quick_actions(client, layer, shutter)
    (fix,) = [a for a in actions if a.title.startswith("Fix SE007")]
    fixed = apply(layer_text, fix.edit.changes[layer])
    assert "uniform bool disableMotionBlur = 1" in fixed
    close_documents(client, layer, shot)


async def test_an_unfixable_rule_s_finding_offers_no_fix(client: LanguageClient, workspace: Path):
    """A rule the configuration makes ``unfixable`` carries no fix in the
    diagnostic's data, as check's reports carry none, and no fix-all is offered
    when such rules hold the only fixes (it was, with an edit that changed
    nothing). Same file and configuration through check's JSON report."""
    folder = workspace / "unfixable"
    folder.mkdir()
    shutil.copy(BROKEN_SHOT, folder / "shot.usda")
    shutil.copy(BROKEN_SHOT.parent / "lighting_wip.usda", folder / "lighting_wip.usda")
    (folder / ".usdrender-lint.toml").write_text(
        'select = ["CA004", "SE007"]\nunfixable = ["CA004", "SE007"]\n'
    )
    uri = open_document(client, folder / "shot.usda")
    found = await diagnostics_of(client, uri, 1)
    checked = subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "check", "--no-cache", "--format", "json"]
        + [str(folder / "shot.usda")],
        capture_output=True,
        text=True,
    )
    reported = {f["code"]: f["fix"] for f in json.loads(checked.stdout)["files"][0]["findings"]}
    assert {str(d.code): d.data["fix"] for d in found} == reported == {"CA004": None, "SE007": None}
    camera = next(d for d in found if d.code == "CA004")
    titles = [a.title for a in await quick_actions(client, uri, camera)]
    assert not any(t.startswith("Fix ") for t in titles)
    assert not any("every safe fix" in t for t in titles)
    assert await fix_all_actions(client, uri) == []
    close_documents(client, uri)


async def test_config_variants_offers_no_fix(client: LanguageClient, workspace: Path):
    """check --fix refuses a configuration that sets variants (and the
    validation plugins offer no fix under it); the editor offered fix-all and
    quick fixes, made under the current selections only."""
    folder = workspace / "variants"
    folder.mkdir()
    shutil.copy(BROKEN_SHOT, folder / "shot.usda")
    shutil.copy(BROKEN_SHOT.parent / "lighting_wip.usda", folder / "lighting_wip.usda")
    (folder / ".usdrender-lint.toml").write_text("variants = true\n")
    uri = open_document(client, folder / "shot.usda")
    found = await diagnostics_of(client, uri, 1)
    camera = next(d for d in found if d.code == "CA004")
    titles = [a.title for a in await quick_actions(client, uri, camera)]
    assert not any(t.startswith("Fix ") or "every safe fix" in t for t in titles)
    assert await fix_all_actions(client, uri) == []
    close_documents(client, uri)
