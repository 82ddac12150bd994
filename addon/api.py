"""Headless API of the add-on (for scripts and farms): no UI involved."""

from __future__ import annotations

import json
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


def store_result(material, paint, path, fits=None) -> None:
    """Record a finished bake on the material (path relative to the .blend
    when it is saved), build and wire its node groups (one per render
    engine) from ``fits`` ({target: (Fit, weights path)}), and clear the
    stale flag."""
    settings = material.paint_lut
    settings.lut_path = bpy.path.relpath(str(path)) if bpy.data.filepath else str(path)
    if fits:
        n = float(paint.index_at(589.3))
        groups = {
            target: nodes.build_group(nodes.group_name(material, target), fitted, weights, n)
            for target, (fitted, weights) in fits.items()
        }
        nodes.wire(material, groups)
    settings.stale = False


def bake_material(material, force=False, **options) -> pathlib.Path:
    """Bake a material's paint now (blocking): the LUT and the closure fit,
    wired into the material's node tree as a node group."""
    paint = paint_of(material)
    path = lut.bake(paint, lut_directory(), force=force, **options)
    store_result(material, paint, path, closures.fit_for_lut(paint, path, exact_metallic=nodes.EXACT_METALLIC))
    material.paint_lut.enabled = True
    return path


def set_paint(material, paint: lut.Paint) -> None:
    """Store a paint on a material's settings: a preset by name, another
    spectral paint whole (the Spectral preset), an RGB paint by its fields
    (converted to the scene's working space)."""
    settings = material.paint_lut
    for name in lut.PRESETS:
        if paint == lut.preset(name, paint.space):
            settings.preset = name
            return
    if paint.spectral:
        settings.spectral_paint = json.dumps(paint.to_dict())
        settings.preset = "SPECTRAL"  # fills the fields with its RGB
        return
    settings.preset = "CUSTOM"
    properties.set_fields(settings, paint.converted(working_space()))


def new_material(name: str, paint: lut.Paint, **options):
    """A new material rendering ``paint``, baked and wired."""
    material = bpy.data.materials.new(name)
    set_paint(material, paint)
    material.paint_lut.enabled = True
    bake_material(material, **options)
    return material


def used_materials(scenes) -> set:
    """The materials ``scenes`` render (original, not evaluated, data).

    Where Blender has evaluated a view layer (the open scene's), every object
    instance its depsgraph holds: collection instances, Geometry Nodes' Set
    Material and instances included.  For every scene, also what its objects
    reach without evaluation: their slots (hidden objects too), collection
    instances, the materials and objects a Geometry Nodes modifier's inputs
    and node tree name, and the background set's objects."""
    used = set()
    for scene in scenes:
        used |= _materials_reached(scene)
        for view_layer in scene.view_layers:
            depsgraph = view_layer.depsgraph  # None for a scene Blender has not evaluated
            if depsgraph is None:
                continue
            depsgraph.update()
            for instance in depsgraph.object_instances:
                obj = instance.object
                materials = [slot.material for slot in obj.material_slots]
                materials += list(getattr(obj.data, "materials", None) or ())
                used.update(m.original for m in materials if m is not None)
    return used


def _materials_reached(scene) -> set:
    """The materials a scene's objects reach without evaluating anything."""
    used, objects, trees = set(), set(), set()

    def visit_id(value):
        if isinstance(value, bpy.types.Material):
            used.add(value)
        elif isinstance(value, bpy.types.Object):
            visit_object(value)
        elif isinstance(value, bpy.types.Collection):
            for obj in value.all_objects:
                visit_object(obj)

    def visit_tree(tree):
        if tree is None or tree in trees:
            return
        trees.add(tree)
        for node in tree.nodes:
            visit_id(getattr(node, "material", None))
            if node.type == "GROUP":
                visit_tree(node.node_tree)
            for socket in node.inputs:
                if socket.type in ("MATERIAL", "OBJECT", "COLLECTION"):
                    visit_id(socket.default_value)

    def visit_object(obj):
        if obj in objects:
            return
        objects.add(obj)
        used.update(slot.material for slot in obj.material_slots if slot.material)
        if obj.instance_type == "COLLECTION":
            visit_id(obj.instance_collection)
        for modifier in obj.modifiers:
            if modifier.type == "NODES":
                for key in modifier.keys():
                    visit_id(modifier[key])
                visit_tree(modifier.node_group)

    while scene is not None and scene not in objects:
        objects.add(scene)  # a background-set cycle ends here
        for obj in scene.objects:
            visit_object(obj)
        scene = scene.background_set
    return used


def is_current(material, paint, **options) -> bool:
    """Whether a material's bake is up to date: not stale, wired, and its LUT
    and closure weights on disk are readable and verified (a corrupted or
    missing file means a rebake, not a failure)."""
    settings = material.paint_lut
    if settings.stale or not settings.lut_path:
        return False
    path = lut.lut_path(paint, lut_directory(), **options)
    if pathlib.Path(bpy.path.abspath(settings.lut_path)) != path:
        return False
    try:
        lut.load_lut(path)
        for target in closures.TARGETS:
            lut.lutfile.read_exr(closures.weights_path(path, target))
    except lut.LUTError:
        return False
    return all(nodes.group_of(material, target) is not None for target in closures.TARGETS)


def bake_materials(used, force=False, **options) -> dict:
    """Bake the paint materials (those with Use Paint LUT) of the file that
    are in ``used``.  Returns {material name: status}: "baked" (computed),
    "cached" (up to date, nothing computed), "unused" (skipped) or
    "failed: <reason>" (the material is left as it was)."""
    status = {}
    for material in bpy.data.materials:
        if not material.paint_lut.enabled:
            continue
        if material not in used:
            status[material.name] = "unused"
            continue
        try:
            paint = paint_of(material)
            if not force and is_current(material, paint, **options):
                status[material.name] = "cached"
                continue
            bake_material(material, force=force, **options)
            status[material.name] = "baked"
        except (ValueError, OSError, RuntimeError) as exc:
            status[material.name] = f"failed: {exc}"
    return status


def bake_scene(scene, force=False, **options) -> dict:
    """Bake the paint materials the scene's objects use (``bake_materials``)."""
    return bake_materials(used_materials([scene]), force=force, **options)
