"""Render cost of a Paint LUT material against a Principled BSDF (Cycles).

    .venv/bin/python scripts/render_cost.py [--samples N] [--size PX] [--engine CYCLES|EEVEE]
    .venv/bin/python scripts/render_cost.py --per-kind
    .venv/bin/python scripts/render_cost.py --osl [--random 2 5]

Renders a UV sphere lit by a Sun and a dim world at 256x256
(addon.scenes.sphere_scene), once with a Principled BSDF and once with each
preset's baked node group (and of the randomised set's paints given by
``--random``), and prints the time ratio (best of 3 renders after a
warm-up) and the closures of its fit.

``--per-kind`` measures those costs: for each closure kind, the add-on's
node group of one closure and of ``PER_KIND_COUNT`` of them (a rough
type's fit with its closures replaced), the difference per closure in
Principled BSDFs.

``--osl`` also times Cycles' OSL variant of each paint (its material's
setting on, Open Shading Language on, CPU) against the same material's SVM
group rendered by SVM and by OSL, and against a Principled BSDF rendered
by OSL."""

from __future__ import annotations

import argparse
import dataclasses
import pathlib
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))

import bpy  # noqa: E402

import addon  # noqa: E402
import lut  # noqa: E402
from addon import api, nodes, scenes  # noqa: E402
from lut import bench  # noqa: E402
from lut.render import bake as render_bake  # noqa: E402
from lut.render import closures, fitting  # noqa: E402

#: Closures of one kind in the larger group ``--per-kind`` times.
PER_KIND_COUNT = 4


def timed(sc, repeat=3):
    bpy.ops.render.render(write_still=False)  # warm-up (kernel and scene sync)
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        bpy.ops.render.render(write_still=False)
        best = min(best, time.perf_counter() - start)
    return best


def kind_sample(kind, n):
    """A closure of ``kind`` with the parameters a rough type's fit gives it."""
    if kind in ("diffuse_toon", "glossy_toon", "retro_toon"):
        return closures.Closure(kind, size=0.5, smooth=0.3)
    return closures.Closure(kind, ior=n, roughness=0.5)


def per_kind(sc, sphere, base, directory):
    """{kind: render cost per closure in Principled BSDFs}: groups of one and
    of ``PER_KIND_COUNT`` closures of each kind, on a rough type's fit."""
    paint = lut.preset("green_carc")
    baked = render_bake.bake_for_render(paint, directory, targets=("CYCLES",))
    fit = baked.fits["CYCLES"]
    values = render_bake.node_inputs(paint, baked.lut.internal_reflectance)
    facet = fitting.COMPONENTS.index("facet")
    diffuse = fitting.COMPONENTS.index("diffuse")
    costs = {}
    for kind in closures.CLOSURE_KINDS:
        times = {}
        for count in (1, PER_KIND_COUNT):
            closure = kind_sample(kind, fit.n)
            weights = np.zeros((count, len(fitting.COMPONENTS), *fit.weights.shape[2:]))
            weights[:, facet if closure.grey else diffuse] = 0.5 / count
            trial = dataclasses.replace(fit, closures=[closure] * count, weights=weights, mirror=False)
            path = directory / f"paintfit-cost-{kind}-{count}.exr"
            fitting.write_fit(trial, path)
            group = nodes.build_group(trial, path)
            material = bpy.data.materials.new(f"cost {kind} {count}")
            nodes.wire(material, {"CYCLES": group}, values)
            sphere.data.materials[0] = material
            times[count] = timed(sc)
        costs[kind] = (times[PER_KIND_COUNT] - times[1]) / (PER_KIND_COUNT - 1) / base
        print(
            f"{kind:14} one closure {times[1] / base:.2f}, per closure more {costs[kind]:.3f}"
            f" (counted {closures.CLOSURE_KINDS[kind].cost} in the fit's budget)",
            flush=True,
        )
    return costs


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--samples", type=int, default=16)
    parser.add_argument("--engine", choices=("CYCLES", "EEVEE"), default="CYCLES")
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument(
        "--random", type=int, nargs="*", default=[], help="also these paints of lut.bench.random_paints, by index"
    )
    parser.add_argument("--per-kind", action="store_true", help="instead: the render cost of each closure kind")
    parser.add_argument("--osl", action="store_true", help="also Cycles' OSL variant of each paint")
    args = parser.parse_args(argv)
    if args.osl and args.engine != "CYCLES":
        parser.error("--osl needs --engine CYCLES")
    addon.register()
    engine = "CYCLES" if args.engine == "CYCLES" else scenes.EEVEE
    sc, sphere = scenes.sphere_scene(args.size, args.samples, engine)
    principled = bpy.data.materials.new("principled")
    sphere.data.materials.append(principled)
    base = timed(sc)
    print(f"Principled BSDF: {base:.3f} s ({args.engine}, {args.size}x{args.size}, {args.samples} samples)")
    if args.osl:
        sc.cycles.shading_system = True
        base_osl = timed(sc)
        sc.cycles.shading_system = False
        print(f"Principled BSDF with OSL: {base_osl:.3f} s")
    if args.per_kind:
        per_kind(sc, sphere, base, pathlib.Path(tempfile.mkdtemp()))
        return
    paints = [(name, lut.preset(name)) for name in lut.PRESETS]
    randomised = bench.random_paints()
    paints += [randomised[i] for i in args.random]
    for name, paint in paints:
        directory = pathlib.Path(tempfile.mkdtemp())
        material = api.new_material(name, paint, directory=directory)
        sphere.data.materials[0] = material
        t = timed(sc)
        cached = render_bake.bake_for_render(
            paint, directory, eevee_calibration=api.eevee_calibration(), eevee_mode=api.eevee_mode()
        )  # what api.new_material baked
        counted = sum(c.cost for c in cached.fits[args.engine].closures)
        print(f"{name:28} {t:.3f} s  ratio {t / base:.2f}  ({counted} closures)")
        if args.osl:
            sc.cycles.shading_system = True
            t_svm_osl = timed(sc)  # the SVM group, rendered by OSL
            material.paint_lut.osl = True  # the variant's group, from the cached bake
            t_osl = timed(sc)
            sc.cycles.shading_system = False
            material.paint_lut.osl = False
            print(
                f"{name + ' (OSL variant)':28} {t_osl:.3f} s  ratio {t_osl / base:.2f} to Principled (SVM), "
                f"{t_osl / base_osl:.2f} to Principled (OSL), {t_osl / t:.2f} to its SVM group "
                f"({t_osl / t_svm_osl:.2f} to the SVM group rendered by OSL, itself {t_svm_osl / base_osl:.2f} "
                "to Principled with OSL)"
            )


if __name__ == "__main__":
    main()
