"""Render fidelity of the paint materials: Cycles, EEVEE and the Principled
BSDF baseline against the model (the README's fidelity table).

    .venv/bin/python scripts/render_fidelity.py [--out scripts/data/render_fidelity.json]

A plane lit by a Sun and seen by an orthographic camera (tests/blender_oracle.py)
renders f·E·cos θl; the measure is the cos-weighted relative RMS against
Paint.brdf · cos θl for θl, θv <= 75° away from the mirror direction.
Cycles is exact, so its figure is the closure fit's; EEVEE (one sample, its
own closure approximations, a coarser grid) is not.  The baseline is a
Principled BSDF with the paint's ρ, n and roughness sqrt(slope), after the
overall scale that suits it best.  Takes about ten minutes (EEVEE)."""

from __future__ import annotations

import argparse
import json
import pathlib
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]

import bpy  # noqa: E402,F401
from blender_oracle import EEVEE, GRID, GRID_EEVEE, Oracle, paints, principled, relative_rms  # noqa: E402

import addon  # noqa: E402
from addon import api, nodes  # noqa: E402
from lut import lutfile  # noqa: E402


def measure(name, paint, directory):
    row = {}
    api.lut_directory = lambda: directory  # bakes go to a scratch folder
    for engine, grid, key in (("CYCLES", GRID, "cycles"), (EEVEE, GRID_EEVEE, "eevee")):
        oracle = Oracle(engine=engine)
        api.paint_of = lambda material: paint
        material = oracle.material(name)
        api.bake_material(material)
        start = time.perf_counter()
        row[key] = relative_rms(oracle, paint, grid)
        row[f"{key}_seconds_per_render"] = (time.perf_counter() - start) / (len(grid[0]) * len(grid[1]) * len(grid[2]))
    if paint.slope > 0:
        # Blender 4.2-4.5's facet lobes (Principled, GGX), measured in 5.0's Cycles.
        nodes.EXACT_METALLIC = False
        oracle = Oracle()
        material = oracle.material(name)
        api.bake_material(material)
        row["cycles_principled_lobes"] = relative_rms(oracle, paint, GRID)
        nodes.EXACT_METALLIC = True
    oracle = Oracle()
    principled(oracle, paint)
    row["principled"] = relative_rms(oracle, paint, GRID, best_scale=True)
    row["principled_unscaled"] = relative_rms(oracle, paint, GRID)
    return row


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=str(ROOT / "scripts" / "data" / "render_fidelity.json"))
    parser.add_argument("--only", nargs="*", help="paint names to measure (default: all)")
    args = parser.parse_args(argv)
    addon.register()
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, paint in paints().items():
            if args.only and name not in args.only:
                continue
            rows[name] = measure(name, paint, pathlib.Path(tmp))
            r = rows[name]
            print(
                f"{name:14s} Cycles {r['cycles']:.2%}  EEVEE {r['eevee']:.2%}  Principled {r['principled']:.2%}",
                flush=True,
            )
    lutfile.atomic_write_bytes(args.out, (json.dumps(rows, indent=2) + "\n").encode())
    print("| paint | Cycles | Cycles, 4.2-4.5 lobes | EEVEE | Principled BSDF: best scale (as is) |")
    print("|---|---|---|---|---|")
    for name, r in rows.items():
        p, raw = r["principled"], r["principled_unscaled"]
        old = f"{r['cycles_principled_lobes']:.2%}" if "cycles_principled_lobes" in r else "same"
        print(f"| {name} | {r['cycles']:.2%} | {old} | {r['eevee']:.2%} | {p:.1%} ({raw:.1%}) |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
