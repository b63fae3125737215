"""Races in the language server, each placed deterministically: a message of
the editor that lands while a lint starts, runs or answers. Unplaced, each
showed now and then (the stress test of test_stress.py found them): a
document left with an older text's diagnostics, or none."""

from __future__ import annotations

from pathlib import Path

import pytest

FINE = '#usda 1.0\ndef RenderSettings "S"\n{\n    uniform int2 resolution = (0, 10)\n}\n'


def test_a_settings_change_as_the_server_starts_does_not_stop_its_linting(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Neovim sends the editor's settings right after initialized: a new
    ``configuration`` in them ended the child the server was starting, the
    start failed as "cancelled", and the server never linted a document."""
    from usdrender_lint.server import worker

    path = tmp_path / "shot.usda"
    path.write_text(FINE)
    linting = worker.Linting()
    real_ready = worker.Child.ready
    changed: list[worker.Child] = []

    def settings_come_in(child: worker.Child, timeout: float = worker.START_TIMEOUT):
        if not changed:
            changed.append(child)
            linting.reconfigure({"ignore": ["SE015"]})  # didChangeConfiguration
        return real_ready(child, timeout)

    monkeypatch.setattr(worker.Child, "ready", settings_come_in)
    try:
        assert "SE001" in {rule.code for rule in linting.start()}
        linted = linting.call("lint", str(path), 1, (str(path),), {}, 60.0)
        codes = {f.code for f in linted.findings}
        assert changed and "SE001" in codes and "SE015" not in codes
    finally:
        linting.close()
