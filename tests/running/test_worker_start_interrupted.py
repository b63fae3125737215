"""Ctrl-C while workers start (``check --watch`` starts them from a fork
server, its file watch being a second thread): no worker prints a traceback.
Before, a worker restored the fork server's Python SIGINT handler and was
interrupted unpickling its arguments (KeyboardInterrupt), and one starting
after the run removed its log folder died of FileNotFoundError."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="no fork server")


def _run(folder: Path, script: str) -> subprocess.CompletedProcess[str]:
    # A file, not -c: the fork server's children import the script's functions.
    path = folder / "script.py"
    path.write_text(textwrap.dedent(script))
    return subprocess.run(
        [sys.executable, str(path)], capture_output=True, text=True, timeout=120, cwd=folder
    )


def test_a_worker_of_the_fork_server_ignores_sigint_from_its_start(tmp_path: Path) -> None:
    done = _run(
        tmp_path,
        """
        import signal, threading, time
        from usdrender_lint.running import workers

        def report(queue):
            queue.put(signal.getsignal(signal.SIGINT) == signal.SIG_IGN)

        if __name__ == "__main__":
            # a second thread, as --watch has: the workers come from the fork server
            threading.Thread(target=time.sleep, args=(30,), daemon=True).start()
            context = workers._context()
            assert context.get_start_method() == "forkserver"
            queue = context.SimpleQueue()
            process = context.Process(target=report, args=(queue,))
            process.start()
            print(queue.get())
            process.join()
            # the parent's own handler is as it was
            print(signal.getsignal(signal.SIGINT) is signal.default_int_handler)
        """,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["True", "True"]


def test_a_worker_starting_after_its_log_folder_went_ends_quietly(tmp_path: Path) -> None:
    done = _run(
        tmp_path,
        f"""
        import threading, time
        from usdrender_lint.running import workers

        def build():
            return None

        if __name__ == "__main__":
            threading.Thread(target=time.sleep, args=(30,), daemon=True).start()
            context = workers._context()
            parent_end, child_end = context.Pipe()
            pool = workers.Pool(build, 1, None)
            process = context.Process(
                target=workers._worker_main, args=(child_end, pool, {str(tmp_path / "gone")!r})
            )
            process.start()
            process.join(60)
            print(process.exitcode)
        """,
    )
    assert "Traceback" not in done.stderr, done.stderr
    assert done.stdout.split() == ["0"]
