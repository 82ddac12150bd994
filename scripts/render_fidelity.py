"""Render fidelity of the paint materials: Cycles (Blender 5 and 4.2-4.5
lobes), EEVEE and the Principled BSDF baseline against the model, on the
named paints and the randomised set (the README's fidelity table).

    .venv/bin/python scripts/render_fidelity.py [--random 24] [--eevee-random 6] [--out FILE.json]

A plane lit by a Sun and seen by an orthographic camera (addon/scenes.py)
renders f·E·cos θl; the measure is the fidelity measure (``lut.render.measure``:
relative RMS of radiance against Paint.brdf · cos θl, every geometry of a
subgrid of its grid counted once, a smooth paint's mirror left out), whole
and over the grazing band θl >= 60° ("<key>_grazing").  Cycles is exact, so
its figure is the closure fit's (printed beside it: the error the fit reports
for the paint, which the panel shows); EEVEE (one sample, its own closure
approximations, a coarser grid) is not.  The baseline
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
from addon.scenes import EEVEE, GRID, GRID_EEVEE, Oracle, oracle_errors, paint_material, paints, principled  # noqa: E402
from lut import bench  # noqa: E402
from lut.lutfiles import files  # noqa: E402


def measure(paint, directory, eevee=True, lobes_4x=True, baseline=True, cycles=True):
    row = {"rough": paint.slope > 0}
    oracle = Oracle()
    _, result = paint_material(oracle, paint, directory)
    for engine, (whole, grazing) in result.all_errors(paint).items():
        row[f"{engine.lower()}_fit"], row[f"{engine.lower()}_fit_grazing"] = whole, grazing
    if cycles:
        row["cycles"], row["cycles_grazing"] = oracle_errors(oracle, paint, GRID)
    if lobes_4x and cycles and paint.slope > 0:  # Blender 4.2-4.5's facet lobes (Principled, GGX), in 5.x's Cycles
        oracle = Oracle()
        paint_material(oracle, paint, directory, exact_metallic=False)
        row["cycles_4x"], row["cycles_4x_grazing"] = oracle_errors(oracle, paint, GRID)
    if eevee:
        oracle = Oracle(engine=EEVEE)
        paint_material(oracle, paint, directory)
        row["eevee"], row["eevee_grazing"] = oracle_errors(oracle, paint, GRID_EEVEE)
    if baseline and cycles:
        oracle = Oracle()
        principled(oracle, paint)
        row["principled"], row["principled_grazing"] = oracle_errors(oracle, paint, GRID, best_scale=True)
        row["principled_unscaled"], row["principled_unscaled_grazing"] = oracle_errors(oracle, paint, GRID)
    return row


def _both(row, key):
    """A row's figure, whole / grazing band."""
    if row.get(key) is None:
        return ""
    return f"{row[key]:.2%} / {row[key + '_grazing']:.2%}"


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
    print("(each figure: whole measure / grazing band, theta_l >= 60 degrees)")
    print("| paint | Cycles (fit reports) | Cycles, 4.2-4.5 lobes | EEVEE | Principled BSDF: best scale (as is) |")
    print("|---|---|---|---|---|")
    for name, r in rows.items():
        if r.get("random"):
            continue
        base = f"{_both(r, 'principled')} ({_both(r, 'principled_unscaled')})" if "principled" in r else ""
        print(
            f"| {name} | {_both(r, 'cycles')} ({_both(r, 'cycles_fit')}) | {_both(r, 'cycles_4x') or 'same'} "
            f"| {_both(r, 'eevee')} | {base} |"
        )
    print("\nRandomised set (worst / median):")
    for kind in (False, True):
        chosen = [r for r in rows.values() if r.get("random") and r["rough"] == kind]
        for key in ("cycles", "cycles_grazing", "cycles_4x", "cycles_4x_grazing", "eevee", "eevee_grazing"):
            values = [r[key] for r in chosen if key in r]
            if values:
                label = "rough" if kind else "smooth"
                print(
                    f"  {label:6s} {key:18s} n={len(values):2d} worst {max(values):.2%} median {np.median(values):.2%}"
                )
    return 0


if __name__ == "__main__":
    sys.exit(main())
