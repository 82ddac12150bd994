"""A file's first save takes its bakes along.

Before its first save a file's bakes go to the extension's user folder
(``api.user_lut_directory``): there is no ``//`` yet.  When the file is then
saved, its materials would still point there, outside the project, where a
render farm or another machine does not look.  Before each save, the LUTs
and weights files of the file's own paint materials that lie in the user
folder are copied (atomically) into ``paint_lut/`` beside the file being
saved, and the materials' LUT paths and weights images are pointed at the
copies, relative to the file, so the saved file is complete and current."""

from __future__ import annotations

import os
import pathlib

import bpy
from bpy.app.handlers import persistent

from . import api
from ._lut import files


def _bake_files(lut_path: pathlib.Path) -> list[pathlib.Path]:
    """A LUT and the weights files fitted to it (named by its key)."""
    key = lut_path.name.removeprefix("paintlut-")
    return [lut_path, *sorted(lut_path.parent.glob(f"paintfit-*-{key}"))]


def take_bakes_along(blend_path) -> list[str]:
    """Copy the user folder's bakes of this file's paint materials beside
    ``blend_path`` (into ``paint_lut/``) and point the materials and their
    weights images at the copies, relative to ``blend_path``.  Returns the
    names of the materials moved."""
    blend_path = pathlib.Path(blend_path).resolve()
    user = api.user_lut_directory().resolve()
    target = blend_path.parent / api.LUT_DIRECTORY.removeprefix("//")
    start = str(blend_path.parent)
    moved, copied = [], {}
    for material in bpy.data.materials:
        settings = material.paint_lut
        if material.library is not None or not settings.enabled or not settings.lut_path:
            continue
        source = pathlib.Path(bpy.path.abspath(settings.lut_path)).resolve()
        if source.parent != user or not source.is_file():
            continue
        for path in _bake_files(source):
            if path not in copied:
                copied[path] = files.atomic_write_bytes(target / path.name, path.read_bytes())
        settings.lut_path = "//" + os.path.relpath(copied[source], start).replace(os.sep, "/")
        moved.append(material.name)
    for image in bpy.data.images:
        if image.library is not None or not image.filepath:
            continue
        path = pathlib.Path(bpy.path.abspath(image.filepath)).resolve()
        if path in copied:
            image.filepath = "//" + os.path.relpath(copied[path], start).replace(os.sep, "/")
    return moved


@persistent
def _on_save_pre(filepath="", *_args):
    if isinstance(filepath, str) and filepath:
        take_bakes_along(filepath)


def register():
    if _on_save_pre not in bpy.app.handlers.save_pre:
        bpy.app.handlers.save_pre.append(_on_save_pre)


def unregister():
    if _on_save_pre in bpy.app.handlers.save_pre:
        bpy.app.handlers.save_pre.remove(_on_save_pre)
