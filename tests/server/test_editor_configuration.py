"""The editor's ``configuration`` (initializationOptions, as ruff's server reads it):
a configuration file every document is linted with, or settings laid over each
document's nearest configuration; each gives the editor what ``check --config``
gives the file. A server per way (its children start with the configuration)."""

from __future__ import annotations

import asyncio
import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import pytest_lsp
from lsprotocol import types
from pytest_lsp import LanguageClient, client_capabilities
from test_protocol import BROKEN_SHOT, SERVER, diagnostics_of, history, open_document

pytestmark = [
    pytest.mark.asyncio(loop_scope="module"),
    pytest.mark.heavy(seconds=22),
]

BIN = Path(sys.executable).parent / "usdrender-lint"
#: The show's own configuration (the nearest), and a studio's file elsewhere.
NEAREST = '[severity]\nSE003 = "warning"\n'
STUDIO = 'ignore = ["CA004"]\n'
TABLE = {"severity": {"CA004": "warning"}, "extend-select": ["UL001"]}


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("configured")
    (root / "show").mkdir()
    shutil.copy(BROKEN_SHOT, root / "show" / "shot.usda")
    (root / "show" / ".usdrender-lint.toml").write_text(NEAREST)
    (root / "studio.toml").write_text(STUDIO)
    return root


async def _client(lsp_client: LanguageClient, workspace: Path, configuration: object) -> None:
    await lsp_client.initialize_session(
        types.InitializeParams(
            capabilities=client_capabilities("visual-studio-code"),
            root_uri=workspace.as_uri(),
            initialization_options={"configuration": configuration},
        )
    )


@pytest_lsp.fixture(scope="module", config=SERVER)
async def with_table(lsp_client: LanguageClient, workspace: Path):
    await _client(lsp_client, workspace, TABLE)
    yield
    await lsp_client.shutdown_session()


@pytest_lsp.fixture(scope="module", config=SERVER)
async def with_file(lsp_client: LanguageClient, workspace: Path):
    await _client(lsp_client, workspace, str(workspace / "studio.toml"))
    yield
    await lsp_client.shutdown_session()


@pytest_lsp.fixture(scope="module", config=SERVER)
async def with_bad_table(lsp_client: LanguageClient, workspace: Path):
    await _client(lsp_client, workspace, {"selct": 1})
    yield
    await lsp_client.shutdown_session()


SEVERITY = {
    types.DiagnosticSeverity.Error: "error",
    types.DiagnosticSeverity.Warning: "warning",
    types.DiagnosticSeverity.Information: "info",
}


def _severities(found: list[types.Diagnostic]) -> dict[str, str]:
    return {str(d.code): SEVERITY[d.severity] for d in found if d.severity is not None}


async def _served(client: LanguageClient, workspace: Path) -> dict[str, str]:
    uri = open_document(client, workspace / "show" / "shot.usda")
    return _severities(await diagnostics_of(client, uri, 1))


def history_of(uri: str) -> list[list[types.Diagnostic]]:
    """Every publication of ``uri``'s diagnostics, by any server of the session."""
    return [found for published, found in history if published == uri]


async def _published_after(client: LanguageClient, uri: str, count: int) -> dict[str, str]:
    """The diagnostics of ``uri``'s next publication after its ``count`` first."""
    async with asyncio.timeout(60):
        while len(history_of(uri)) <= count:
            await client.wait_for_notification(types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
    return _severities(history_of(uri)[count])


def _checked(workspace: Path, *args: str) -> dict[str, str]:
    run = subprocess.run(
        [str(BIN), "check", "--no-cache", "--show-info", "--format", "json", *args, "show"],
        cwd=workspace,
        capture_output=True,
        text=True,
        check=False,
    )
    (entry,) = json.loads(run.stdout)["files"]
    return {f["code"]: f["severity"] for f in entry["findings"]}


async def test_a_table_is_laid_over_each_documents_nearest(
    with_table: LanguageClient, workspace: Path
) -> None:
    served = await _served(with_table, workspace)
    assert served["CA004"] == "warning" and served["SE003"] == "warning"  # the nearest's too
    given = ("--config", 'severity.CA004 = "warning"', "--config", 'extend-select = ["UL001"]')
    assert served == _checked(workspace, *given)


async def test_a_file_is_every_documents_configuration(
    with_file: LanguageClient, workspace: Path
) -> None:
    served = await _served(with_file, workspace)
    assert "CA004" not in served and served["SE003"] == "error"  # the nearest is not read
    assert served == _checked(workspace, "--config", str(workspace / "studio.toml"))


async def test_a_bad_table_is_the_documents_one_error(
    with_bad_table: LanguageClient, workspace: Path
) -> None:
    uri = open_document(with_bad_table, workspace / "show" / "shot.usda")
    (error,) = await diagnostics_of(with_bad_table, uri, 1)
    assert error.message == (
        "the editor's configuration: unknown key 'selct' (did you mean 'select'?)"
    )


async def test_a_settings_change_relints_with_the_new_configuration(
    with_bad_table: LanguageClient, workspace: Path
) -> None:
    """workspace/didChangeConfiguration, ours under our name as Neovim sends them:
    the open documents are linted again with the new configuration."""
    uri = (workspace / "show" / "shot.usda").as_uri()
    before = len(history_of(uri))
    with_bad_table.workspace_did_change_configuration(
        types.DidChangeConfigurationParams(settings={"usdrender-lint": {"configuration": TABLE}})
    )
    served = await _published_after(with_bad_table, uri, before)
    given = ("--config", 'severity.CA004 = "warning"', "--config", 'extend-select = ["UL001"]')
    assert served == _checked(workspace, *given)
    # Settings of other tools, or the same configuration again, change nothing.
    with_bad_table.workspace_did_change_configuration(
        types.DidChangeConfigurationParams(settings={"other-tool": {"x": 1}})
    )
    with_bad_table.workspace_did_change_configuration(
        types.DidChangeConfigurationParams(settings={"configuration": TABLE})
    )
    await asyncio.sleep(2)
    assert len(history_of(uri)) == before + 1
