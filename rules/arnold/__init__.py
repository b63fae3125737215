"""AR: rules of the arnold profile (Arnold through arnold-usd)."""

from __future__ import annotations

from .ar001_driver_unknown import DriverUnknown
from .ar002_filter_not_string import FilterNotString
from .ar003_aov_name_missing import AovNameMissing

RULES = (DriverUnknown, FilterNotString, AovNameMissing)
