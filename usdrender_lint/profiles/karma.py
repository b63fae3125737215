"""``karma``: Houdini's Karma (CPU and XPU), rendered by husk."""

from __future__ import annotations

from .model import Profile

#: The husk reference page (Houdini 21.0, "Stand-alone utilities: husk").
HUSK_DOC = "Houdini docs, husk (https://www.sidefx.com/docs/houdini/ref/utils/husk.html)"
#: The Karma Render Settings LOP page, parameter "Output Picture".
KARMA_SETTINGS_DOC = (
    "Houdini docs, Karma Render Settings LOP, Output Picture "
    "(https://www.sidefx.com/docs/houdini/nodes/lop/karmarendersettings.html)"
)

#: The Karma rendering properties page: the render properties Karma reads,
#: which Houdini's Karma LOPs author as karma:* properties. (No public page
#: found names the Karma* API schemas Houdini applies with them.)
KARMA_PROPERTIES_DOC = (
    "Houdini docs, Karma rendering properties "
    "(https://www.sidefx.com/docs/houdini/props/karma.html)"
)

KARMA = Profile(
    name="karma",
    description="Houdini's Karma CPU / XPU through husk: the schema plus husk's "
    "output conventions (KA rules).",
    family="KA",
    namespaces=("karma:",),
    api_schemas=("Karma*",),
    evidence_sources=(KARMA_PROPERTIES_DOC,),
)
