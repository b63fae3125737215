"""Whether Sdf's recursive walks of a layer (``Traverse``, and the one behind
``GetCompositionAssetDependencies``) would abort the process: usd-core 26.11
reads a variant (set) named "" but cannot make a path of it, and the walks then
recurse without end or dereference an invalid variant set spec, where
composing the stage merely posts an error. Asked before any walk (the fast
path's, the result cache's, the arcs' crate check)."""

from __future__ import annotations

import re

from pxr import Sdf

from ..layers.files import layer_real_path
from . import layer_words

#: A variant named "" in usda text (``"" {``, or ``"" (`` for one with metadata).
#: (Pattern text: re compiles it at first use, not at every start-up.)
_EMPTY_VARIANT_NAME = rb'""\s*[({]'


def names_an_empty_variant(layer: Sdf.Layer) -> bool:
    """Whether the layer names a variant or variant set "" (a crate's names are
    not text to search: looked for prim by prim, in a crate with variants)."""
    if layer.GetFileFormat().formatId == "usda":
        return _text_names_one(layer)
    return _crate_names_one(layer)


def _crate_names_one(layer: Sdf.Layer) -> bool:
    file = layer_real_path(layer)
    if file and "variantSetChildren" not in layer_words.may_hold(file, ("variantSetChildren",)):
        return False  # no variant set anywhere in the crate
    get_spec = layer.GetPrimAtPath
    stack = [Sdf.Path.absoluteRootPath]
    while stack:
        path = stack.pop()
        spec = get_spec(path)
        if spec is None:
            continue
        variant_sets = spec.variantSets
        if len(variant_sets):
            for set_name in variant_sets.keys():  # noqa: SIM118 - Sdf's views iterate specs
                names = spec.GetVariantNames(set_name) if set_name else []
                if not set_name or not all(names):
                    return True
                stack.extend(path.AppendVariantSelection(set_name, n) for n in names)
        children = spec.nameChildren.keys()  # noqa: SIM118 - Sdf's views iterate specs
        stack.extend(path.AppendChild(name) for name in children if name)
    return False


def _text_names_one(layer: Sdf.Layer) -> bool:
    file = layer_real_path(layer)
    return bool(file) and _text_file_names_one(file)


def _text_file_names_one(file: str) -> bool:
    try:
        with open(file, "rb") as handle:
            return re.search(_EMPTY_VARIANT_NAME, handle.read()) is not None
    except OSError:
        return False
