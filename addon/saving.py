"""A file's first save takes its bakes along.

Before its first save a file's bakes go to the extension's user folder
(``api.user_lut_directory``): there is no ``//`` yet.  Saved as they are,
its materials would point there, outside the project, where a render farm
or another machine does not look.  So when an unsaved file is saved, the
LUTs and weights files of its own paint materials that lie in the user
folder are first copied (atomically) into ``paint_lut/`` beside the file
being saved, and the materials' LUT paths and weights images are pointed at
the copies, relative to it: the saved file is complete and current.  When
the session does not become that file (Save Copy) or the save fails, the
paths are put back; the copies stay (valid caches)."""

from __future__ import annotations

import os
import pathlib

import bpy
from bpy.app.handlers import persistent

from . import api
from ._lut import cleanup, files

#: The paths changed by the save under way: [(ID, attribute, old value)].
_CHANGED: list = []


def _bake_files(lut_path: pathlib.Path) -> list[pathlib.Path]:
    """A LUT and the weights files fitted to it (their names hold its key)."""
    key = cleanup.file_key(lut_path)
    return sorted(path for path in lut_path.parent.iterdir() if path.is_file() and cleanup.file_key(path) == key)


def take_bakes_along(blend_path) -> list:
    """Copy the user folder's bakes of this unsaved file's paint materials
    beside ``blend_path`` (into ``paint_lut/``) and point the materials and
    their weights images at the copies, relative to ``blend_path``.
    Returns what was changed: [(ID, attribute, old value)]."""
    blend_path = pathlib.Path(blend_path).resolve()
    user = api.user_lut_directory().resolve()
    target = blend_path.parent / api.LUT_DIRECTORY.removeprefix("//")
    start = str(blend_path.parent)
    changed, copied = [], {}

    def relative(path):
        return "//" + os.path.relpath(path, start).replace(os.sep, "/")

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
        changed.append((settings, "lut_path", settings.lut_path))
        settings.lut_path = relative(copied[source])
    for image in bpy.data.images:
        if image.library is not None or not image.filepath:
            continue
        path = pathlib.Path(bpy.path.abspath(image.filepath)).resolve()
        if path in copied:
            changed.append((image, "filepath", image.filepath))
            image.filepath = relative(copied[path])
    return changed


def _put_back():
    for owner, attribute, value in reversed(_CHANGED):
        setattr(owner, attribute, value)
    _CHANGED.clear()


@persistent
def _on_save_pre(filepath="", *_args):
    _CHANGED.clear()
    # Only a file's first save: a saved file's bakes are in its own folder
    # already, and Blender rebases relative paths when a saved file is
    # saved elsewhere.
    if isinstance(filepath, str) and filepath and not bpy.data.filepath:
        _CHANGED.extend(take_bakes_along(filepath))


@persistent
def _on_save_post(filepath="", *_args):
    if _CHANGED and bpy.data.filepath != filepath:  # Save Copy: the session stays unsaved
        _put_back()
    _CHANGED.clear()


@persistent
def _on_save_post_fail(*_args):
    _put_back()


HANDLERS = (
    ("save_pre", _on_save_pre),
    ("save_post", _on_save_post),
    ("save_post_fail", _on_save_post_fail),
)


def register():
    for name, handler in HANDLERS:
        handlers = getattr(bpy.app.handlers, name, None)
        if handlers is not None and handler not in handlers:
            handlers.append(handler)


def unregister():
    for name, handler in HANDLERS:
        handlers = getattr(bpy.app.handlers, name, None)
        if handlers is not None and handler in handlers:
            handlers.remove(handler)
