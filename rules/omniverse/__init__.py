"""OV: rules of the omniverse profile (Omniverse RTX: Kit, Isaac Sim, ovrtx)."""

from __future__ import annotations

from .ov001_sensor_output_missing import SensorOutputMissing
from .ov002_legacy_sensor_camera import LegacySensorCamera

RULES = (SensorOutputMissing, LegacySensorCamera)
