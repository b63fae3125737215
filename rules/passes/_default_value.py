"""Where a RenderPass attribute's default value is authored and whether it is
lost to a mistake another rule reports, shared by PA001, PA004, PA006 and
PA007."""

from __future__ import annotations

from pxr import Sdf, Usd

from usdrender_lint.api.resolve import DEFAULT_TIME, mismatched_spec


def _authored_layer(attr: Usd.Attribute) -> Sdf.Layer | None:
    """The layer of the strongest spec holding the attribute's default value."""
    for spec in attr.GetPropertyStack(DEFAULT_TIME):
        if spec.HasDefaultValue():
            return spec.layer
    return None


def _value_lost_elsewhere(attr: Usd.Attribute) -> bool:
    """The Default-time value is lost to a mistake another rule reports: a
    mistyped opinion (SE016) or time samples with no default on a uniform
    attribute (SE017). Rules that read the value stay silent then, so one
    mistake gives one finding."""
    if mismatched_spec(attr) is not None:
        return True
    return attr.GetNumTimeSamples() > 0 and _authored_layer(attr) is None
