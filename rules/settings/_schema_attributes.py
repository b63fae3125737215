"""The authored schema attributes of every render prim kind, shared by SE016
and SE017."""

from __future__ import annotations

from pxr import Usd

from usdrender_lint.api import Context, schemas

#: Every render prim kind: SE016 and SE017 look at all their schema attributes.
_RENDER_PRIM_TYPES = (schemas.RenderSettingsBase, schemas.RenderVar, schemas.RenderPass)


def _authored_schema_attributes(
    prim: Usd.Prim, ctx: Context
) -> tuple[tuple[Usd.Attribute, Usd.PrimDefinition.Attribute], ...]:
    """The prim's authored attributes that its schema declares, with their
    definitions: SE016 and SE017 both walk them, so they are listed once per lint."""
    return ctx.cached(_list_authored_schema_attributes, prim)


def _list_authored_schema_attributes(
    ctx: Context, prim: Usd.Prim
) -> tuple[tuple[Usd.Attribute, Usd.PrimDefinition.Attribute], ...]:
    attribute_definition = prim.GetPrimDefinition().GetAttributeDefinition
    found = []
    for attr in prim.GetAuthoredAttributes():
        definition = attribute_definition(attr.GetName())
        if definition:  # custom attributes have none
            found.append((attr, definition))
    return tuple(found)
