"""SE rules on real public files from ../shared/corpus: the defects they carry
are found, exactly, and nothing else of the SE family fires on them."""

from __future__ import annotations

from pathlib import Path

import pytest

from usdrender_lint.engine import Linter
from usdrender_lint.rules.settings import RULES

ARNOLD = "Autodesk__arnold-usd/testsuite"
CASES = {
    # A Solaris export: the all-purpose binding written as its C++ name.
    f"{ARNOLD}/test_0055/data/test.usda": {
        ("SE007", "/rendersettings1.instantaneousShutter"),
        ("SE011", "/rendersettings1.materialBindingPurposes"),
        ("SE015", "/rendersettings1"),
    },
    # Animated resolution and productName: spec-based consumers read neither.
    f"{ARNOLD}/test_0159/data/test.usda": {
        ("SE017", "/Render/Products/main.productName"),
        ("SE017", "/Render/Products/main.resolution"),
        ("SE017", "/Render/options.resolution"),
        ("SE007", "/Render/Products/main.instantaneousShutter"),
        ("SE007", "/Render/options.instantaneousShutter"),
        ("SE011", "/Render/options.materialBindingPurposes"),
    },
    # A crop that also overscans vertically.
    f"{ARNOLD}/test_0233/data/test.usda": {
        ("SE005", "/Render/rendersettings.dataWindowNDC"),
        ("SE007", "/Render/rendersettings.instantaneousShutter"),
        ("SE011", "/Render/rendersettings.materialBindingPurposes"),
    },
    # A pre-26.11 colour-space token.
    "mxpv__openusd/fixtures/usdRender_scene.usda": {
        ("SE012", "/Render/settings.renderingColorSpace"),
    },
}


@pytest.mark.parametrize("relative", sorted(CASES))
def test_se_findings_on_corpus_file(shared_dir: Path, relative: str) -> None:
    path = shared_dir / "corpus" / "files" / relative
    if not path.is_file():
        pytest.skip(f"{relative} is not in this corpus snapshot")
    result = Linter([rule() for rule in RULES], raise_errors=True).lint_path(str(path))
    found = {(f.code, f.location.path) for f in result.findings}
    assert found == CASES[relative]
