"""Render fidelity of the paint materials: Cycles (Blender 5 and 4.2-4.5
lobes), EEVEE and the Principled BSDF baseline against the model, on the
named paints and the randomised acceptance set (the README's fidelity table).

    .venv/bin/python scripts/render_fidelity.py [--random 24] [--eevee-random 6] [--out FILE.json]

A plane lit by a Sun and seen by an orthographic camera (addon/scenes.py)
renders f·E·cos θl; the measure is the cos-weighted relative RMS against
Paint.brdf · cos θl for θl, θv <= 75° away from the mirror direction.
Cycles is exact, so its figure is the closure fit's (printed beside it: the
error the fit reports for the paint, which the panel shows); EEVEE (one
sample, its own closure approximations, a coarser grid) is not.  The baseline
is a Principled BSDF with the paint's ρ, n and roughness sqrt(slope), after
the overall scale that suits it best (and as is)."""

from __future__ import annotations

import argparse
import json
import pathlib
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402,F401
import numpy as np  # noqa: E402

import addon  # noqa: E402
from addon.scenes import EEVEE, GRID, GRID_EEVEE, Oracle, paint_material, paints, principled, relative_rms  # noqa: E402
from lut import bench  # noqa: E402
from lut.lutfiles import files  # noqa: E402


def measure(paint, directory, eevee=True, lobes_4x=True, baseline=True, cycles=True):
    row = {"rough": paint.slope > 0}
    oracle = Oracle()
    _, result = paint_material(oracle, paint, directory)
    row["cycles_fit"] = result.errors(paint)["CYCLES"]
    row["eevee_fit"] = result.errors(paint)["EEVEE"]
    if cycles:
        row["cycles"] = relative_rms(oracle, paint, GRID)
    if lobes_4x and cycles and paint.slope > 0:  # Blender 4.2-4.5's facet lobes (Principled, GGX), in 5.x's Cycles
        oracle = Oracle()
        paint_material(oracle, paint, directory, exact_metallic=False)
        row["cycles_4x"] = relative_rms(oracle, paint, GRID)
    if eevee:
        oracle = Oracle(engine=EEVEE)
        paint_material(oracle, paint, directory)
        row["eevee"] = relative_rms(oracle, paint, GRID_EEVEE)
    if baseline and cycles:
        oracle = Oracle()
        principled(oracle, paint)
        row["principled"] = relative_rms(oracle, paint, GRID, best_scale=True)
        row["principled_unscaled"] = relative_rms(oracle, paint, GRID)
    return row


def _pct(value):
    return "" if value is None else f"{value:.2%}"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=str(ROOT / "scripts" / "data" / "render_fidelity.json"))
    parser.add_argument("--random", type=int, default=24, help="paints of the randomised set (lut.bench.random_paints)")
    parser.add_argument("--eevee-random", type=int, default=6, help="of those, how many to render in EEVEE too")
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--no-eevee", action="store_true", help="Cycles and the baseline only (EEVEE renders are slow)")
    parser.add_argument("--only-eevee", action="store_true", help="EEVEE only, for the named paints and --eevee-random")
    args = parser.parse_args(argv)
    addon.register()
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        cycles, eevee = not args.only_eevee, not args.no_eevee
        for name, paint in paints().items():
            rows[name] = measure(paint, pathlib.Path(tmp), eevee=eevee, cycles=cycles)
            print(name, {k: (round(v, 4) if isinstance(v, float) else v) for k, v in rows[name].items()}, flush=True)
        for i, (label, paint) in enumerate(bench.random_paints(args.random, args.seed)):
            if args.only_eevee and i >= args.eevee_random:
                break
            rows[label] = measure(
                paint, pathlib.Path(tmp), eevee=eevee and i < args.eevee_random, cycles=cycles, baseline=False
            )
            rows[label]["random"] = True
            print(label, {k: (round(v, 4) if isinstance(v, float) else v) for k, v in rows[label].items()}, flush=True)
    files.atomic_write_text(args.out, json.dumps(rows, indent=2) + "\n")
    if args.only_eevee or args.no_eevee:
        print("(a partial run: merge it with the other into the README's table by hand)")
    print("| paint | Cycles (fit reports) | Cycles, 4.2-4.5 lobes | EEVEE | Principled BSDF: best scale (as is) |")
    print("|---|---|---|---|---|")
    for name, r in rows.items():
        if r.get("random"):
            continue
        base = f"{r['principled']:.1%} ({r['principled_unscaled']:.1%})" if "principled" in r else ""
        print(
            f"| {name} | {_pct(r.get('cycles'))} ({_pct(r['cycles_fit'])}) | {_pct(r.get('cycles_4x')) or 'same'} "
            f"| {_pct(r.get('eevee'))} | {base} |"
        )
    print("\nRandomised set (worst / median):")
    for kind in (False, True):
        chosen = [r for r in rows.values() if r.get("random") and r["rough"] == kind]
        for key in ("cycles", "cycles_4x", "eevee"):
            values = [r[key] for r in chosen if key in r]
            if values:
                label = "rough" if kind else "smooth"
                print(
                    f"  {label:6s} {key:10s} n={len(values):2d} worst {max(values):.2%} median {np.median(values):.2%}"
                )
    return 0


if __name__ == "__main__":
    sys.exit(main())
