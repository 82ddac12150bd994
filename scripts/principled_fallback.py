"""The Principled fallback's fidelity: per paint, the fitted Principled BSDF
(lut.render.principled.fit_principled, as addon.export adds it) rendered by Cycles
against the model, beside the Principled an artist would set up (ρ as base
colour, IOR n, roughness sqrt(slope), Blender's default multiscatter GGX).

    .venv/bin/python scripts/principled_fallback.py [--out FILE.json]

The measure is the acceptance measure (addon/scenes.py): the
cos-weighted relative RMS of f·cos θl against Paint.brdf · cos θl for
θl, θv <= 75° away from the mirror direction."""

from __future__ import annotations

import argparse
import json
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402,F401

from addon.scenes import Oracle, paints, principled, principled_params_material, relative_rms  # noqa: E402
from lut.render import principled as fallback  # noqa: E402

fallback_material = principled_params_material


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", help="also write the figures as JSON")
    args = parser.parse_args(argv)
    oracle = Oracle()
    rows = {}
    print(f"{'paint':16} {'fit':>7} {'Cycles':>7} {'artist':>7}  parameters")
    for name, paint in paints().items():
        params, error = fallback.fit_principled(paint)
        fallback_material(oracle, params)
        rendered = relative_rms(oracle, paint)
        principled(oracle, paint)
        artist = relative_rms(oracle, paint)
        rows[name] = {"fit": error, "rendered": rendered, "artist": artist, "params": params.to_dict()}
        print(f"{name:16} {error:7.4f} {rendered:7.4f} {artist:7.4f}  {params}")
    if args.out:
        from lut.lutfiles.files import atomic_write_text

        atomic_write_text(args.out, json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
