"""The language server's latency (issue 29), beside a bare ``Usd.Stage.Open``
of the same text in this process, in the same run.

- **typing**: a 1,000-prim ``.usda`` render template is open in the server;
  each round makes a one-character edit (an incremental ``didChange``) and
  times it until the ``publishDiagnostics`` of that version arrives. Goal: a
  median of at most 50 ms. Its baseline: ``Usd.Stage.Open`` of the same text,
  written to a new file each round (so USD reads and parses it), in this
  process; the rounds alternate, so machine load hits both alike.
- **large** (skipped with ``--quick``): a 100k-prim ``.usda`` (about 15 MB).
  While its first lint runs, a hover is answered (the time shows the server
  does not wait for the lint); a one-character edit then cancels that lint,
  and the time from the edit to its diagnostics is printed beside a bare
  open of the text.

``--session`` prints instead the JSON-RPC messages of one editing session on
the broken example shot: open, diagnostics, code action, the edit applied,
the diagnostics after it, shutdown and exit.

    .venv/bin/python benchmarks/server_latency.py [--rounds 25] [--quick] [--session]
"""

from __future__ import annotations

import argparse
import json
import queue
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
BROKEN_SHOT = HERE.parent / "examples" / "broken_shot" / "shot.usda"


def template(prims: int) -> str:
    """A render template of ``prims`` prims: Xforms under /World, a camera and
    the render prims (one RenderSettings, product and var)."""
    nodes = "".join(
        f'    def Xform "node{i}"\n    {{\n        double3 xformOp:translate = ({i}, 0, 0)\n'
        '        uniform token[] xformOpOrder = ["xformOp:translate"]\n    }\n'
        for i in range(prims - 7)
    )
    return (
        '#usda 1.0\n(\n    defaultPrim = "World"\n    renderSettingsPrimPath = "/Render/Settings"\n'
        ')\n\ndef Xform "World"\n{\n'
        f'{nodes}    def Camera "cam"\n    {{\n        float focalLength = 35\n    }}\n}}\n\n'
        'def Scope "Render"\n{\n    def RenderSettings "Settings"\n    {\n'
        "        rel camera = </World/cam>\n        rel products = </Render/beauty>\n"
        "        uniform int2 resolution = (1920, 1080)\n    }\n"
        '    def RenderProduct "beauty"\n    {\n        token productName = "beauty.####.exr"\n'
        "        rel orderedVars = </Render/color>\n    }\n"
        '    def RenderVar "color"\n    {\n        uniform string sourceName = "Ci"\n    }\n}\n'
    )


class Client:
    """A minimal LSP client over the server's stdio; every message is kept
    (with the time it was sent or received) for --session."""

    def __init__(self, *, log: bool = False) -> None:
        self.process = subprocess.Popen(
            [sys.executable, "-m", "usdrender_lint", "server"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
        )
        self.log = log
        self.inbox: queue.Queue[dict | None] = queue.Queue()
        self.ids = 0
        #: The server's window/logMessage lines, as they arrive.
        self.logs: list[str] = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        stream = self.process.stdout
        assert stream is not None
        while True:
            length = None
            while True:
                line = stream.readline()
                if not line:
                    self.inbox.put(None)
                    return
                if not line.strip():
                    break
                name, _, value = line.decode().partition(":")
                if name.lower() == "content-length":
                    length = int(value)
            assert length is not None
            self.inbox.put(json.loads(stream.read(length)))

    def send(self, message: dict) -> None:
        message = {"jsonrpc": "2.0", **message}
        if self.log:
            print(f"--> {json.dumps(message)}")
        data = json.dumps(message).encode()
        assert self.process.stdin is not None
        self.process.stdin.write(b"Content-Length: %d\r\n\r\n" % len(data) + data)
        self.process.stdin.flush()

    def request(self, method: str, params: dict | None = None, timeout: float = 600) -> dict:
        self.ids += 1
        ident = self.ids
        self.send({"id": ident, "method": method, "params": params})
        return self.wait(lambda m: m.get("id") == ident, timeout)

    def notify(self, method: str, params: dict) -> None:
        self.send({"method": method, "params": params})

    def wait(self, wanted, timeout: float = 600) -> dict:
        deadline = time.perf_counter() + timeout
        while True:
            message = self.inbox.get(timeout=max(deadline - time.perf_counter(), 0.001))
            if message is None:
                raise RuntimeError("the server closed its output")
            if self.log:
                print(f"<-- {json.dumps(message)}")
            if message.get("method") == "window/logMessage":
                self.logs.append(message["params"]["message"])
            if message.get("method") == "client/registerCapability":
                self.send({"id": message["id"], "result": None})
            if wanted(message):
                return message

    def diagnostics(self, uri: str, version: int, timeout: float = 600) -> dict:
        return self.wait(
            lambda m: (
                m.get("method") == "textDocument/publishDiagnostics"
                and m["params"]["uri"] == uri
                and m["params"].get("version") == version
            ),
            timeout,
        )

    def start(self, root: Path) -> None:
        """Initialize, and wait until the server lints (a first small document)."""
        self.request(
            "initialize",
            {"processId": None, "rootUri": root.as_uri(), "capabilities": {}},
        )
        self.notify("initialized", {})
        self.diagnostics(self.open(root / "ready.usda", "#usda 1.0\n"), 1)

    def open(self, path: Path, text: str) -> str:
        uri = path.as_uri()
        self.notify(
            "textDocument/didOpen",
            {"textDocument": {"uri": uri, "languageId": "usda", "version": 1, "text": text}},
        )
        return uri

    def stop(self) -> int:
        self.request("shutdown")
        self.notify("exit", {})
        return self.process.wait(timeout=30)


def _bare_open(text: str, folder: Path, index: int) -> float:
    from pxr import Usd

    path = folder / f"bare{index}.usda"
    path.write_text(text)
    started = time.perf_counter()
    stage = Usd.Stage.Open(str(path))
    elapsed = time.perf_counter() - started
    del stage
    return elapsed


def _ms(seconds: float) -> str:
    return f"{seconds * 1000:.1f} ms"


def typing(rounds: int, folder: Path) -> None:
    text = template(1000)
    client = Client()
    client.start(folder)
    path = folder / "template.usda"
    uri = client.open(path, text)
    client.diagnostics(uri, 1)
    lines = text.split("\n")
    line = next(i for i, x in enumerate(lines) if "(500, 0, 0)" in x)
    column = lines[line].index("(500") + 3  # the last digit of 500
    relints, opens, ratios = [], [], []
    for version in range(2, rounds + 2):
        digit = str(version % 10)
        edit = {
            "range": {
                "start": {"line": line, "character": column},
                "end": {"line": line, "character": column + 1},
            },
            "text": digit,
        }
        started = time.perf_counter()
        client.notify(
            "textDocument/didChange",
            {"textDocument": {"uri": uri, "version": version}, "contentChanges": [edit]},
        )
        client.diagnostics(uri, version)
        relint = time.perf_counter() - started
        lines[line] = lines[line][:column] + digit + lines[line][column + 1 :]
        bare = _bare_open("\n".join(lines), folder, version)
        relints.append(relint)
        opens.append(bare)
        ratios.append(relint / bare)
    client.stop()
    relint, bare = statistics.median(relints), statistics.median(opens)
    print(f"typing: a 1,000-prim .usda ({len(text):,} characters), {rounds} one-character edits")
    print(
        f"  edit -> diagnostics   median {_ms(relint)}  (min {_ms(min(relints))}, "
        f"max {_ms(max(relints))})  goal <= 50 ms"
    )
    print(
        f"  bare Usd.Stage.Open   median {_ms(bare)}  (min {_ms(min(opens))}, "
        f"max {_ms(max(opens))})"
    )
    print(f"  ratio {relint / bare:.2f}x (paired {statistics.median(ratios):.2f}x)")


def large(folder: Path) -> None:
    text = template(100_000)
    bare = _bare_open(text, folder, 0)
    client = Client()
    client.start(folder)
    path = folder / "large.usda"
    uri = client.open(path, text)
    time.sleep(1.0)  # its first lint runs now
    started = time.perf_counter()
    client.request(
        "textDocument/hover",
        {"textDocument": {"uri": uri}, "position": {"line": 8, "character": 8}},
    )
    hover = time.perf_counter() - started
    line = text.split("\n").index("        double3 xformOp:translate = (5, 0, 0)")
    started = time.perf_counter()
    client.notify(
        "textDocument/didChange",
        {
            "textDocument": {"uri": uri, "version": 2},
            "contentChanges": [
                {
                    "range": {
                        "start": {"line": line, "character": 37},
                        "end": {"line": line, "character": 38},
                    },
                    "text": "6",
                }
            ],
        },
    )
    client.diagnostics(uri, 2)
    edit = time.perf_counter() - started
    cancelled = [line for line in client.logs if "cancelled" in line]
    client.stop()
    print(f"large: a 100k-prim .usda ({len(text) / 1e6:.1f} MB)")
    print(f"  hover while its first lint runs   {_ms(hover)}")
    said = cancelled[0] if cancelled else "the first lint was NOT cancelled"
    print(f"  edit -> its diagnostics           {edit:.2f} s ({said})")
    print(f"  bare Usd.Stage.Open of the text   {bare:.2f} s  ratio {edit / bare:.2f}x")


def session() -> None:
    """One editing session's messages, as an editor exchanges them."""
    text = BROKEN_SHOT.read_text()
    with tempfile.TemporaryDirectory() as work:
        folder = Path(work)
        path = folder / "shot.usda"
        path.write_text(text)
        client = Client(log=True)
        client.start(folder)
        uri = client.open(path, text)
        published = client.diagnostics(uri, 1)
        camera = next(d for d in published["params"]["diagnostics"] if d["code"] == "CA004")
        actions = client.request(
            "textDocument/codeAction",
            {
                "textDocument": {"uri": uri},
                "range": camera["range"],
                "context": {"diagnostics": [camera]},
            },
        )
        (edit,) = actions["result"][0]["edit"]["changes"][uri]
        client.notify(
            "textDocument/didChange",
            {
                "textDocument": {"uri": uri, "version": 2},
                "contentChanges": [{"range": edit["range"], "text": edit["newText"]}],
            },
        )
        client.diagnostics(uri, 2)
        print(f"exit status {client.stop()}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=25)
    parser.add_argument("--quick", action="store_true", help="the typing figure only")
    parser.add_argument("--session", action="store_true", help="print one session's messages")
    options = parser.parse_args(argv)
    if options.session:
        session()
        return 0
    with tempfile.TemporaryDirectory() as work:
        typing(options.rounds, Path(work))
        if not options.quick:
            large(Path(work))
    return 0


if __name__ == "__main__":
    sys.exit(main())
