"""Benchmark the Mitsuba 3 plugin germer_paint (lut.polarized.benchmark): the
Mueller LUT's bake time and size per preset, render time against Mitsuba's
pplastic given the same paint in the same variant and scene, and the two side
by side with the models on the plane oracle (S0 and degree of linear
polarization, green channel).  Prints Markdown tables.  Runs in the Mitsuba
environment:

    .venv-mitsuba/bin/python scripts/benchmark_mitsuba.py [--quick]
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))

from lut import PRESETS, preset  # noqa: E402

#: The plane oracle's geometries (θl, φl, θv, φv in degrees): near the
#: normal, off-specular, grazing light, backscatter.
GEOMETRIES = ((20.0, 0.0, 30.0, 180.0), (45.0, 0.0, 60.0, 150.0), (70.0, 0.0, 40.0, 90.0), (60.0, 0.0, 50.0, 10.0))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument(
        "--quick", action="store_true", help="a smoke test: the smooth preset (bakes in seconds), a small image"
    )
    parser.add_argument("--size", type=int, default=64, help="sphere image side (default: %(default)s)")
    parser.add_argument("--spp", type=int, default=8, help="samples per pixel (default: %(default)s)")
    args = parser.parse_args(argv)
    from lut.polarized import benchmark, mitsuba_bsdf

    variant, why = mitsuba_bsdf.choose_variant()
    print(why)
    names = ["glossy_white"] if args.quick else list(PRESETS)
    size, spp = (16, 2) if args.quick else (args.size, args.spp)
    with tempfile.TemporaryDirectory() as cache:
        print("\n| preset | Mueller LUT bake | size | germer_paint render | pplastic render | ratio |")
        print("|---|---|---|---|---|---|")
        for name in names:
            paint = preset(name)
            bake = benchmark.bake_cost(paint)
            times = benchmark.render_ratio(paint, size=size, spp=spp, cache=cache, variant=variant)
            print(
                f"| {name} | {bake['seconds']:.2f} s | {bake['megabytes']:.1f} MB | {times['germer_paint']:.2f} s"
                f" | {times['pplastic']:.3f} s | {times['ratio']:.1f}x |"
            )
        print(f"\n(sphere {size}x{size}, {spp} spp, {variant}; the second render of each scene timed)")
        columns = "S0 model | germer_paint | pplastic | DoLP model | germer_paint | pplastic"
        print(f"\n| preset | θl, φl, θv, φv | {columns} |")
        print("|---|---|---|---|---|---|---|---|")
        for name in names:
            for row in benchmark.side_by_side(preset(name), GEOMETRIES[:2] if args.quick else GEOMETRIES, cache=cache):
                m, g, p = row["model"], row["germer_paint"], row["pplastic"]
                geometry = ", ".join(f"{a:g}" for a in row["geometry"])
                print(
                    f"| {name} | {geometry} | {m['S0']:.4f} | {g['S0']:.4f} | {p['S0']:.4f} | {m['DoLP']:.3f}"
                    f" | {g['DoLP']:.3f} | {p['DoLP']:.3f} |"
                )


if __name__ == "__main__":
    main()
