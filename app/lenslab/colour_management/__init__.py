"""Colour management through OpenColorIO: which config, the working space the renderer computes in, and the view
transform from scene-linear light to a display's code values (docs/colour.md).

Nothing here knows about GL or Qt: the renderer asks :class:`~lenslab.colour_management.view.ViewTransform` for the
GLSL and lookup tables OCIO generates and uploads them itself; exports run the same transform on OCIO's CPU
processor.
"""
