"""Where a lint was when it timed out, for the time-out's message: "timed out after
120 s in rule CA005 (camera-optics-invalid)" says whose code to look at.

The process that times a lint (the supervisor for a lone file, the pool for a
worker's) asks the timed process for its Python stack before it kills it:
:func:`listen` has Python's faulthandler write every thread's stack to a file
descriptor on STALL_SIGNAL, from inside the signal handler, so it answers even while
USD's C++ holds the interpreter. :func:`site` reads the stack: the frame the engine
runs a rule's hook in names the rule (its module and line, looked up among the rule
classes this process imported), or the step the engine was in.
"""

from __future__ import annotations

import faulthandler
import re
import sys
import time
from collections.abc import Callable

from .interrupts import STALL_SIGNAL

#: Seconds the stack may take to arrive (the handler writes it at once).
DUMP_WAIT = 0.5
#: Seconds the rest of a stack takes once it has begun.
_QUIET = 0.05
#: Compiled when a stack is read (a time-out), not at start-up.
_FRAME = r'^\s+File "(.*)", line (\d+) in (\S+)\s*$'
_THREAD = r"^(?:Current thread|Thread) 0x[0-9a-f]+ "

Frame = tuple[str, int, str]


def listen(fd: int) -> None:
    """In a timed process: write every thread's Python stack to ``fd`` on STALL_SIGNAL."""
    faulthandler.register(STALL_SIGNAL, file=fd, all_threads=True)


def collect(read: Callable[[], str], wait: float = DUMP_WAIT) -> str:
    """What ``read()`` (the dump received so far) gives once the stack asked for has
    come, or after ``wait`` seconds (a process that cannot answer)."""
    deadline = time.monotonic() + wait
    while time.monotonic() < deadline:
        if "most recent call first" in read():
            time.sleep(_QUIET)  # the rest of it follows at once
            break
        time.sleep(0.01)
    return read()


def frames(dump: str) -> list[list[Frame]]:
    """Each thread's frames in a faulthandler dump, the most recent first."""
    threads: list[list[Frame]] = []
    for line in dump.splitlines():
        if re.match(_THREAD, line):
            threads.append([])
            continue
        found = re.match(_FRAME, line)
        if found and threads:
            threads[-1].append((found[1], int(found[2]), found[3]))
    return threads


def site(dump: str) -> str | None:
    """Where the dumped lint was ("in rule CA005 (camera-optics-invalid)", "while USD
    opened the stage"), or None when the stack shows no step of a lint."""
    from ..engine import linter, partial, stage

    steps = {
        _key(linter.Linter._run): None,  # a rule's hook: the frame above
        _key(stage.open_stage): "while USD opened the stage",
        _key(partial.open_partial): "while USD opened the stage",
        _key(linter.Linter._decide_profiles): "while the renderer profiles were decided",
        _key(linter.Linter._walk): "while the stage was walked",
    }
    for thread in frames(dump):
        for index, (file, _, name) in enumerate(thread):
            if (file, name) not in steps:
                continue
            phrase = steps[(file, name)]
            if phrase is None:
                return _rule_phrase(*thread[index - 1]) if index else None
            return phrase
    return None


def _key(function: Callable[..., object]) -> tuple[str, str]:
    code = function.__code__
    return code.co_filename, code.co_name


def _rule_phrase(file: str, line: int, name: str) -> str:
    """The rule whose hook ``name`` spans ``line`` of ``file`` (among the rule
    classes of the modules this process imported)."""
    from ..api import Rule

    for module in list(sys.modules.values()):
        if getattr(module, "__file__", None) != file:
            continue
        for value in vars(module).values():
            if not (isinstance(value, type) and issubclass(value, Rule)):
                continue
            hook = value.__dict__.get(name)
            code = getattr(hook, "__code__", None)
            if code is not None and _spans(code, line) and getattr(value, "code", None):
                return f"in rule {value.code} ({value.name})"
    return f"in a rule's {name} ({file}:{line})"


def _spans(code, line: int) -> bool:  # noqa: ANN001 - a code object
    lines = [number for _, _, number in code.co_lines() if number is not None]
    return bool(lines) and min(code.co_firstlineno, *lines) <= line <= max(lines)


__all__ = ["DUMP_WAIT", "STALL_SIGNAL", "collect", "frames", "listen", "site"]
