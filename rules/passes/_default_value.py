"""Where a RenderPass attribute's default value is authored and whether it is
lost to a mistake another rule reports, shared by PA001, PA004, PA006 and
PA007."""

from __future__ import annotations

from pxr import Sdf, Usd

from usdrender_lint.api.resolve import DEFAULT_TIME, PrimValues


def _authored_layer(attr: Usd.Attribute) -> Sdf.Layer | None:
    """The layer of the strongest spec holding the attribute's default value."""
    for spec in attr.GetPropertyStack(DEFAULT_TIME):
        if spec.HasDefaultValue():
            return spec.layer
    return None


def _value_lost_elsewhere(values: PrimValues, name: str) -> bool:
    """The Default-time value of the attribute ``name`` is lost to a mistake
    another rule reports: a mistyped opinion (SE016) or time samples with no
    default on a uniform attribute (SE017). Rules that read the value stay
    silent then, so one mistake gives one finding."""
    if values.mismatched(name) is not None:
        return True
    if not values.may_vary(name):
        return False  # provably no time samples, known without asking the attribute
    attr = values.attribute(name)
    return attr.GetNumTimeSamples() > 0 and _authored_layer(attr) is None
