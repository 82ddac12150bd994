"""Make the bundled paint library: addon/assets/ and its pictures.

    python scripts/make_assets.py [--samples N] [--size PX]

run by Blender 4.2's Python module (the oldest supported Blender; see
``OLDEST``), e.g. in a Python 3.11 virtual environment made for it:

    python3.11 -m venv .venv-bpy42
    .venv-bpy42/bin/pip install bpy==4.2.0 numpy==1.26.4 matplotlib==3.10.7
    .venv-bpy42/bin/python scripts/make_assets.py

(pip bpy 4.2 ends with a segmentation fault at interpreter exit in any
script that registered the add-on; everything is written before.)

For every paint of ``lut.paint.presets.LIBRARY`` (the paper's three samples, then
the common finishes) this writes a material into
``addon/assets/paint_lut_library.blend``, marked as an asset in a catalog of
``addon/assets/blender_assets.cats.txt``, with a Cycles-rendered preview.  A
library material holds its paint (``material.paint_lut``), a Principled
fallback and the first-use flag of ``addon.library``: no bake, whose files
would live on this machine.  The preview is rendered from a baked copy (LUTs
in a temporary folder): a sphere in front of a soft box, over a checker
floor seen only in reflections, on a transparent background.

It also writes each preview as docs/figures/library/<name>.png and a
contact sheet of them all, labelled, as docs/figures/asset_library.png."""

from __future__ import annotations

import argparse
import math
import pathlib
import sys
import tempfile
import uuid

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402

import addon  # noqa: E402
from addon import api, export, library  # noqa: E402
from lut.paint import presets  # noqa: E402

#: Catalogs of the library: (path, the paints in it).
CATALOGS = {"Paint LUT/Paper Samples": tuple(presets.PRESETS), "Paint LUT/Finishes": tuple(presets.FINISHES)}
#: Fixed catalog UUIDs (derived from the path), so a rebuild keeps them.
NAMESPACE = uuid.UUID("6f1f7d1c-3b0e-4b8e-9a55-2c1d0e7f4a10")

#: Display names of the paper's samples (the finishes are their own names, titled).
NAMES = {"glossy_white": "Glossy White", "glossy_red": "Glossy Red", "green_carc": "Green CARC"}

FIGURES = ROOT / "docs" / "figures"

#: The oldest Blender the extension supports (blender_manifest.toml): the
#: library is written by it, because a file saved by Blender 5 does not
#: open in 4.2 ("not a blend file") while 4.2's files open in every later one.
OLDEST = (4, 2)


def paints():
    """The library's paint names, in order."""
    return list(presets.LIBRARY)


def display_name(name: str) -> str:
    return NAMES.get(name, name.replace("_", " ").title())


def catalog_id(path: str) -> str:
    return str(uuid.uuid5(NAMESPACE, path))


def catalog_of(name: str) -> str:
    return next(path for path, names in CATALOGS.items() if name in names)


def write_catalogs(folder: pathlib.Path) -> pathlib.Path:
    """blender_assets.cats.txt: Blender's catalog definition format, version 1."""
    lines = [
        "# This is an Asset Catalog Definition file for Blender.",
        "#",
        "# Empty lines and lines starting with `#` will be ignored.",
        "# The first non-ignored line should be the version indicator.",
        '# Other lines are of the format "UUID:catalog/path/for/assets:simple catalog name"',
        "",
        "VERSION 1",
        "",
    ]
    paths = ["Paint LUT", *CATALOGS]
    lines += [f"{catalog_id(path)}:{path}:{path.replace('/', '-')}" for path in paths]
    target = folder / "blender_assets.cats.txt"
    target.write_text("\n".join(lines) + "\n")
    return target


def description(name: str) -> str:
    paint = presets.library_paint(name)
    where = "the paper's sample" if name in presets.PRESETS else f"finish, {presets.FINISH_DATA[name][0]}"
    return (
        f"Paint LUT {where}: n {paint.n:g}, g {paint.g:g}, RMS slope {paint.slope:g} ({paint.distribution}). "
        "Baked on first use."
    )


def library_material(name: str):
    """The library's material of a paint: settings, Principled fallback,
    first-use flag, asset metadata.  Not baked."""
    paint = presets.library_paint(name)
    material = bpy.data.materials.new(display_name(name))
    if material.node_tree is None:  # Blender 4.x: a new material has no node tree yet
        material.use_nodes = True
    material.node_tree.nodes.clear()  # the default Principled BSDF: the fallback replaces it
    api.set_paint(material, paint)
    material.paint_lut.enabled = True
    export.update_fallback(material, api.paint_of(material))
    material[library.PAINT] = name
    material[library.FIRST_USE] = True
    material.asset_mark()
    data = material.asset_data
    data.catalog_id = catalog_id(catalog_of(name))
    data.description = description(name)
    data.author = "Paint LUT"
    for tag in ("paint", "Paint LUT", "finish" if name in presets.FINISHES else "paper sample"):
        data.tags.new(tag, skip_if_exists=True)
    return material


def preview_scene(size: int, samples: int):
    """A sphere, a soft box, a checker floor seen only in reflections, a
    dim sky; transparent film, Standard view."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = True
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.film_transparent = True
    scene.view_settings.view_transform = "Standard"
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGBA"
    world = bpy.data.worlds.new("sky")
    scene.world = world
    if world.node_tree is None:
        world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (0.6, 0.7, 0.85, 1.0)
    background.inputs["Strength"].default_value = 0.25
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.data.lens = 85
    camera.location = (0.0, -7.0, 1.2)
    camera.rotation_euler = (math.radians(90 - math.degrees(math.atan2(1.2, 7.0))), 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    box = bpy.data.objects.new("soft box", bpy.data.lights.new("soft box", "AREA"))
    box.data.shape, box.data.size, box.data.size_y = "RECTANGLE", 2.5, 1.2
    box.data.energy = 160.0
    box.location = (-2.5, -4.0, 3.0)
    box.rotation_euler = (math.radians(50), 0.0, math.radians(-32))
    scene.collection.objects.link(box)
    bpy.ops.mesh.primitive_plane_add(size=30, location=(0, 0, -1))
    floor = bpy.context.object
    floor.visible_camera = False
    checker_material = bpy.data.materials.new("checker")
    if checker_material.node_tree is None:
        checker_material.use_nodes = True
    tree = checker_material.node_tree
    checker = tree.nodes.new("ShaderNodeTexChecker")
    checker.inputs["Scale"].default_value = 12.0
    checker.inputs["Color1"].default_value = (0.8, 0.8, 0.8, 1.0)
    checker.inputs["Color2"].default_value = (0.05, 0.05, 0.05, 1.0)
    tree.links.new(checker.outputs["Color"], tree.nodes["Principled BSDF"].inputs["Base Color"])
    floor.data.materials.append(checker_material)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=1.0)
    bpy.ops.object.shade_smooth()
    return scene, bpy.context.object


def render_preview(scene, sphere, material, directory: pathlib.Path, out: pathlib.Path):
    """Render a baked copy of ``material`` on the sphere into ``out`` (PNG)
    and return the image's RGBA pixels (floats, as stored: display-referred)."""
    baked = material.copy()
    for key in (library.FIRST_USE, library.PAINT):
        del baked[key]
    baked.asset_clear()
    api.bake_material(baked, directory=directory)
    sphere.data.materials.clear()
    sphere.data.materials.append(baked)
    scene.render.filepath = str(out)
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(str(out))
    pixels = list(image.pixels)
    bpy.data.images.remove(image)
    sphere.data.materials.clear()
    bpy.data.materials.remove(baked)
    return pixels


def set_preview(material, pixels, size: int):
    preview = material.preview_ensure()
    preview.image_size = (size, size)
    preview.image_pixels_float.foreach_set(pixels)


def contact_sheet(pictures: dict, target: pathlib.Path) -> None:
    """The previews in a row per catalog, each labelled with its name and
    finish or source (matplotlib)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.image as mpimg
    import matplotlib.pyplot as plt

    rows = list(CATALOGS.items())
    columns = max(len(names) for _, names in rows)
    fig, axes = plt.subplots(len(rows), columns, figsize=(1.9 * columns, 2.35 * len(rows)), squeeze=False)
    fig.patch.set_facecolor("#303030")
    for r, (catalog, names) in enumerate(rows):
        for c in range(columns):
            ax = axes[r][c]
            ax.axis("off")
            if c >= len(names):
                continue
            name = names[c]
            ax.imshow(mpimg.imread(pictures[name]))
            paint = presets.library_paint(name)
            detail = f"slope {paint.slope:g} {paint.distribution[:3]}." if paint.slope else "smooth"
            ax.set_title(f"{display_name(name)}\n{detail}", color="white", fontsize=9)
        axes[r][0].text(
            -0.08, 0.5, catalog.split("/")[-1], transform=axes[r][0].transAxes, rotation=90,
            va="center", ha="right", color="#bbbbbb", fontsize=9,
        )  # fmt: skip
    fig.tight_layout()
    fig.savefig(target, dpi=100, facecolor=fig.get_facecolor())
    plt.close(fig)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--samples", type=int, default=48, help="Cycles samples per preview (denoised)")
    parser.add_argument("--size", type=int, default=128, help="preview size in pixels")
    parser.add_argument("--assets", default=str(library.ASSETS), help="the asset library folder")
    parser.add_argument("--figures", default=str(FIGURES), help="where the pictures go")
    parser.add_argument(
        "--allow-newer", action="store_true",
        help=f"write the library with this Blender although files of Blender newer than {OLDEST} do not open in it",
    )  # fmt: skip
    args = parser.parse_args(argv)
    if bpy.app.version[:2] != OLDEST and not args.allow_newer:
        raise SystemExit(
            f"error: run this with Blender {OLDEST[0]}.{OLDEST[1]} (pip bpy=={OLDEST[0]}.{OLDEST[1]}.0, Python 3.11): "
            f"the library must open in every supported Blender and this is {bpy.app.version_string}"
        )
    assets, figures = pathlib.Path(args.assets), pathlib.Path(args.figures)
    (figures / "library").mkdir(parents=True, exist_ok=True)
    assets.mkdir(parents=True, exist_ok=True)
    addon.register()
    try:
        scene, sphere = preview_scene(args.size, args.samples)
        materials, pictures = [], {}
        with tempfile.TemporaryDirectory(prefix="paint_lut_assets") as tmp:
            for name in paints():
                material = library_material(name)
                pictures[name] = figures / "library" / f"{name}.png"
                pixels = render_preview(scene, sphere, material, pathlib.Path(tmp), pictures[name])
                set_preview(material, pixels, args.size)
                materials.append(material)
                print(f"{name}: {material.name}", flush=True)
        write_catalogs(assets)
        target = assets / library.LIBRARY_BLEND.name
        bpy.data.libraries.write(str(target), set(materials), fake_user=True, compress=True)
        contact_sheet(pictures, figures / "asset_library.png")
    finally:
        addon.unregister()
    print(target)
    return 0


if __name__ == "__main__":
    sys.exit(main())
