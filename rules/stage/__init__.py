"""ST: stage-wide checks (opening, composition, which settings render)."""

from __future__ import annotations

from .st001_stage_open_failed import StageOpenFailed
from .st002_composition_error_on_render_prim import CompositionErrorOnRenderPrim
from .st003_render_settings_path_missing import RenderSettingsPathMissing
from .st004_render_settings_ambiguous import RenderSettingsAmbiguous
from .st005_render_settings_path_unresolved import RenderSettingsPathUnresolved
from .st006_render_settings_path_not_render_settings import RenderSettingsPathNotRenderSettings
from .st007_render_settings_path_in_sublayer import RenderSettingsPathInSublayer
from .st008_render_prim_outside_render_scope import RenderPrimOutsideRenderScope
from .st009_unreferenced_render_prim import UnreferencedRenderPrim
from .st010_unknown_render_prim_type import UnknownRenderPrimType

RULES = (
    StageOpenFailed,
    CompositionErrorOnRenderPrim,
    RenderSettingsPathMissing,
    RenderSettingsAmbiguous,
    RenderSettingsPathUnresolved,
    RenderSettingsPathNotRenderSettings,
    RenderSettingsPathInSublayer,
    RenderPrimOutsideRenderScope,
    UnreferencedRenderPrim,
    UnknownRenderPrimType,
)
