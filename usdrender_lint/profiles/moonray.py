"""``moonray``: DreamWorks' MoonRay through its Hydra delegate, hdMoonray."""

from __future__ import annotations

from .model import Accepted, Profile

#: hdMoonray's render buffers: how a render var becomes a MoonRay RenderOutput.
RENDER_BUFFER_CC = (
    "dreamworksanimation/hdMoonray lib/hydramoonray/RenderBuffer.cc (RenderBuffer::bind)"
)
#: hdMoonray's render settings: MoonRay scene variables.
RENDER_SETTINGS_CC = (
    "dreamworksanimation/hdMoonray lib/hydramoonray/RenderSettings.cc (RenderSettings::apply)"
)

MOONRAY = Profile(
    name="moonray",
    description="MoonRay through hdMoonray: the schema, with MoonRay's scene variables "
    "(moonray:sceneVariable:*) on the settings and its RenderOutput attributes "
    "(parameters:moonray:*) on the vars.",
    namespaces=("moonray:", "parameters:moonray:"),
    evidence_sources=(RENDER_SETTINGS_CC, RENDER_BUFFER_CC),
    var_outputs=(
        Accepted(
            name="parameters:moonray:result",
            why="hdMoonray turns each render var into a MoonRay RenderOutput and sets every "
            "RenderOutput attribute from the var's parameters:moonray:<attribute> setting, "
            "after the defaults it derives from the AOV name; a var whose "
            "parameters:moonray:result is authored (a state variable, light AOV, "
            "cryptomatte, ...) defines its output without a sourceName",
            source=RENDER_BUFFER_CC,
        ),
    ),
)
