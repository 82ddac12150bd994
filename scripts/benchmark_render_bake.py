"""Bake time of the render path: a paint type's LUT and both engines' closure
fits, cold (what the add-on's Bake costs for a new type) and cached (what
another colour of a baked type costs), per preset and on types of the
randomised set.  A colour edit costs no bake at all: it sets node inputs.

    .venv/bin/python scripts/benchmark_render_bake.py [--random 6] [--repeat 2]
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import lut  # noqa: E402
from lut import bench  # noqa: E402
from lut.lutfiles import table  # noqa: E402


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--random", type=int, default=6, help="types of the randomised set to time too")
    parser.add_argument("--repeat", type=int, default=2, help="best of this many cold bakes")
    args = parser.parse_args(argv)
    paints = [(name, lut.preset(name)) for name in lut.PRESETS] + bench.random_paints(args.random)
    print(f"threads per bake: {table.default_workers()}")
    print("| paint | LUT | fits (Cycles, its OSL variant, EEVEE) | total, cold | another colour (cached) |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for label, lut_s, fit_s, total, cached in bench.render_bake_times(paints, tmp, args.repeat):
            print(f"| {label} | {lut_s:.2f} s | {fit_s:.2f} s | {total:.2f} s | {1000 * cached:.0f} ms |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
