"""The suite's own check that a test leaves no thread running (tests/conftest.py)."""

from __future__ import annotations

import sys
import threading
import time

import pytest
from thread_support import busy_threads

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc")


def test_a_thread_left_looping_is_found_and_a_waiting_one_is_not() -> None:
    stop = threading.Event()

    def loop() -> None:
        while not stop.is_set():
            pass

    looping = threading.Thread(target=loop, name="looping", daemon=True)
    waiting = threading.Thread(target=stop.wait, name="waiting", daemon=True)
    looping.start()
    waiting.start()
    try:
        time.sleep(0.05)
        found = busy_threads()
    finally:
        stop.set()
        looping.join()
        waiting.join()
    assert [name.split(" ")[0] for name in found] == ["looping"]
    assert busy_threads() == []
