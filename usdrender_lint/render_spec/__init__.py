"""``usdrender-lint spec``: what a stage will render, as data and as a picture.

:mod:`.compute` reads the render specification from the stage ``check``
linted (``UsdRenderComputeSpec`` semantics; the command runs it as the
inspector of ``running.inspect``), :mod:`.framing` holds its arithmetic,
:mod:`.document` makes the versioned JSON document that :mod:`.textview`
and :mod:`.svg` draw.
"""
