"""Render the three preset paints side by side in Cycles (the README's picture).

    .venv/bin/python scripts/render_presets.py [--out presets.png] [--samples N]

The README's picture is made with ``--out docs/figures/presets.png``; by
default the picture goes to the current folder, so a trial run never
replaces the documented one.

Three spheres on a grey floor (addon.scenes.presets_scene), each material
made by the add-on's headless API (addon.api.new_material: bake, closure
fit, node groups), lit by a Sun and a soft sky; Filmic-free 'Standard' view
so the paint colours are shown as rendered.  The LUTs go to a temporary
folder."""

from __future__ import annotations

import argparse
import pathlib
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402

import addon  # noqa: E402
import lut  # noqa: E402
from addon import api, scenes  # noqa: E402
from lut.lutfiles import files  # noqa: E402


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="presets.png", help="the picture (default: %(default)s, here)")
    parser.add_argument("--samples", type=int, default=128)
    parser.add_argument("--size", type=int, nargs=2, default=(960, 360), metavar=("W", "H"))
    args = parser.parse_args(argv)
    addon.register()
    scene, spheres = scenes.presets_scene(*args.size, args.samples)
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
