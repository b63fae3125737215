"""hdPrman's render terminals: the RenderSettings attributes whose connections
name the integrator and the sample and display filters
(OpenUSD third_party/renderman-26/plugin/hdPrman/renderSettings.cpp)."""

from __future__ import annotations

INTEGRATOR = "outputs:ri:integrator"
TERMINALS = (INTEGRATOR, "outputs:ri:sampleFilters", "outputs:ri:displayFilters")
