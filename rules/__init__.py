"""The built-in checks, one class per rule, grouped by the schema they inspect.

Installed as ``usdrender_lint.rules`` and registered through the
``usdrender_lint.rules`` entry point group, exactly like a third-party plugin.
"""

from __future__ import annotations

from . import (
    arnold,
    camera,
    karma,
    meta,
    omniverse,
    passes,
    products,
    renderman,
    settings,
    stage,
    vars,
)

RULES = (
    *stage.RULES,
    *settings.RULES,
    *camera.RULES,
    *products.RULES,
    *vars.RULES,
    *passes.RULES,
    *meta.RULES,
    # Renderer rules: each runs only under its profile (R2-5).
    *karma.RULES,
    *renderman.RULES,
    *arnold.RULES,
    *omniverse.RULES,
)
