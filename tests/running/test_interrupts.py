"""A signal that lands where Python cannot raise (a weakref callback, as importlib's
module locks use during an import) prints no traceback; the run still stops."""

import subprocess
import sys

import pytest

from usdrender_lint.running import interrupts

SIGNAL_IN_A_CALLBACK = """
import os, signal, sys, weakref
from usdrender_lint.running import interrupts
interrupts.install()
class Held: pass
held = Held()
ref = weakref.ref(held, lambda _: os.kill(os.getpid(), signal.SIGINT))
del held  # the callback runs here: the handler's Stopped cannot propagate from it
try:
    interrupts.check_stopped()
except interrupts.Stopped as stopped:
    sys.stderr.write(f"usdrender-lint: {stopped.reason}\\n")
    sys.exit(stopped.exit_status)
"""

OTHER_UNRAISABLE = """
import weakref
from usdrender_lint.running import interrupts
interrupts.install()
class Held: pass
held = Held()
ref = weakref.ref(held, lambda _: 1 / 0)
del held
"""


def _run(code: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)


def test_a_signal_in_a_weakref_callback_stops_the_run_without_a_traceback() -> None:
    done = _run(SIGNAL_IN_A_CALLBACK)
    assert done.returncode == 130
    assert done.stderr == "usdrender-lint: interrupted\n"


def test_other_unraisable_errors_are_still_shown() -> None:
    done = _run(OTHER_UNRAISABLE)
    assert "ZeroDivisionError" in done.stderr


def test_a_signal_whose_exception_was_swallowed_is_the_status_of_a_command_that_exits(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """click ends every command with sys.exit: a signal whose exception USD's
    C++ swallowed (the handler recorded it) ended the run 0, as if it never came."""
    monkeypatch.setattr(interrupts, "_received", None)
    with pytest.raises(interrupts.Stopped) as stopped, interrupts.stop_on_signals():
        interrupts._received = 15  # the handler ran; its exception went nowhere
        raise SystemExit(0)
    assert stopped.value.exit_status == 143
