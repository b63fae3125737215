"""``generic``: the usdRender schema alone (Revision 1 plus R2-1..R2-4)."""

from __future__ import annotations

from .model import Profile

GENERIC = Profile(
    name="generic",
    description="The usdRender schema alone, with UsdRenderComputeSpec's semantics; "
    "no renderer's own rules.",
)
