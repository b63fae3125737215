"""Layers as files: the ``.usda`` statement spans and line index, a layer's
real path and identifier, whether a file can be read, and safe writing of a
layer. The floor below both the engine (which reads layers) and the fixer
(which edits them): neither reaches into the other for these."""
