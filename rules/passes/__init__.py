"""PA: RenderPass prims, their sources, dependencies and collections."""

from __future__ import annotations

from .pa001_render_source_invalid import RenderSourceInvalid
from .pa002_input_passes_invalid_target import InputPassesInvalidTarget
from .pa003_input_passes_cycle import InputPassesCycle
from .pa004_file_name_unresolvable import FileNameUnresolvable
from .pa005_collection_membership_invalid import CollectionMembershipInvalid
from .pa006_collection_expression_ignored import CollectionExpressionIgnored
from .pa007_pass_type_empty import PassTypeEmpty
from .pa008_collection_target_missing import CollectionTargetMissing

RULES = (
    RenderSourceInvalid,
    InputPassesInvalidTarget,
    InputPassesCycle,
    FileNameUnresolvable,
    CollectionMembershipInvalid,
    CollectionExpressionIgnored,
    PassTypeEmpty,
    CollectionTargetMissing,
)
