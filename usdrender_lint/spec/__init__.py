"""``usdrender-lint spec``: what a stage will render, as data and as a picture.

:mod:`.compute` reads the render specification from the stage ``check``
linted (``UsdRenderComputeSpec`` semantics), :mod:`.framing` holds its
arithmetic, :mod:`.runner` runs files through the check pipeline's pieces,
:mod:`.document` makes the versioned JSON document that :mod:`.textview`
and :mod:`.svg` draw.
"""
