"""The language server (``usdrender-lint server``): findings, fixes and rule
documentation in the editor, from the same lint as ``check``.

It needs the ``[server]`` extra (pygls, lsprotocol); nothing else in the
package imports this one, so the command line never pays for it.
"""

from __future__ import annotations

import sys

from ..running.interrupts import check_stopped, deferred

#: What to install: the extra's packages (usdrender-lint is on no package index,
#: so ``pip install 'usdrender-lint[server]'`` would ask one for it).
MISSING = (
    "usdrender-lint: error: the language server needs its [server] extra: "
    "pip install 'pygls>=2.0' 'lsprotocol>=2025.0.0'"
)
#: The protocol's messages go to standard output.
NO_STDOUT = "usdrender-lint: error: standard output is closed: the language server speaks over it"


def main() -> None:
    """Serve the Language Server Protocol on stdin and stdout until the client
    says exit (or its process ends)."""
    try:
        with deferred():  # a Ctrl-C during USD's imports arrives after them, as in check
            from .protocol import serve
    except ImportError as exc:
        if exc.name not in ("pygls", "lsprotocol") and not str(exc.name).startswith("pygls."):
            raise
        sys.stderr.write(f"{MISSING}\n")
        sys.exit(2)
    if getattr(sys.stdout, "buffer", None) is None:  # started with it closed (cli.main)
        sys.stderr.write(f"{NO_STDOUT}\n")
        sys.exit(2)
    # Where another thread took the signal, its exception was raised during the
    # imports, in USD's C++, which swallowed it; the command's handler then ignored
    # the signals that followed, and the server never ended.
    check_stopped()
    _end_on_signals()
    serve()


def _end_on_signals() -> None:
    """Ctrl-C, SIGTERM and SIGHUP end the server at once, with the command's
    line and exit status (130, 143, 129). The command's own handler raises in
    the main thread, where pygls's loop then waits for its thread reading stdin,
    which nothing ends: the server hung, deaf to the signals that followed (the
    handler ignores them after the first). As when the client's process is gone
    (protocol.watch_client), nothing is left to save."""
    import os
    import signal

    from ..running.interrupts import STOPPING, not_ignored

    def end(signum: int, frame: object) -> None:
        os.write(2, f"usdrender-lint: {STOPPING[signal.Signals(signum)]}\n".encode())
        os._exit(128 + signum)

    for signum in not_ignored():
        signal.signal(signum, end)
