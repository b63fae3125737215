"""Which prims are render prims and where they live by convention, shared by
ST002, ST008 and ST010."""

from __future__ import annotations

from pxr import Sdf, Usd

from usdrender_lint.api import schemas

#: The usdRender naming convention: render prims live under this root prim.
RENDER_SCOPE = Sdf.Path("/Render")
RENDER_SCHEMAS = (schemas.RenderSettingsBase, schemas.RenderVar, schemas.RenderPass)


def is_render_type(prim: Usd.Prim) -> bool:
    return any(prim.IsA(schema) for schema in RENDER_SCHEMAS)
