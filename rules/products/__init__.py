"""PR: RenderProduct checks."""

from __future__ import annotations

from .pr001_product_name_empty import ProductNameEmpty
from .pr002_product_name_duplicate import ProductNameDuplicate
from .pr003_product_type_not_allowed import ProductTypeNotAllowed
from .pr004_product_missing_render_vars import ProductMissingRenderVars
from .pr005_ordered_vars_invalid_target import OrderedVarsInvalidTarget
from .pr006_duplicate_render_vars import DuplicateRenderVars
from .pr007_settings_only_attribute_on_product import SettingsOnlyAttributeOnProduct
from .pr008_deep_raster_missing_alpha import DeepRasterMissingAlpha

RULES = (
    ProductNameEmpty,
    ProductNameDuplicate,
    ProductTypeNotAllowed,
    ProductMissingRenderVars,
    OrderedVarsInvalidTarget,
    DuplicateRenderVars,
    SettingsOnlyAttributeOnProduct,
    DeepRasterMissingAlpha,
)
