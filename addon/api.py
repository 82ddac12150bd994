"""Headless API of the add-on (for scripts and farms): no UI involved."""

from __future__ import annotations

import pathlib
import tempfile

import bpy

import lut
from lut import closures

from . import nodes, properties
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
    """Bake a material's paint now (blocking): the LUT and the closure fit,
    wired into the material's node tree as a node group."""
    paint = paint_of(material)
    path = lut.bake(paint, lut_directory(), force=force, **options)
    store_result(material, paint, path, *closures.fit_for_lut(paint, path))
    material.paint_lut.enabled = True
    return path


def set_paint(material, paint: lut.Paint) -> None:
    """Store a paint on a material's settings: a preset by name, an RGB paint
    by its fields (converted to the scene's working space)."""
    settings = material.paint_lut
    for name in lut.PRESETS:
        if paint == lut.preset(name, paint.space):
            settings.preset = name
            return
    if paint.spectral:
        raise ValueError("spectral paints other than the presets cannot be stored on a material yet; use RGB colours")
    settings.preset = "CUSTOM"
    properties.set_fields(settings, paint.converted(working_space()))


def new_material(name: str, paint: lut.Paint, **options):
    """A new material rendering ``paint``, baked and wired."""
    material = bpy.data.materials.new(name)
    set_paint(material, paint)
    material.paint_lut.enabled = True
    bake_material(material, **options)
    return material


def bake_scene(scene, force=False, **options) -> dict:
    """Bake the paint materials (those with Use Paint LUT) of the file as the
    scene needs them.  Returns {material name: status}: "baked" (computed),
    "cached" (up to date, nothing computed), "unused" (not on any object in
    the scene, skipped) or "failed: <reason>"."""
    used = {slot.material for obj in scene.objects for slot in obj.material_slots if slot.material is not None}
    status = {}
    for material in bpy.data.materials:
        settings = material.paint_lut
        if not settings.enabled:
            continue
        if material not in used:
            status[material.name] = "unused"
            continue
        try:
            paint = paint_of(material)
            cached = not force and not settings.stale and lut.lut_path(paint, lut_directory(), **options).exists()
            if cached and settings.lut_path:
                status[material.name] = "cached"
                continue
            bake_material(material, force=force, **options)
            status[material.name] = "baked"
        except (ValueError, OSError) as exc:
            status[material.name] = f"failed: {exc}"
    return status
