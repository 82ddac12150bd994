"""Paint LUT Blender extension: the Blender-facing layer.

Properties, panels and operators live here; all physics and file formats are
in ``lut``.  Work in progress (issue 4): a bake writes the LUT and, for
smooth paints, a per-view closure fit wired into the material as a node
group (Cycles); rough paints and EEVEE's own target are not done yet."""

import bpy

from . import operators, panels, properties

_MODULES = (properties, operators, panels)


def _expose_openimageio():
    """lut writes EXR files with OpenImageIO: inside Blender use the bundled
    module unless one is importable already."""
    try:
        import OpenImageIO  # noqa: F401
    except ImportError:
        bpy.utils.expose_bundled_modules()


def register():
    _expose_openimageio()
    for module in _MODULES:
        module.register()


def unregister():
    for module in reversed(_MODULES):
        module.unregister()
