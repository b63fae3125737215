"""The renderSettingsPrimPath stage metadata and its fixes, shared by the ST
rules that read it (ST003 to ST007)."""

from __future__ import annotations

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Fix, schemas

#: The renderSettingsPrimPath layer-metadata field (pseudo-root of a layer).
RENDER_SETTINGS_PATH_KEY = "renderSettingsPrimPath"


def settings_path_opinion(ctx: Context) -> tuple[str, Sdf.Layer] | None:
    """The renderSettingsPrimPath value that counts and the layer authoring it.

    Only the session and root layers' metadata is stage metadata (catalog,
    Ambiguous semantics 8; a sublayer's opinion is invisible to
    ``stage.GetMetadata``); the session layer is the stronger. Read once per
    lint: five ST rules ask."""
    return ctx.cached(_read_settings_path_opinion)


def _read_settings_path_opinion(ctx: Context) -> tuple[str, Sdf.Layer] | None:
    stage = ctx.stage
    for layer in (stage.GetSessionLayer(), stage.GetRootLayer()):
        if layer is not None and layer.pseudoRoot.HasInfo(RENDER_SETTINGS_PATH_KEY):
            return str(layer.pseudoRoot.GetInfo(RENDER_SETTINGS_PATH_KEY)), layer
    return None


def _set_settings_path(value: str):
    def apply(stage: Usd.Stage) -> None:
        # Stage metadata goes to the edit target, which must be the root or session layer.
        stage.SetMetadata(RENDER_SETTINGS_PATH_KEY, value)

    return apply


def _single_settings_fix(ctx: Context, what: str) -> Fix | None:
    """Point renderSettingsPrimPath at the stage's only usable RenderSettings."""
    settings = ctx.prims_of(schemas.RenderSettings)
    if len(settings) != 1:
        return None
    path = str(settings[0].GetPath())
    return Fix(
        description=f'{what} renderSettingsPrimPath = "{path}" in the root layer',
        safe=True,
        apply=_set_settings_path(path),
        layer=ctx.stage.GetRootLayer(),
    )


def _settings_path_problem(stage: Usd.Stage, value: str) -> str | None:
    """Why a non-empty renderSettingsPrimPath names no prim (ST005), or None."""
    if not Sdf.Path.IsValidPathString(value):
        return "is not a valid path"
    path = Sdf.Path(value)
    if not path.IsAbsolutePath():
        return "is relative (it must be absolute)"
    if not path.IsPrimPath():
        return "is not a prim path"
    if not stage.GetPrimAtPath(path):
        return "names no prim on the composed stage"
    return None
