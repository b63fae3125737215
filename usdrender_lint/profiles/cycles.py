"""``cycles``: Blender's Cycles through its Hydra render delegate (HdCycles)."""

from __future__ import annotations

from .model import Profile

#: HdCycles' render settings keys (Blender's intern/cycles/hydra).
RENDER_DELEGATE = (
    "blender/blender intern/cycles/hydra/render_delegate.h (HD_CYCLES_RENDER_SETTINGS_TOKENS: "
    "cycles:device, cycles:threads, cycles:time_limit, cycles:samples, cycles:sample_offset) "
    "and render_delegate.cpp (HdCyclesDelegate::SetRenderSetting: cycles:integrator:<socket>)"
)

# What HdCycles' public source does not support, so the profile does not
# claim it: it syncs no RenderSettings prim (its Bprims are renderBuffer and
# openvdbAsset only; the application hands it the settings) and defines no
# prim types, product types or settings that change a generic rule's verdict.
CYCLES = Profile(
    name="cycles",
    description="Cycles through its Hydra delegate (HdCycles, in Blender's source): the "
    "schema alone; its settings namespace cycles: is evidence of the renderer, so a "
    "configuration carrying it is judged as Cycles' and never under another renderer's rules.",
    namespaces=("cycles:",),
    evidence_sources=(RENDER_DELEGATE,),
)
