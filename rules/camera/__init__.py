"""CA: the render camera of each render configuration."""

from __future__ import annotations

from .ca001_camera_unset import CameraUnset
from .ca002_camera_multiple_targets import CameraMultipleTargets
from .ca003_camera_target_missing import CameraTargetMissing
from .ca004_camera_target_not_camera import CameraTargetNotCamera
from .ca005_camera_optics_invalid import CameraOpticsInvalid
from .ca006_aspect_ratio_mismatch_implicit_conform import AspectRatioMismatchImplicitConform
from .ca007_depth_of_field_disabled_with_fstop import DepthOfFieldDisabledWithFStop
from .ca008_shutter_interval_inverted import ShutterIntervalInverted
from .ca009_clipping_range_invalid import ClippingRangeInvalid

RULES = (
    CameraUnset,
    CameraMultipleTargets,
    CameraTargetMissing,
    CameraTargetNotCamera,
    CameraOpticsInvalid,
    AspectRatioMismatchImplicitConform,
    DepthOfFieldDisabledWithFStop,
    ShutterIntervalInverted,
    ClippingRangeInvalid,
)
