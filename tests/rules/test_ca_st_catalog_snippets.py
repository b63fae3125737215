"""The catalog's failing snippets for the ST and CA rules
(../shared/spec/snippets): each fires its own rule, and the ST/CA rules that
fire are exactly the ones the catalog lists under "Other rules that also fire
on the failing snippet" (copied here from the catalog), as Revision 2 changes
them: R2-2 drops CA001 from every snippet whose RenderSettings has no usable
product (ST002..ST005, ST007..ST009)."""

from __future__ import annotations

from pathlib import Path

import pytest

from usdrender_lint.rules import camera, stage
from usdrender_lint.testing import lint

FAMILY_RULES = [rule() for rule in (*stage.RULES, *camera.RULES)]
#: Per snippet, the ST/CA codes the catalog says fire on it.
EXPECTED = {
    "CA001": {"CA001", "ST003"},
    "CA002": {"CA002", "CA006", "ST003"},
    "CA003": {"CA003", "ST003"},
    "CA004": {"CA004", "ST003"},
    "CA005": {"CA005", "ST003"},
    "CA006": {"CA006", "ST003"},
    "CA007": {"CA006", "CA007", "ST003"},
    "CA008": {"CA006", "CA008", "ST003"},
    "CA009": {"CA006", "CA009", "ST003"},
    "ST001": {"ST001"},
    "ST002": {"ST002", "ST003"},  # R2-2: a settings without products gets no CA001
    "ST003": {"ST003"},  # R2-2: a settings without products gets no CA001
    "ST004": {"ST004"},  # R2-2: a settings without products gets no CA001
    "ST005": {"ST005"},  # R2-2: a settings without products gets no CA001
    "ST006": {"CA001", "ST006"},
    "ST007": {"ST003", "ST007"},  # R2-2: a settings without products gets no CA001
    "ST008": {"ST003", "ST008"},  # R2-2: a settings without products gets no CA001
    "ST009": {"ST003", "ST009"},  # R2-2: a settings without products gets no CA001
    "ST010": {"ST010"},
}


@pytest.mark.parametrize("code", sorted(EXPECTED))
def test_snippet_fires_what_the_catalog_lists(shared_dir: Path, code: str) -> None:
    snippets = list((shared_dir / "spec" / "snippets").glob(f"{code}-*.usda"))
    if not snippets:
        pytest.skip(f"no catalog snippet for {code}")
    (snippet,) = snippets
    assert {f.code for f in lint(snippet, FAMILY_RULES)} == EXPECTED[code]
