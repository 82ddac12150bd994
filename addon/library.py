"""The bundled paint library: an asset library of paint materials, and their
bake on first use.

``assets/paint_lut_library.blend`` (written by scripts/make_assets.py) holds
one material per paint of ``lut.paint.presets.LIBRARY``, marked as an asset with a
rendered preview, and ``assets/blender_assets.cats.txt`` its catalogs.
Blender 4.2 to 5.2 have no manifest entry for an extension's asset library,
so ``register`` adds the folder to the Preferences' asset libraries
(``preferences.filepaths.asset_libraries.new``), imported as Append (Reuse
Data) or Append (``IMPORT_METHODS``), and ``unregister`` removes it again.

A library material carries its paint (``material.paint_lut``) and a
Principled fallback (``export``) but no bake: its LUT and fits would name
files on the machine that made the library.  It is flagged ``FIRST_USE``;
once it is in a file (dropped on an object, appended, or in a file opened),
a depsgraph or load handler schedules a timer that bakes it in the
background (``jobs.BakeJob``, like the panel's Bake) into
``api.lut_directory()`` (beside the saved .blend, or the extension's user
folder for an unsaved file), wires it and clears the flag.  Scripts, which
have no event loop to run timers, call ``bake_pending`` (blocking, through
``api.bake_material``)."""

from __future__ import annotations

import os
import pathlib

import bpy
from bpy.app.handlers import persistent

from . import api, jobs, nodes

#: The asset library's folder, its .blend and its name in the Preferences.
ASSETS = pathlib.Path(__file__).resolve().parent / "assets"
LIBRARY_BLEND = ASSETS / "paint_lut_library.blend"
LIBRARY_NAME = "Paint LUT"

#: ID properties of a library material: the library paint it is (a name of
#: ``lut.paint.presets.LIBRARY``), whether it still waits for its first bake, and
#: why that bake failed (if it did).
PAINT = "paint_lut_library"
FIRST_USE = "paint_lut_first_use"
ERROR = "paint_lut_first_use_error"

#: How the Asset Browser imports the library's materials, the first this
#: Blender offers: Append (Reuse Data) on 4.2-4.5; Blender 5 offers Link,
#: Append and Pack for user libraries, and a linked or packed material is
#: read-only (it could not be baked), so there it is Append.
IMPORT_METHODS = ("APPEND_REUSE", "APPEND")


def _same_folder(a, b) -> bool:
    def norm(path):
        return os.path.normcase(os.path.realpath(bpy.path.abspath(str(path)).rstrip("/\\")))

    return bool(a) and bool(b) and norm(a) == norm(b)


def asset_libraries():
    return bpy.context.preferences.filepaths.asset_libraries


def find_library():
    """The Preferences' asset library entry of the bundled folder, or None."""
    return next((lib for lib in asset_libraries() if _same_folder(lib.path, ASSETS)), None)


def register_library():
    """Add the bundled folder to the Preferences' asset libraries (once: an
    entry left by an earlier session, e.g. after a crash, is reused)."""
    library = find_library()
    if library is None:
        library = asset_libraries().new(name=LIBRARY_NAME, directory=str(ASSETS))
    for method in IMPORT_METHODS:
        try:
            library.import_method = method
            break
        except TypeError:  # not offered for user libraries by this Blender
            continue
    return library


def unregister_library():
    """Remove every Preferences entry of the bundled folder."""
    libraries = asset_libraries()
    for library in [lib for lib in libraries if _same_folder(lib.path, ASSETS)]:
        libraries.remove(library)


def pending():
    """Local materials of the open file that wait for their first bake."""
    return [m for m in bpy.data.materials if m.get(FIRST_USE) and m.library is None]


def _is_library_file() -> bool:
    """The open file is the library itself (bakes would go into the add-on's folder)."""
    return bool(bpy.data.filepath) and _same_folder(bpy.data.filepath, LIBRARY_BLEND)


def bake_pending(directory=None) -> dict:
    """Bake every material waiting for its first bake (``pending``) with
    ``api.bake_material`` (into ``directory``, default ``api.lut_directory()``)
    and clear its flag.  A failure is recorded on the material (``ERROR``)
    and printed, never raised: the material keeps its Principled fallback
    and the panel's Bake button retries.  Returns {material name: "baked" or
    "failed: <reason>"}."""
    status = {}
    if _is_library_file():
        return status
    for material in pending():
        if material.name in _jobs:  # the interactive path is baking it already
            continue
        try:
            api.bake_material(material, directory=directory)
            status[material.name] = "baked"
            if ERROR in material:
                del material[ERROR]
        except (ValueError, OSError, RuntimeError, TypeError, KeyError) as exc:
            reason = str(exc) or type(exc).__name__
            _fail(material, reason)
            status[material.name] = f"failed: {reason}"
        del material[FIRST_USE]
    if status:
        _redraw()
    return status


def _redraw():
    wm = getattr(bpy.context, "window_manager", None)
    for window in getattr(wm, "windows", ()):
        for area in window.screen.areas:
            area.tag_redraw()


#: Seconds between the timer's looks at running first-use bakes.
POLL = 0.25

#: First-use bakes running in the background: {material name: (BakeJob, paint, type key at start)}.
_jobs = {}


def _fail(material, reason):
    material[ERROR] = reason
    print(f"Paint LUT: first bake of {material.name!r} failed: {reason}")


def _finish_jobs():
    """Wire the bakes that finished into their materials (if those still wait for them)."""
    for name, (job, paint, type_key) in list(_jobs.items()):
        if not job.done:
            continue
        del _jobs[name]
        material = bpy.data.materials.get(name)
        if material is None or material.library is not None or not material.get(FIRST_USE):
            continue  # removed, renamed or baked meanwhile: the next look starts it again if it still waits
        if job.error:
            _fail(material, job.error)
        else:
            api.finish_background_bake(material, paint, job.result, type_key)
            if ERROR in material:
                del material[ERROR]
        del material[FIRST_USE]
        _redraw()


def _start_next():
    """Start the first-use bake of one waiting material (one at a time: the
    bake already uses every core, and materials of one type then share it)."""
    for material in pending():
        if material.name in _jobs:
            continue
        try:
            paint = api.paint_of(material)
        except ValueError as exc:
            _fail(material, str(exc))
            del material[FIRST_USE]
            continue
        job = jobs.BakeJob(
            paint, api.lut_directory(), exact_metallic=nodes.EXACT_METALLIC, targets=api.engine_targets(),
            eevee_calibration=api.eevee_calibration(), eevee_mode=api.eevee_mode(),
        ).start()  # fmt: skip
        _jobs[material.name] = (job, paint, material.paint_lut.type_key())
        return


def _on_timer():
    """The interactive first-use path: bakes run on a worker thread
    (``jobs.BakeJob``, as the panel's Bake) so the interface never waits;
    each finished one is wired with ``api.finish_background_bake``.  Returns
    the next interval while anything runs or waits, else None (stop)."""
    if _is_library_file():
        return None
    _finish_jobs()
    if not _jobs:
        _start_next()
    return POLL if _jobs or pending() else None


def _cancel_jobs():
    for job, _paint, _key in _jobs.values():
        job.cancel()
    _jobs.clear()


def schedule() -> bool:
    """Bake the waiting materials soon (from a timer, outside the handler
    that noticed them).  Returns whether anything waits."""
    if not pending() or _is_library_file():
        return False
    if not bpy.app.timers.is_registered(_on_timer):
        bpy.app.timers.register(_on_timer, first_interval=0.1)
    return True


@persistent
def _on_depsgraph_update(scene, depsgraph=None):
    if depsgraph is None or depsgraph.id_type_updated("MATERIAL") or depsgraph.id_type_updated("OBJECT"):
        schedule()


@persistent
def _on_load_pre(*_args):
    _cancel_jobs()  # their materials belong to the file being closed


@persistent
def _on_load(*_args):
    schedule()


@persistent
def _on_factory_preferences(*_args):
    """Factory preferences were loaded while the add-on stays enabled: they
    hold no entry of ours, so add it again."""
    register_library()


HANDLERS = (
    (bpy.app.handlers.depsgraph_update_post, _on_depsgraph_update),
    (bpy.app.handlers.load_pre, _on_load_pre),
    (bpy.app.handlers.load_post, _on_load),
    (bpy.app.handlers.load_factory_preferences_post, _on_factory_preferences),
)


def register():
    register_library()
    for handlers, handler in HANDLERS:
        if handler not in handlers:
            handlers.append(handler)


def unregister():
    for handlers, handler in HANDLERS:
        if handler in handlers:
            handlers.remove(handler)
    if bpy.app.timers.is_registered(_on_timer):
        bpy.app.timers.unregister(_on_timer)
    _cancel_jobs()
    unregister_library()
