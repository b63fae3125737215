"""On every file of the shared corpus (a copy; skipped without ../shared):
the --fix-to layer, as the stage's root, composes exactly like the file after
--fix, and a second --fix changes no byte."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from pxr import Sdf, Usd

from usdrender_lint.engine import open_stage
from usdrender_lint.fixing import FixOptions, fix_files
from usdrender_lint.fixing.overlay import composed_stage
from usdrender_lint.running.pipeline import Request, prepare

pytestmark = pytest.mark.heavy(seconds=90)

LAYERS = (".usda", ".usd", ".usdc")


@pytest.fixture
def corpus(shared_dir: Path, tmp_path: Path) -> Path:
    source = shared_dir / "corpus" / "files"
    if not source.is_dir():
        pytest.skip("no shared corpus")
    copy = tmp_path / "files"
    shutil.copytree(source, copy)
    for path in copy.rglob("*"):
        path.chmod(path.stat().st_mode | 0o200)  # the corpus is read-only
    return copy


def read(paths: list[Path]) -> dict[Path, bytes]:
    return {path: path.read_bytes() for path in paths}


def test_fix_to_composes_like_fix_and_fixing_twice_changes_nothing(corpus: Path) -> None:
    prepared = prepare(Request(paths=(str(corpus),), isolated=True))
    linter, keep = prepared.linter, prepared.is_reported
    roots = sorted(p for p in corpus.rglob("*") if p.suffix in LAYERS)
    compared, different, not_idempotent = 0, [], []
    for path in roots:
        stage = open_stage(str(path)).stage
        if stage is None:
            continue  # ST001: nothing to fix
        files = [Path(layer.realPath) for layer in stage.GetUsedLayers() if layer.realPath]
        del stage
        pristine = read(files)
        overlay = path.with_name(path.stem + ".overrides.usda")
        fix_files(linter, [str(path)], FixOptions(fix_to=str(overlay)), keep)
        assert read(files) == pristine, path  # --fix-to writes no source
        if not overlay.exists():
            continue
        overlaid = composed_stage(Usd.Stage.Open(str(overlay)))
        overlay.unlink()
        fix_files(linter, [str(path)], FixOptions(), keep)
        fixed = read(files)
        if composed_stage(Usd.Stage.Open(str(path))) == overlaid:
            compared += 1
        else:
            different.append(str(path.relative_to(corpus)))
        again = fix_files(linter, [str(path)], FixOptions(), keep)
        if read(files) != fixed or again.applied:
            not_idempotent.append(str(path.relative_to(corpus)))
        for changed in (f for f in files if fixed[f] != pristine[f]):
            changed.write_bytes(pristine[changed])
            layer = Sdf.Layer.Find(str(changed))
            if layer is not None:
                layer.Reload(True)
    assert different == [] and not_idempotent == []
    assert compared >= 150  # the corpus's files with a safe fix
