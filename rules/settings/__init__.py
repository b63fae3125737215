"""SE: RenderSettingsBase and RenderSettings attributes."""

from __future__ import annotations

from .se001_resolution_non_positive import ResolutionNonPositive
from .se002_pixel_aspect_ratio_invalid import PixelAspectRatioInvalid
from .se003_data_window_malformed import DataWindowMalformed
from .se004_data_window_outside_aperture import DataWindowOutsideAperture
from .se005_data_window_crop_or_overscan import DataWindowCropOrOverscan
from .se006_aspect_ratio_conform_policy_invalid import AspectRatioConformPolicyInvalid
from .se007_instantaneous_shutter_deprecated import InstantaneousShutterDeprecated
from .se008_instantaneous_shutter_conflict import InstantaneousShutterConflict
from .se009_included_purposes_invalid import IncludedPurposesInvalid
from .se010_included_purposes_missing_default import IncludedPurposesMissingDefault
from .se011_material_binding_purposes_invalid import MaterialBindingPurposesInvalid
from .se012_rendering_color_space_unknown import RenderingColorSpaceUnknown
from .se013_rendering_color_space_not_linear import RenderingColorSpaceNotLinear
from .se014_products_target_invalid import ProductsTargetInvalid
from .se015_no_products import NoProducts
from .se016_attribute_type_mismatch import AttributeTypeMismatch
from .se017_time_samples_ignored import TimeSamplesIgnored

RULES = (
    ResolutionNonPositive,
    PixelAspectRatioInvalid,
    DataWindowMalformed,
    DataWindowOutsideAperture,
    DataWindowCropOrOverscan,
    AspectRatioConformPolicyInvalid,
    InstantaneousShutterDeprecated,
    InstantaneousShutterConflict,
    IncludedPurposesInvalid,
    IncludedPurposesMissingDefault,
    MaterialBindingPurposesInvalid,
    RenderingColorSpaceUnknown,
    RenderingColorSpaceNotLinear,
    ProductsTargetInvalid,
    NoProducts,
    AttributeTypeMismatch,
    TimeSamplesIgnored,
)
