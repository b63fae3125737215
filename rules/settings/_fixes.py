"""What an SE fix applies to a stage, shared by the SE rules that offer fixes."""

from __future__ import annotations

from collections.abc import Callable

from pxr import Usd

Apply = Callable[[Usd.Stage], None]
