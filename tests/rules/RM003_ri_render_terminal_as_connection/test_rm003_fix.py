"""RM003's fix: a text edit of the connection's own line, safe only when the
relationship has no targets (otherwise it changes which integrator renders)."""

from __future__ import annotations

import shutil
from pathlib import Path

from fix_support import check
from pxr import Sdf, Usd

FOLDER = Path(__file__).parent


def _copy(name: str, tmp_path: Path) -> Path:
    for path in FOLDER.glob("*.usda"):
        if path.name == name or not path.name.startswith(("pass_", "fail_")):
            shutil.copy(path, tmp_path / path.name)
    return tmp_path / name


def test_the_fix_edits_only_the_connection_line(tmp_path: Path) -> None:
    path = _copy("fail_mixed.usda", tmp_path)
    before = path.read_text(encoding="utf-8").splitlines()
    result, _ = check("--select", "RM003", "--fix", str(path))
    assert result.exit_code == 0, result.output
    after = path.read_text(encoding="utf-8").splitlines()
    changed = [(a, b) for a, b in zip(before, after, strict=True) if a != b]
    assert changed == [
        (
            "        token outputs:ri:displayFilters.connect = </Render/Background.outputs:result>",
            "        rel ri:displayFilters = </Render/Background>",
        )
    ]
    assert "        # The display filter, still connected the old way." in after


def test_the_fix_over_a_weaker_relationship_is_unsafe(tmp_path: Path) -> None:
    path = _copy("fail_relationship_in_weaker_layer.usda", tmp_path)
    result, document = check("--select", "RM003", "--fix", str(path))
    assert result.exit_code == 0, result.output  # a warning
    assert not [fix for fix in document["fixes"] if fix["applied"]]
    (finding,) = document["files"][0]["findings"]
    assert finding["fix"]["safe"] is False
    result, _ = check("--select", "RM003", "--fix", "--unsafe-fixes", str(path))
    assert result.exit_code == 0, result.output
    stage = Usd.Stage.Open(str(path))
    settings = stage.GetPrimAtPath("/Render/Settings")
    assert settings.GetRelationship("ri:integrator").GetTargets() == [Sdf.Path("/Render/Direct")]
    assert not settings.GetAttribute("outputs:ri:integrator").HasAuthoredConnections()
    assert (tmp_path / "rels_layer.usda").read_text(encoding="utf-8") == (
        FOLDER / "rels_layer.usda"
    ).read_text(encoding="utf-8")
