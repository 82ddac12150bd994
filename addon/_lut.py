"""The add-on's one import of the library, so that no other ``lut`` can
stand in for it.

Blender installs extensions' wheels into one shared site-packages, where a
top-level ``lut`` of another extension could shadow ours.  So the extension
zip (scripts/build_extension.py) ships the library as ``paint_lut_core``;
the repository keeps ``lut`` (tests and scripts import it), and the add-on
run from the repository uses that.  Every add-on module imports the library
from here, by the names below:

    from ._lut import lut                  # instead of: import lut
    from ._lut import closures, fitting    # instead of: from lut.render import closures, fitting

Those names are the library modules the add-on uses, one line each with
its path in the library's layers (``lut/__init__.py``)."""

from __future__ import annotations

import importlib

#: The library's name inside the extension's wheel.
BUNDLED = "paint_lut_core"

try:
    lut = importlib.import_module(BUNDLED)
except ModuleNotFoundError as error:
    if error.name != BUNDLED:  # the bundled library is there but broken: say so
        raise
    lut = importlib.import_module("lut")


def _module(path: str):
    return importlib.import_module(f"{lut.__name__}.{path}")


schema = _module("paint.schema")
baking = _module("lutfiles.baking")
cleanup = _module("lutfiles.cleanup")
exr = _module("lutfiles.exr")
files = _module("lutfiles.files")
lutfile = _module("lutfiles.format")
closures = _module("render.closures")
eevee = _module("render.eevee")
fitting = _module("render.fitting")
measure = _module("render.measure")
principled = _module("render.principled")
render_bake = _module("render.bake")
farm = _module("farm")
