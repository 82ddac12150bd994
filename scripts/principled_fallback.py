"""The Principled fallback's fidelity: per paint, the fitted Principled BSDF
(lut.render.principled.fit_principled, as addon.export adds it) rendered by Cycles
against the model, beside the Principled an artist would set up (ρ as base
colour, IOR n, roughness sqrt(slope), Blender's default multiscatter GGX).

    .venv/bin/python scripts/principled_fallback.py [--out FILE.json]

The measure is the fidelity measure (``lut.render.measure``) on the
fallback fit's own grid (``lut.render.principled.GRID``, off the mirror):
the relative RMS of f·cos θl against Paint.brdf · cos θl, every geometry
counted once, whole and over the grazing band θl >= 60°."""

from __future__ import annotations

import argparse
import json
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402,F401

from addon.scenes import Oracle, oracle_errors, paints, principled, principled_params_material  # noqa: E402
from lut.render import measure  # noqa: E402
from lut.render import principled as fallback  # noqa: E402

fallback_material = principled_params_material


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", help="also write the figures as JSON")
    args = parser.parse_args(argv)
    oracle = Oracle()
    rows = {}
    points = measure.grid_points(fallback.GRID, measure.MIRROR_EXCLUSION)  # where the fallback is fitted
    print(f"{'paint':16} {'fit':>7} {'Cycles':>7} {'grazing':>7} {'artist':>7} {'grazing':>7}  parameters")
    for name, paint in paints().items():
        params, error = fallback.fit_principled(paint)
        fallback_material(oracle, params)
        rendered = oracle_errors(oracle, paint, points=points)
        principled(oracle, paint)
        artist = oracle_errors(oracle, paint, points=points)
        rows[name] = {
            "fit": error,
            "rendered": rendered[0],
            "rendered_grazing": rendered[1],
            "artist": artist[0],
            "artist_grazing": artist[1],
            "params": params.to_dict(),
        }
        print(
            f"{name:16} {error:7.4f} {rendered[0]:7.4f} {rendered[1]:7.4f} {artist[0]:7.4f} {artist[1]:7.4f}  {params}"
        )
    if args.out:
        from lut.lutfiles.files import atomic_write_text

        atomic_write_text(args.out, json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
