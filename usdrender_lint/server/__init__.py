"""The language server (``usdrender-lint server``): findings, fixes and rule
documentation in the editor, from the same lint as ``check``.

It needs the ``[server]`` extra (pygls, lsprotocol); nothing else in the
package imports this one, so the command line never pays for it.
"""

from __future__ import annotations

import sys

MISSING = (
    "usdrender-lint: the language server needs the [server] extra: "
    "pip install 'usdrender-lint[server]'"
)


def main() -> None:
    """Serve the Language Server Protocol on stdin and stdout until the client
    says exit (or its process ends)."""
    try:
        from .protocol import serve
    except ImportError as exc:
        if exc.name not in ("pygls", "lsprotocol") and not str(exc.name).startswith("pygls."):
            raise
        sys.stderr.write(f"{MISSING}\n")
        sys.exit(2)
    serve()
