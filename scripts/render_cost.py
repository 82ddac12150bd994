"""Render cost of a Paint LUT material against a Principled BSDF (Cycles).

    .venv/bin/python scripts/render_cost.py [--samples N] [--size PX] [--engine CYCLES|EEVEE]

Renders a UV sphere lit by a Sun and a dim world at 256x256
(addon.scenes.sphere_scene), once with a Principled BSDF and once with each
preset's baked node group (and of the randomised set's paints given by
``--random``), and prints the time ratio (best of 3 renders after a
warm-up)."""

from __future__ import annotations

import argparse
import pathlib
import sys
import tempfile
import time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))

import bpy  # noqa: E402

import addon  # noqa: E402
import lut  # noqa: E402
from addon import api, scenes  # noqa: E402
from lut import bench  # noqa: E402
from lut.render import bake as render_bake  # noqa: E402


def timed(sc, repeat=3):
    bpy.ops.render.render(write_still=False)  # warm-up (kernel and scene sync)
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        bpy.ops.render.render(write_still=False)
        best = min(best, time.perf_counter() - start)
    return best


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--samples", type=int, default=16)
    parser.add_argument("--engine", choices=("CYCLES", "EEVEE"), default="CYCLES")
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument(
        "--random", type=int, nargs="*", default=[], help="also these paints of lut.bench.random_paints, by index"
    )
    args = parser.parse_args(argv)
    addon.register()
    engine = "CYCLES" if args.engine == "CYCLES" else scenes.EEVEE
    sc, sphere = scenes.sphere_scene(args.size, args.samples, engine)
    principled = bpy.data.materials.new("principled")
    sphere.data.materials.append(principled)
    base = timed(sc)
    print(f"Principled BSDF: {base:.3f} s ({args.engine}, {args.size}x{args.size}, {args.samples} samples)")
    paints = [(name, lut.preset(name)) for name in lut.PRESETS]
    randomised = bench.random_paints()
    paints += [randomised[i] for i in args.random]
    for name, paint in paints:
        directory = pathlib.Path(tempfile.mkdtemp())
        material = api.new_material(name, paint, directory=directory)
        sphere.data.materials[0] = material
        t = timed(sc)
        cached = render_bake.bake_for_render(paint, directory, eevee_calibration=api.eevee_calibration())
        closures = sum(c.cost for c in cached.fits[args.engine].closures)
        print(f"{name:28} {t:.3f} s  ratio {t / base:.2f}  ({closures} closures)")


if __name__ == "__main__":
    main()
