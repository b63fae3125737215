"""The language server gives every real text layer (``../shared/corpus``) the
findings ``check`` gives it: each file opened alone in the editor, as saved,
its diagnostics (every finding on the document; one in a layer that is not open
is shown there too, with the layer as related information) against ``check
--no-cache --show-info`` of the same files; and its Fix All makes the text
``check --fix`` writes (each layer whose fixes are all its own).

The differential test of the other paths is tests/running/test_paths_agree.py.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from collections import Counter
from pathlib import Path

import pytest
import pytest_lsp
from conftest import SHARED
from lsprotocol import types
from pytest_lsp import LanguageClient
from test_protocol import (
    SERVER,
    apply,
    close_documents,
    diagnostics_of,
    fix_all_actions,
    open_document,
    start_session,
)

pytestmark = [pytest.mark.asyncio(loop_scope="module"), pytest.mark.heavy(seconds=52)]

CORPUS = SHARED / "corpus" / "files"
#: What a finding is, for the comparison (what a diagnostic carries of it).
SEVERITY = {
    types.DiagnosticSeverity.Error: "error",
    types.DiagnosticSeverity.Warning: "warning",
    types.DiagnosticSeverity.Information: "info",
    types.DiagnosticSeverity.Hint: "info",
}


def _text_layers() -> list[Path]:
    if not CORPUS.is_dir():
        return []
    found = []
    for path in sorted(CORPUS.rglob("*")):
        if path.suffix.lower() not in (".usd", ".usda") or not path.is_file():
            continue
        with path.open("rb") as file:
            if file.read(8) == b"PXR-USDC":
                continue
        try:
            path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            continue  # an editor would not open it as this text
        found.append(path)
    return found


LAYERS = _text_layers()


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    if not LAYERS:
        pytest.skip("../shared is not present (only on developer machines and in CI)")
    return CORPUS


@pytest_lsp.fixture(scope="module", config=SERVER)
async def client(lsp_client: LanguageClient, workspace: Path):
    await start_session(lsp_client, workspace, "corpus")
    yield
    await lsp_client.shutdown_session()


def _checked() -> dict[str, Counter]:
    """``check``'s findings of every layer, by its file, as the diagnostics carry them."""
    done = subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "check", "--no-cache", "--format", "json"]
        + ["--show-info", "--fail-on", "never", *map(str, LAYERS)],
        capture_output=True,
        timeout=600,
        cwd=CORPUS,
    )
    assert done.returncode in (0, 2), done.stderr[-3000:]
    return {
        entry["file"]: Counter(
            (f["code"], f["path"], f["message"], f["severity"], f["profile"])
            for f in entry["findings"]
        )
        for entry in json.loads(done.stdout)["files"]
    }


async def test_every_real_text_layer_gets_check_s_findings_in_the_editor(
    client: LanguageClient, workspace: Path
) -> None:
    checked = _checked()
    assert len(checked) == len(LAYERS) > 100
    differing = []
    for path in LAYERS:
        uri = open_document(client, path)
        shown = await diagnostics_of(client, uri, 1)
        close_documents(client, uri)
        got = Counter(
            (d.code, d.data["path"], d.message, SEVERITY[d.severity], d.data["profile"])
            for d in shown
        )
        expected = checked[str(path)]
        if got != expected:
            differing.append(f"{path}: only check {expected - got}; only here {got - expected}")
    assert differing == []


def _fixed_by_check(root: Path) -> dict[str, str]:
    """``check --fix`` of a copy of the corpus at ``root``: the text of each
    layer whose fixes are all its own, by its path in the corpus."""
    shutil.copytree(CORPUS, root)
    for folder, _, files in os.walk(root):
        for name in files:
            os.chmod(os.path.join(folder, name), 0o644)  # the corpus is read-only
    done = subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "check", "--no-cache", "--fix"]
        + ["--fail-on", "never", "--format", "json", "."],
        capture_output=True,
        timeout=600,
        cwd=root,
    )
    assert done.returncode in (0, 2), done.stderr[-3000:]
    layers: dict[str, set[str | None]] = {}
    for fix in json.loads(done.stdout)["fixes"]:
        layer = os.path.normpath(fix["layer"]) if fix["layer"] else None
        layers.setdefault(os.path.normpath(fix["file"]), set()).add(layer)
    own = [file for file, touched in layers.items() if touched == {file}]
    return {str(CORPUS / file): (root / file).read_text() for file in own}


async def test_fix_all_makes_the_text_check_fix_writes(
    client: LanguageClient, workspace: Path, tmp_path: Path
) -> None:
    fixed = _fixed_by_check(tmp_path / "files")
    assert len(fixed) > 50
    differing = []
    for path in LAYERS:
        uri = open_document(client, path)
        await diagnostics_of(client, uri, 1)
        actions = await fix_all_actions(client, uri)
        close_documents(client, uri)
        text = path.read_text()
        if str(path) not in fixed:
            continue  # no fix, or one in another layer: Fix All edits this document alone
        edited = apply(text, actions[0].edit.changes[uri]) if actions else text
        if edited != fixed[str(path)]:
            differing.append(str(path))
    assert differing == []
