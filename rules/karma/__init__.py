"""KA: rules of the karma profile (Houdini's Karma through husk)."""

from __future__ import annotations

from .ka001_product_not_written import ProductNotWritten
from .ka002_frame_token_missing import FrameTokenMissing
from .ka003_aov_name_missing import AovNameMissing

RULES = (ProductNotWritten, FrameTokenMissing, AovNameMissing)
