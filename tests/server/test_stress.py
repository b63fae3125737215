"""A real server driven through rapid, seeded sequences of open, change, save,
close and settings changes over documents that sublayer each other: once the
editor stops, every open document shows the diagnostics of its latest text
(what ``check`` says of that text, sublayers and all) and every closed one
shows none.

Each race the server had of this kind left a document showing an older text's
diagnostics, or none, until its next edit; the deterministic tests that place
each interleaving are in test_robust.py and test_races.py."""

from __future__ import annotations

import json
import os
import random
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest
from lsp_editor import Editor

from usdrender_lint.server.protocol import NAME

pytestmark = pytest.mark.heavy(seconds=17)

#: The documents: d0 (a shot) may sublayer d1..d3, d1 may sublayer d2 and d3, ...
DOCUMENTS = 4
#: Seconds the server may take to settle once the editor stops (2 busy cores).
SETTLE = 30.0
#: LSP's DiagnosticSeverity of check's severities.
SEVERITY = {"error": 1, "warning": 2, "info": 3}
#: The editor's configurations the settings switch between (a table, as --config).
CONFIGURATIONS: list[dict[str, Any] | None] = [
    None,
    {"ignore": ["SE015"]},
    {"severity": {"SE001": "warning"}},
]


def random_text(rng: random.Random, index: int, version: int) -> str:
    """Document ``index``'s text: sublayers of later documents, and a
    RenderSettings whose resolution is sometimes wrong."""
    below = [j for j in range(index + 1, DOCUMENTS) if rng.random() < 0.5]
    head = "#usda 1.0\n"
    if below:
        layers = ", ".join(f"@./d{j}.usda@" for j in below)
        head += f"(\n    subLayers = [{layers}]\n)\n"
    width = rng.choice([-1, 0, 640, 1920])
    height = rng.choice([0, 480, 1080])
    return (
        f"{head}# edit {version}\n"
        f'def Scope "Render"\n{{\n    def RenderSettings "S{index}"\n    {{\n'
        f"        uniform int2 resolution = ({width}, {height})\n    }}\n}}\n"
    )


class Documents:
    """The editor's documents, and what it does to them."""

    def __init__(self, editor: Editor, folder: Path, rng: random.Random) -> None:
        self.editor = editor
        self.folder = folder
        self.rng = rng
        self.paths = [folder / f"d{i}.usda" for i in range(DOCUMENTS)]
        #: The open documents' versions and texts, by index.
        self.open: dict[int, tuple[int, str]] = {}
        self.configuration: dict[str, Any] | None = None
        for i, path in enumerate(self.paths):
            path.write_text(random_text(rng, i, 0))

    def uri(self, index: int) -> str:
        return self.paths[index].as_uri()

    def step(self) -> None:
        rng = self.rng
        roll = rng.random()
        index = rng.randrange(DOCUMENTS)
        if roll < 0.03:
            self.configuration = rng.choice([c for c in CONFIGURATIONS if c != self.configuration])
            settings = {NAME: {"configuration": self.configuration}}
            self.editor.notify("workspace/didChangeConfiguration", {"settings": settings})
        elif index not in self.open:
            text = rng.choice([self.paths[index].read_text(), random_text(rng, index, 1)])
            self.open[index] = (1, text)
            item = {"uri": self.uri(index), "languageId": "usda", "version": 1, "text": text}
            self.editor.notify("textDocument/didOpen", {"textDocument": item})
        elif roll < 0.15:
            del self.open[index]
            self.editor.notify("textDocument/didClose", {"textDocument": {"uri": self.uri(index)}})
        elif roll < 0.25:
            self.paths[index].write_text(self.open[index][1])
            self.editor.notify("textDocument/didSave", {"textDocument": {"uri": self.uri(index)}})
        else:
            version = self.open[index][0] + 1
            text = random_text(rng, index, version)
            self.open[index] = (version, text)
            self.editor.notify(
                "textDocument/didChange",
                {
                    "textDocument": {"uri": self.uri(index), "version": version},
                    "contentChanges": [{"text": text}],
                },
            )

    def expected(self) -> dict[str, set[tuple[str, str, int]]]:
        """What ``check`` says of each open document's text, on the URI the
        server shows each finding on: the layer's when it is open, else the
        document's. (The open texts are written to their files for check, which
        the server, holding them open, does not read.)"""
        for index, (_, text) in self.open.items():
            self.paths[index].write_text(text)
        found: dict[str, set[tuple[str, str, int]]] = {self.uri(i): set() for i in self.open}
        if not self.open:
            return found
        given = []
        for key, value in (self.configuration or {}).items():
            for name, each in value.items() if isinstance(value, dict) else [("", value)]:
                given += ["--config", f"{key}{'.' if name else ''}{name} = {json.dumps(each)}"]
        names = [self.paths[i].name for i in sorted(self.open)]
        run = subprocess.run(
            [sys.executable, "-m", "usdrender_lint", "check", "--no-cache", "--show-info"]
            + ["--format", "json", *given, *names],
            cwd=self.folder,
            capture_output=True,
            text=True,
            check=False,
        )
        open_files = {self.paths[i].name: self.uri(i) for i in self.open}
        for entry in json.loads(run.stdout)["files"]:
            uri = open_files[entry["file"]]
            for finding in entry["findings"]:
                target = open_files.get(finding["layer"] or entry["file"], uri)
                found[target].add(
                    (finding["code"], finding["message"], SEVERITY[finding["severity"]])
                )
        return found

    def shown(self) -> dict[str, tuple[int | None, set[tuple[str, str, int]]]]:
        with self.editor.lock:
            return {
                uri: (version, {(d["code"], d["message"], d["severity"]) for d in diagnostics})
                for uri, (version, diagnostics) in self.editor.published.items()
            }

    def settled(self) -> list[str]:
        """Wait for the server to show what check says; what it does not, if it never does."""
        expected = self.expected()
        deadline = time.monotonic() + SETTLE
        while True:
            shown = self.shown()
            wrong = []
            for index in range(DOCUMENTS):
                uri = self.uri(index)
                version, diagnostics = shown.get(uri, (None, set()))
                if index in self.open:
                    latest = self.open[index][0]
                    if version != latest or diagnostics != expected[uri]:
                        wrong.append(
                            f"d{index} (version {latest}) shows version {version}: "
                            f"{sorted(diagnostics)}, check says {sorted(expected[uri])}"
                        )
                elif diagnostics:
                    wrong.append(f"d{index} (closed) shows {sorted(diagnostics)}")
            if not wrong or time.monotonic() > deadline:
                return wrong
            time.sleep(0.2)


#: The seeds run (each a sequence of edits; more, to look further:
#: ``USDRENDER_LINT_STRESS_SEEDS="1 2 3" pytest -n0 tests/server/test_stress.py``).
SEEDS = [int(s) for s in os.environ.get("USDRENDER_LINT_STRESS_SEEDS", "6").split()]


@pytest.mark.parametrize("seed", SEEDS)
def test_every_open_document_ends_showing_its_latest_text_s_findings(
    tmp_path: Path, seed: int
) -> None:
    rng = random.Random(seed)
    editor = Editor(tmp_path / "server.log")
    try:
        documents = Documents(editor, tmp_path, rng)
        for round_ in range(4):
            for _ in range(35):
                documents.step()
                time.sleep(rng.choice([0.0, 0.0, 0.0, 0.005, 0.02, 0.08]))
            wrong = documents.settled()
            assert not wrong, f"seed {seed}, round {round_}:\n" + "\n".join(wrong)
    finally:
        editor.end()
