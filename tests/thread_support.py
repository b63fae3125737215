"""Threads a test left running: the suite's check that every test's threads end with it."""

from __future__ import annotations

import os
import threading
import time


def _cpu_seconds() -> dict[threading.Thread, float]:
    """The CPU time of each Python thread of this process but the calling one,
    from ``/proc/self/task/<tid>/stat`` (Linux; none elsewhere)."""
    tick = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100
    seconds = {}
    for thread in threading.enumerate():
        if thread is threading.current_thread() or thread.native_id is None:
            continue
        try:
            with open(f"/proc/self/task/{thread.native_id}/stat") as stat:
                # After the name in parentheses: state, ppid, ... utime (12th), stime (13th).
                fields = stat.read().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue
        seconds[thread] = (int(fields[11]) + int(fields[12])) / tick
    return seconds


def busy_threads(window: float = 0.5) -> list[str]:
    """The Python threads that ran on a CPU for over a tenth of ``window``
    seconds while the calling thread slept: with no test running, none should
    (a waiting thread runs for none of it; a looping one on a loaded machine,
    beside the other test workers, for a third or more). (Two
    reader threads of the language-server tests once looped at their server's
    end of output for the rest of the worker's life, and the suite took twice
    as long.)"""
    before = _cpu_seconds()
    time.sleep(window)
    after = _cpu_seconds()
    return [
        f"{thread.name} ({after[thread] - before[thread]:.2f} s of CPU in {window} s)"
        for thread in after
        if thread in before and after[thread] - before[thread] > window / 10
    ]
