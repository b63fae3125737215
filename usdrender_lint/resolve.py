"""``usdrender_lint.resolve``: the name rules written for 0.1 import; the module
is :mod:`usdrender_lint.api.resolve` (one module object under both names)."""

import sys

from .api import resolve

sys.modules[__name__] = resolve
