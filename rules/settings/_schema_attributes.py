"""The authored schema attributes of every render prim kind, shared by SE016
and SE017."""

from __future__ import annotations

from pxr import Usd

from usdrender_lint.api import schemas
from usdrender_lint.api.resolve import PrimValues, SchemaAttribute, prim_values

#: Every render prim kind: SE016 and SE017 look at all their schema attributes.
_RENDER_PRIM_TYPES = (schemas.RenderSettingsBase, schemas.RenderVar, schemas.RenderPass)
#: The one varying render attribute: the only one value clips can give values to.
_CLIPPED = "productName"


def _authored_schema_attributes(
    prim: Usd.Prim,
) -> tuple[PrimValues, list[tuple[str, SchemaAttribute]]]:
    """The prim's values and its authored attributes that its schema declares,
    by name, with what the schema declares (the declarations are read once per
    process, the names once per lint). Listed for each caller, not kept: on a
    stage where nothing can vary SE017 never asks, and keeping the list for
    SE016 alone cost more than listing it (a cached lookup per prim)."""
    values = prim_values(prim)
    names = values.authored_names()
    schema_attribute = values.schema_attribute
    declared = []
    for name in names:
        schema = schema_attribute(name)
        # Custom attributes and relationships have no attribute declaration.
        if schema.type_name is not None:
            declared.append((name, schema))
    if _CLIPPED not in names and values.may_be_authored(_CLIPPED):
        # Value clips give it samples though no spec names it, and USD lists
        # only the names specs author.
        schema = schema_attribute(_CLIPPED)
        if schema.type_name is not None and values.attribute(_CLIPPED).HasAuthoredValue():
            declared.append((_CLIPPED, schema))  # a RenderProduct's
    return values, declared
