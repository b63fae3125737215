"""RM: rules of the renderman profile (RenderMan through hdPrman)."""

from __future__ import annotations

from .rm001_integrator_multiple_connections import IntegratorMultipleConnections
from .rm002_render_terminal_target_missing import RenderTerminalTargetMissing
from .rm003_render_terminal_as_connection import RenderTerminalAsConnection
from .rm004_projection_as_connection import ProjectionAsConnection

RULES = (
    IntegratorMultipleConnections,
    RenderTerminalTargetMissing,
    RenderTerminalAsConnection,
    ProjectionAsConnection,
)
