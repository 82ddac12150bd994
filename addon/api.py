"""Headless API of the add-on (for scripts and farms): no UI involved."""

from __future__ import annotations

import pathlib
import tempfile

import bpy

import lut

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


def store_result(material, path) -> None:
    """Record a finished bake on the material (path relative to the .blend
    when it is saved) and clear its stale flag."""
    settings = material.paint_lut
    settings.lut_path = bpy.path.relpath(str(path)) if bpy.data.filepath else str(path)
    settings.stale = False


def bake_material(material, force=False, **options) -> pathlib.Path:
    """Bake a material's paint now (blocking) and record the result."""
    path = lut.bake(paint_of(material), lut_directory(), force=force, **options)
    store_result(material, path)
    return path
