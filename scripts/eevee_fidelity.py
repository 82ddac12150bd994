"""EEVEE render fidelity of paint materials on the randomised acceptance set,
for the running Blender line (the README's EEVEE column).

    .venv/bin/python scripts/eevee_fidelity.py [--random 24] [--seed 2026] [--out FILE.json]
    .venv/bin/python scripts/eevee_fidelity.py --named   # the presets and named paints
    .venv-bpy52/bin/python scripts/eevee_fidelity.py      # Blender 5.2 LTS

Method.  Every paint of ``lut.bench.random_paints`` is made a material by the
add-on (``addon.api``: its type baked, fitted for EEVEE against the running
line's measured closure responses) and put on its own sphere of the
calibration scene (``calibrate_eevee.SphereScene``: orthographic camera, delta
Sun without shadows, black world, one sample per pixel, film filter off).
One render fixes the angle γ between light and view; a sweep of γ gives
every sphere's pixels a spread of (θl, θv, φ) (from the Normal pass), so one
sweep measures every paint at once.  Each paint's pixels are compared with
``Paint.brdf``·cos θl by ``lut.bench.binned_error``: the acceptance measure
(cos-weighted relative RMS, θl, θv <= 75°, away from the mirror direction)
on 5° × 5° × 15° bins.  Printed beside it: the error the EEVEE fit reports
(``Fit.error``, on the acceptance and dense grids: what the panel shows).  And, for the viewport
against the final render, the same pixels against Cycles' render of the
same materials (``--cycles``)."""

from __future__ import annotations

import argparse
import json
import math
import pathlib
import sys
import tempfile
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from lut import bench  # noqa: E402
from lut.lutfiles import files  # noqa: E402
from lut.render import fitting  # noqa: E402

#: Light-view angles of the sweep (degrees).
GAMMAS = tuple(range(0, 176, 10))
#: Pixels across a sphere: enough samples for the bins, few enough that the
#: model's evaluation on them (rough types: quadrature) stays quick.
CELL = 48


def measure(paints, directory, gammas=GAMMAS, cycles=False, cell=CELL, raw=None):
    """Per (label, lut.Paint) of ``paints`` (materials baked in
    ``directory``): {"label", "paint", "eevee" (rendered error), "eevee_fit"
    and "cycles_fit" (the errors the fits report), "bins"}, and with ``cycles`` "cycles" (the
    same spheres in Cycles against the model) and "eevee_vs_cycles" (EEVEE's
    pixels against Cycles'); ``raw``: a dict to receive each paint's samples.
    The add-on must be registered."""
    from addon import api
    from scripts.calibrate_eevee import SphereScene

    scene = SphereScene([None] * len(paints), cell=cell)
    rows = []
    for sphere, (label, paint) in zip(scene.objects, paints, strict=True):
        material = api.new_material(label, paint, directory=directory)
        sphere.data.materials.append(material)
        reported = api.fit_errors(material)
        rows.append(
            {
                "label": label,
                "paint": paint,
                "eevee_fit": reported.get("EEVEE", (None,))[0],
                "cycles_fit": reported.get("CYCLES", (None,))[0],
            }
        )
    samples = _sweep(scene, gammas)
    cycles_samples = None
    if cycles:
        engine = scene.scene.render.engine
        scene.scene.render.engine = "CYCLES"
        scene.scene.cycles.device = "CPU"
        scene.scene.cycles.samples = 1  # exact: a delta Sun, every closure evaluated per light sample
        scene.scene.cycles.use_denoising = False
        scene.scene.cycles.max_bounces = 0  # direct light only: no sphere mirrors its neighbours
        cycles_samples = _sweep(scene, gammas)
        scene.scene.render.engine = engine
    for i, row in enumerate(rows):
        tl, tv, ph, rgb = samples[i]
        model = row["paint"].brdf(tl, tv, ph) * np.cos(tl)[:, None]
        row["eevee"], row["bins"] = bench.binned_error(tl, tv, ph, rgb, model)
        if raw is not None:
            raw[row["label"]] = (tl, tv, ph, rgb, model, None if cycles_samples is None else cycles_samples[i][3])
        if cycles_samples is not None:
            crgb = cycles_samples[i][3]
            row["cycles"] = bench.binned_error(tl, tv, ph, crgb, model)[0]
            row["eevee_vs_cycles"] = bench.binned_error(tl, tv, ph, rgb, crgb)[0]
    return rows


#: Pixels next to a sphere's silhouette left out: EEVEE shades them several
#: times brighter than the surface inside (Cycles does not).
ERODE = 2


def _sweep(scene, gammas):
    """Per sphere: the concatenated (θl, θv, φ, radiance) of the sweep."""
    per = [[] for _ in scene.objects]
    for gamma in gammas:
        for i, s in enumerate(scene.render(math.radians(gamma), erode=ERODE)):
            per[i].append(s)
    return [tuple(np.concatenate([x[j] for x in s]) for j in range(4)) for s in per]


def summary(rows, key="eevee"):
    """{class: (worst, median, count)} of ``key`` over the rows, smooth and rough."""
    out = {}
    for name, rough in (("smooth", False), ("rough", True)):
        values = [r[key] for r in rows if (r["paint"].slope > 0) == rough and r.get(key) is not None]
        if values:
            out[name] = (max(values), float(np.median(values)), len(values))
    return out


def main(argv=None) -> int:
    import bpy

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    version = "{}.{}".format(*bpy.app.version[:2])
    default_out = ROOT / "scripts" / "data" / f"eevee_fidelity-{version}.json"
    parser.add_argument("--random", type=int, default=24, help="paints of the randomised set (lut.bench.random_paints)")
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--cycles", action="store_true", help="also render the spheres in Cycles: EEVEE vs Cycles")
    parser.add_argument("--out", type=pathlib.Path, default=default_out)
    parser.add_argument("--luts", type=pathlib.Path, help="bake into (and reuse) this folder, not a temporary one")
    parser.add_argument(
        "--named", action="store_true", help="the named paints (addon.scenes.paints) instead of the randomised set"
    )
    args = parser.parse_args(argv)
    if args.named:
        from addon.scenes import paints as named

        paints = list(named().items())
        if args.out == default_out:
            args.out = default_out.with_name(f"eevee_fidelity-named-{version}.json")
    else:
        paints = bench.random_paints(args.random, args.seed)
    import addon

    addon.register()
    start = time.time()
    with tempfile.TemporaryDirectory() as tmp:
        rows = measure(paints, args.luts or pathlib.Path(tmp), cycles=args.cycles)
    report = {"blender": version, "seed": args.seed, "paints": {}}
    for row in rows:
        report["paints"][row["label"]] = {
            "rough": row["paint"].slope > 0,
            **{k: row.get(k) for k in ("eevee", "eevee_fit", "bins", "cycles", "cycles_fit", "eevee_vs_cycles")},
        }
        shown = "" if row["eevee_fit"] is None else f"{row['eevee_fit']:6.2%}"
        extra = ""
        if "cycles" in row:
            extra = f"  Cycles {row['cycles']:6.2%}  EEVEE vs Cycles {row['eevee_vs_cycles']:6.2%}"
        print(f"{row['label']:28s} EEVEE {row['eevee']:6.2%}  fit reports {shown}  ({row['bins']} bins){extra}")
    report["summary"] = {}
    for key in ("eevee", "cycles", "eevee_vs_cycles"):
        targets = fitting.TARGET_ERROR["CYCLES" if key == "cycles" else "EEVEE"]
        for name, (worst, median, count) in summary(rows, key).items():
            report["summary"][f"{key} {name}"] = {"worst": worst, "median": median, "count": count}
            met = sum(1 for r in rows if (r["paint"].slope > 0) == (name == "rough") and r[key] <= targets[name])
            print(
                f"{key:16s} {name:6s} n={count:2d} worst {worst:.2%} median {median:.2%};"
                f" {met} within {targets[name]:.0%}"
            )
    files.atomic_write_text(args.out, json.dumps(report, indent=2) + "\n")
    print(f"Blender {version}: {len(rows)} paints in {time.time() - start:.0f} s; wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
