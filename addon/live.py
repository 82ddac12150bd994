"""What a colour edit does, live: the paint of a material's settings
(``paint_of``, in the scene's ``working_space``) sent to its node groups'
inputs and its export fallback (``update_inputs``): no bake.

Below the settings (``properties`` calls ``update_inputs`` from its update
callbacks) and above the node groups and the export fallback, so that every
add-on module's imports point one way."""

from __future__ import annotations

import functools
import pathlib

import bpy

from . import export, nodes
from ._lut import lut, render_bake


def working_space() -> str:
    """The scene-linear working space of the open file, as a lut space name
    (Blender 5.0: bpy.data.colorspace.working_space; earlier: Linear Rec.709)."""
    colorspace = getattr(bpy.data, "colorspace", None)
    name = getattr(colorspace, "working_space", "Linear Rec.709") if colorspace is not None else "Linear Rec.709"
    return name if name in lut.colour.management.WORKING_SPACES else "Linear Rec.709"


def paint_of(material) -> lut.Paint:
    """The lut.Paint of a material's Paint LUT settings, in the scene's working space."""
    return material.paint_lut.to_paint(working_space())


def update_inputs(material) -> None:
    """Send a material's colours (pigment, single scattering, surface
    reflection) to its paint groups' inputs: a colour edit needs no bake."""
    settings = material.paint_lut
    try:
        paint = paint_of(material)
    except ValueError:
        return
    rbar = settings.internal_reflectance if settings.internal_reflectance > 0 else None
    values = render_bake.node_inputs(paint, rbar)
    nodes.set_inputs(material, values)
    if rbar is not None and settings.lut_path and not settings.stale:
        try:  # the export fallback follows the colour too (its shape waits for the next bake)
            table = _loaded_lut(bpy.path.abspath(settings.lut_path))
            export.recolour_fallback(material, table, render_bake.amplitudes_of_inputs(values, rbar))
        except lut.LUTError:
            pass  # no LUT to refit from: the fallback keeps its colour until the next bake


@functools.lru_cache(maxsize=8)
def _loaded_lut_at(path, mtime_ns):
    return lut.load_lut(path)


def _loaded_lut(path):
    """A LUT read once per file version (colour edits come in bursts)."""
    try:
        return _loaded_lut_at(str(path), pathlib.Path(path).stat().st_mtime_ns)
    except OSError as exc:
        raise lut.LUTError(f"{path}: {exc}") from None
