"""Headless API of the add-on (for scripts and farms): no UI involved."""

from __future__ import annotations

import pathlib
import tempfile

import bpy

import lut
from lut import closures

from . import nodes
from .properties import working_space

#: LUTs go here, relative to the saved .blend file.
LUT_DIRECTORY = "//paint_lut"


def lut_directory() -> pathlib.Path:
    """Where bakes are written: ``//paint_lut`` next to the saved .blend file,
    or a temporary folder for an unsaved one."""
    if bpy.data.filepath:
        return pathlib.Path(bpy.path.abspath(LUT_DIRECTORY))
    return pathlib.Path(tempfile.gettempdir()) / "paint_lut"


def paint_of(material) -> lut.Paint:
    """The lut.Paint of a material's Paint LUT settings, in the scene's working space."""
    return material.paint_lut.to_paint(working_space())


def store_result(material, paint, path, fitted=None, weights=None) -> None:
    """Record a finished bake on the material (path relative to the .blend
    when it is saved), build and wire its node group when there is a closure
    fit, and clear the stale flag."""
    settings = material.paint_lut
    settings.lut_path = bpy.path.relpath(str(path)) if bpy.data.filepath else str(path)
    if fitted is not None:
        group = nodes.build_group(
            f"{nodes.GROUP_PREFIX} {material.name}", fitted, weights, float(paint.index_at(589.3))
        )
        nodes.wire(material, group)
    settings.stale = False


def bake_material(material, force=False, **options) -> pathlib.Path:
    """Bake a material's paint now (blocking): the LUT, and for smooth paints
    the closure fit wired into the material's node tree."""
    paint = paint_of(material)
    path = lut.bake(paint, lut_directory(), force=force, **options)
    store_result(material, paint, path, *closures.fit_for_lut(paint, path))
    return path
