"""Which layer an asset path of a sublayer, reference or payload names, as far
as the path alone tells: what the result cache keys a lint on (engine/linter.py
``Reads``, running/result_cache.py).

Every asset path a layer can hold has an answer here and none raises: an
internal arc names no layer; a path to a file names that file; a path whose
file depends on more than the path (expression variables, another resolver's
URI, an anonymous layer, a path Sdf cannot anchor) is
:class:`Unkeyable`, which makes the lint's result uncacheable.
"""

from __future__ import annotations

import re

from pxr import Sdf, Tf

#: A URI scheme or the anonymous layers' prefix (``omniverse:``, ``https:``,
#: ``anon:``); two characters at least, so that ``C:`` stays a drive.
_SCHEME = re.compile(r"[A-Za-z][A-Za-z0-9+.\-]+:")


class Unkeyable(Exception):
    """The layer an asset path names is not known from the path and the files
    on disk (the message says why)."""


def arc_target(anchor: Sdf.Layer, asset_path: str) -> str | None:
    """The identifier of the layer ``asset_path`` names, anchored at ``anchor``
    (a file path, perhaps a package member ``a.usdz[b.usda]``, or a search path
    the default resolver looks up), or None when it names no layer: an internal
    reference or payload (``references = </prim>``, whose asset path Sdf gives
    as ``''``). Raises :class:`Unkeyable`."""
    if not asset_path:
        return None
    if "`" in asset_path:
        raise Unkeyable(f"@{asset_path}@ uses expression variables")
    if _SCHEME.match(asset_path):
        raise Unkeyable(f"@{asset_path}@ is resolved by a resolver other than the file system")
    # File format arguments choose how the file is read, not which file it is.
    asset_path = asset_path.partition(":SDF_FORMAT_ARGS:")[0]
    try:
        return Sdf.ComputeAssetPathRelativeToLayer(anchor, asset_path)
    except Tf.ErrorException as exc:
        detail = " ".join(str(exc).split())
        raise Unkeyable(f"@{asset_path}@ cannot be anchored: {detail}") from None
