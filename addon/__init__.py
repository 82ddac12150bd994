"""Paint LUT Blender extension: the Blender-facing layer.

Properties, panels, operators, node building and batch baking live here; all
physics and file formats are in ``lut``.  A bake writes the paint's LUT and
per-view closure fits (Cycles, EEVEE) and wires them into the material as
node groups (``nodes``); ``api`` and ``batch`` are the headless entry points.
``library`` registers the bundled paint materials as an asset library and
bakes each one on its first use; ``saving`` takes an unsaved file's bakes
along on its first save."""

import bpy

from . import library, operators, panels, properties, saving

_MODULES = (properties, operators, panels, library, saving)


def _expose_openimageio():
    """lut writes EXR files with OpenImageIO when it can: inside Blender 4.4+
    use the bundled module unless one is importable already.  Blender 4.2-4.3
    have none; lut then uses its own numpy EXR code (lut.lutfiles.exr)."""
    try:
        import OpenImageIO  # noqa: F401
    except ImportError:
        expose = getattr(bpy.utils, "expose_bundled_modules", None)
        if expose is not None:
            expose()


def register():
    _expose_openimageio()
    for module in _MODULES:
        module.register()


def unregister():
    for module in reversed(_MODULES):
        module.unregister()
