"""The raw JSON-RPC editor the server's hard tests drive (lsp_editor.py)."""

from __future__ import annotations

import io
import subprocess
import sys
import threading
from typing import IO

import pytest
from lsp_editor import read_message


def test_a_message_is_read_after_its_headers() -> None:
    body = b'{"jsonrpc": "2.0", "id": 1, "result": null}'
    stream = io.BytesIO(
        b"Content-Length: %d\r\nContent-Type: x\r\n\r\n" % len(body) + body + b"\r\n"
    )
    assert read_message(stream) == {"jsonrpc": "2.0", "id": 1, "result": None}


def _ending(stream: IO[bytes]) -> str:
    """How a reader of ``stream`` ended within 10 s ("running" if it did not:
    a thread, so that a reader that never ends fails the test, not hangs it)."""
    ended = ["running"]

    def read() -> None:
        try:
            read_message(stream)
        except EOFError:
            ended[0] = "end of output"

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    reader.join(10)
    return ended[0]


@pytest.mark.parametrize("left", [b"", b"\r\n", b"Content-Length: 2\r\n"])
def test_the_servers_end_of_output_ends_the_reader(left: bytes) -> None:
    """A server that exited leaves its pipe at its end: the reader stops there.
    It once took the end for a blank line and spun for the rest of the test
    worker's life, on a core every later test needed."""
    assert _ending(io.BytesIO(left)) == "end of output"


def test_the_reader_of_an_exited_servers_pipe_ends() -> None:
    exited = subprocess.Popen([sys.executable, "-c", "pass"], stdout=subprocess.PIPE)
    exited.wait()
    assert exited.stdout is not None
    with exited.stdout:
        assert _ending(exited.stdout) == "end of output"
