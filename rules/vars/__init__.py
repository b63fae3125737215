"""VA: RenderVar checks."""

from __future__ import annotations

from .va001_source_name_empty import SourceNameEmpty
from .va002_source_type_not_allowed import SourceTypeNotAllowed
from .va003_lpe_malformed import LpeMalformed
from .va004_primvar_source_not_found import PrimvarSourceNotFound
from .va005_data_type_unknown import DataTypeUnknown
from .va006_data_type_not_pixel_type import DataTypeNotPixelType
from .va007_scalar_source_default_color3f import ScalarSourceDefaultColor3f
from .va008_aov_name_collision import AovNameCollision
from .va009_intrinsic_source_unimplemented import IntrinsicSourceUnimplemented

RULES = (
    SourceNameEmpty,
    SourceTypeNotAllowed,
    LpeMalformed,
    PrimvarSourceNotFound,
    DataTypeUnknown,
    DataTypeNotPixelType,
    ScalarSourceDefaultColor3f,
    AovNameCollision,
    IntrinsicSourceUnimplemented,
)
