"""LUT files: a paint type tabulated on its angle grid (``angles``,
``table``), baked and cached by content (``baking``), stored in the LUT's
EXR file format (``format`` over ``exr``), written atomically (``files``)
and cleaned up (``cleanup``).

Owns everything on disk that describes a paint.  May import ``lut.models``,
``lut.colour`` and ``lut.paint``; nothing above it (the render fit reads
these files, the add-on wires them)."""

from . import angles, baking, cleanup, exr, files, format, table

__all__ = ["angles", "baking", "cleanup", "exr", "files", "format", "table"]
