"""--fix and --fix-to on real files from the shared corpus (copied to a tmp dir;
skipped without ../shared): only the fixed opinions change, a second run changes
nothing, and the --fix-to layer, as the stage's root, fixes the same findings."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from fix_support import check, codes, spec_fields
from pxr import Sdf, Usd

#: Self-contained layers with several kinds of safe fix (CA006, SE007, SE011, ST003).
FILES = [
    "Autodesk__arnold-usd/testsuite/test_0055/data/test.usda",
    "Autodesk__arnold-usd/testsuite/test_0149/data/test.usda",
    "PixarAnimationStudios__OpenUSD/pxr/usdImaging/bin/usdrecord/testenv/MotionBlurTest/"
    "motionBlur.usda",
]


@pytest.fixture(params=FILES, ids=lambda name: name.split("/")[-3])
def corpus_copy(request, shared_dir: Path, tmp_path: Path) -> Path:
    source = shared_dir / "corpus" / "files" / request.param
    if not source.is_file():
        pytest.skip(f"{request.param} is not in the corpus")
    copy = tmp_path / "shot.usda"
    shutil.copyfile(source, copy)
    copy.chmod(0o644)  # the corpus is read-only
    return copy


def _flattened(path: Path) -> dict[str, dict[str, str]]:
    return spec_fields(Usd.Stage.Open(str(path)).Flatten())


def test_fix_changes_only_the_fixed_opinions_and_is_idempotent(corpus_copy: Path) -> None:
    before = _flattened(corpus_copy)
    _, document = check("--fix", str(corpus_copy))
    applied = [fix for fix in document["fixes"] if fix["applied"]]
    assert len({fix["code"] for fix in applied}) >= 2
    after = _flattened(corpus_copy)
    changed = {p for p in before.keys() | after.keys() if before.get(p) != after.get(p)}
    fixed_prims = {Sdf.Path(fix["path"]).GetPrimPath() for fix in applied if fix["path"]}
    for path in changed:
        if path == "/":  # stage metadata: only a stage-level fix may touch it
            assert any(fix["path"] is None for fix in applied)
            continue
        assert Sdf.Path(path).IsPropertyPath() and Sdf.Path(path).GetPrimPath() in fixed_prims
    assert not {fix["code"] for fix in applied} & set(codes(document))
    fixed = corpus_copy.read_bytes()
    _, again = check("--fix", str(corpus_copy))
    assert corpus_copy.read_bytes() == fixed
    assert again["fixes"] == []


def test_fix_to_overrides_fix_the_same_findings(corpus_copy: Path) -> None:
    source = corpus_copy.read_bytes()
    overrides = corpus_copy.with_name("fixes.usda")
    _, document = check("--fix-to", str(overrides), str(corpus_copy))
    assert corpus_copy.read_bytes() == source
    applied = {(fix["code"], fix["path"]) for fix in document["fixes"] if fix["applied"]}
    assert applied
    assert list(Sdf.Layer.OpenAsAnonymous(str(overrides)).subLayerPaths) == ["shot.usda"]
    _, on_top = check(str(overrides))
    remaining = {(f["code"], f["path"]) for r in on_top["files"] for f in r["findings"]}
    assert not applied & remaining
