"""stage.arcs_problem: what it reads before USD composes a stage."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from pxr import Sdf

from usdrender_lint.engine import stage


def _no_resolver() -> None:
    raise AssertionError("a resolver context was made for a layer that names no layer")


def test_a_layer_naming_no_layer_is_not_walked(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    path = tmp_path / "shot.usda"
    path.write_text('#usda 1.0\ndef RenderSettings "Settings"\n{\n}\n')
    root = Sdf.Layer.FindOrOpen(str(path))
    monkeypatch.setattr(stage.Ar, "GetResolver", _no_resolver)
    assert stage.arcs_problem(root, str(path)) is None
    assert stage.arcs_problem(root, str(path), external=False) is None


def test_a_sublayer_is_still_read_and_held(tmp_path: Path) -> None:
    (tmp_path / "light.usda").write_text('#usda 1.0\ndef Scope "Light"\n{\n}\n')
    path = tmp_path / "shot.usda"
    path.write_text("#usda 1.0\n(\n    subLayers = [@light.usda@]\n)\n")
    held: list[Sdf.Layer] = []
    assert stage.arcs_problem(Sdf.Layer.FindOrOpen(str(path)), str(path), held=held) is None
    assert [Path(layer.realPath).name for layer in held] == ["light.usda"]


_NAMED_PIPE = "not a regular file (a named pipe or a device, whose open can wait forever)"


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
@pytest.mark.parametrize(
    ("opinion", "where"),
    [
        ("(\n    subLayers = [@./pipe.usda@]\n)\n", "pipe.usda"),
        ('def Scope "A" (\n    references = @./pipe.usda@\n)\n{\n}\n', "pipe.usda"),
        ('def Scope "A" (\n    payload = @./linked.usda@\n)\n{\n}\n', "linked.usda"),
        (
            'def Scope "A" (\n    variants = {\n        string v = "a"\n    }\n'
            '    prepend variantSets = "v"\n)\n{\n    variantSet "v" = {\n'
            '        "a" {\n        }\n        "b" (\n            references = @./pipe.usda@\n'
            "        ) {\n        }\n    }\n}\n",
            "pipe.usda",
        ),
    ],
    ids=["sublayer", "reference", "payload through a link", "unselected variant"],
)
def test_an_arc_to_a_named_pipe_is_refused_before_usd_opens_it(
    tmp_path: Path, opinion: str, where: str
) -> None:
    """USD's open of a named pipe waits for a writer, forever: the arc is refused
    as a root that is one is (the test would hang, not fail, without it)."""
    os.mkfifo(tmp_path / "pipe.usda")
    (tmp_path / "linked.usda").symlink_to(tmp_path / "pipe.usda")
    path = tmp_path / "shot.usda"
    path.write_text(f"#usda 1.0\n{opinion}")
    root = Sdf.Layer.FindOrOpen(str(path))
    assert stage.arcs_problem(root, str(path)) == f"{tmp_path / where}: {_NAMED_PIPE}"


def test_a_folder_or_an_expression_named_by_an_arc_is_usds_to_report(tmp_path: Path) -> None:
    (tmp_path / "folder.usda").mkdir()
    path = tmp_path / "shot.usda"
    path.write_text('#usda 1.0\n(\n    subLayers = [@./folder.usda@, @`"./later.usda"`@]\n)\n')
    root = Sdf.Layer.FindOrOpen(str(path))
    assert stage.arcs_problem(root, str(path)) is None
    assert stage.arc_file_problem(root, "./folder.usda") is None
    assert stage.arc_file_problem(root, "./nowhere.usda") is None
