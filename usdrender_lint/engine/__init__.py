"""The engine: open a stage (in full or only what the rules read), walk it once,
dispatch prims to rules, locate findings in the layers, apply customData
suppressions, explore variants. It knows rules and the data model, never the
configuration, a formatter or the command line."""

from __future__ import annotations

from .linter import (
    RENDER_SCHEMAS,
    InspectionError,
    Inspector,
    Linter,
    LintRun,
    TracedFinding,
)
from .locate import bounded_message, locate
from .plugins import (
    SchemasMissing,
    plugin_notes,
    plugin_problems,
    register_plugins,
    reported_by_worker,
)
from .stage import (
    STAGE_OPEN_FAILED_CODE,
    STAGE_OPEN_FAILED_NAME,
    USD_EXTENSIONS,
    StageOpenResult,
    open_stage,
)

__all__ = [
    "RENDER_SCHEMAS",
    "STAGE_OPEN_FAILED_CODE",
    "STAGE_OPEN_FAILED_NAME",
    "USD_EXTENSIONS",
    "InspectionError",
    "Inspector",
    "LintRun",
    "Linter",
    "SchemasMissing",
    "StageOpenResult",
    "TracedFinding",
    "bounded_message",
    "locate",
    "open_stage",
    "plugin_notes",
    "plugin_problems",
    "register_plugins",
    "reported_by_worker",
]
