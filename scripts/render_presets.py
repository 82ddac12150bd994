"""Render the three preset paints side by side in Cycles (the README's picture).

    .venv/bin/python scripts/render_presets.py [--out docs/figures/presets.png] [--samples N]

Three spheres on a grey floor, each material made by the add-on's headless
API (addon.api.new_material: bake, closure fit, node groups), lit by a Sun
and a soft sky; Filmic-free 'Standard' view so the paint colours are shown
as rendered.  The LUTs go to a temporary folder."""

from __future__ import annotations

import argparse
import math
import pathlib
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402

import addon  # noqa: E402
import lut  # noqa: E402
from addon import api  # noqa: E402
from lut import files  # noqa: E402


def build_scene(width, height, samples):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.view_settings.view_transform = "Standard"
    scene.render.image_settings.file_format = "PNG"
    world = bpy.data.worlds.new("sky")
    scene.world = world
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (0.55, 0.65, 0.8, 1.0)
    background.inputs["Strength"].default_value = 0.35
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.data.lens = 50
    camera.location = (0.0, -11.0, 2.4)
    camera.rotation_euler = (math.radians(90 - math.degrees(math.atan2(2.4, 11.0))), 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy = 3.0
    sun.data.angle = math.radians(3.0)
    sun.rotation_euler = (math.radians(40), math.radians(-25), math.radians(-20))
    scene.collection.objects.link(sun)
    bpy.ops.mesh.primitive_plane_add(size=40, location=(0, 0, -1))
    floor = bpy.data.materials.new("floor")
    floor.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.3, 0.3, 0.3, 1.0)
    bpy.context.object.data.materials.append(floor)
    spheres = []
    for i in range(3):
        bpy.ops.mesh.primitive_uv_sphere_add(segments=96, ring_count=48, radius=1.0, location=(2.3 * (i - 1), 0, 0))
        bpy.ops.object.shade_smooth()
        spheres.append(bpy.context.object)
    return scene, spheres


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=str(ROOT / "docs" / "figures" / "presets.png"))
    parser.add_argument("--samples", type=int, default=128)
    parser.add_argument("--size", type=int, nargs=2, default=(960, 360), metavar=("W", "H"))
    args = parser.parse_args(argv)
    addon.register()
    scene, spheres = build_scene(*args.size, args.samples)
    with tempfile.TemporaryDirectory() as tmp:
        for sphere, name in zip(spheres, lut.PRESETS, strict=True):
            sphere.data.materials.append(api.new_material(name, lut.preset(name), directory=pathlib.Path(tmp)))
        with files.atomic_target(args.out) as partial:
            scene.render.filepath = partial
            bpy.ops.render.render(write_still=True)
    print(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
