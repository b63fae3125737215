"""``usdrender-lint server``: the language server for editors."""

from __future__ import annotations

import click


@click.command("server")
def server_command() -> None:
    """Run the language server for editors (LSP over stdio; the [server] extra)."""
    from ..server import main as serve

    serve()
