"""EEVEE render fidelity of paint materials on the randomised set, for the
running Blender line (the README's EEVEE column).

    .venv/bin/python scripts/eevee_fidelity.py [--random 24] [--seed 2026] [--out FILE.json]
    .venv/bin/python scripts/eevee_fidelity.py --named   # the presets and named paints
    .venv-bpy52/bin/python scripts/eevee_fidelity.py      # Blender 5.2 LTS
    .venv/bin/python scripts/eevee_fidelity.py --eevee-mode CONVERGED   # at 64 samples

Method.  Every paint of ``lut.bench.random_paints`` is made a material by the
add-on (``addon.api``: its type baked, fitted for EEVEE against the running
line's measured closure responses, in the scene's EEVEE mode Exact at 1
sample) and put on its own sphere of the
calibration scene (``calibrate_eevee.SphereScene``: orthographic camera, delta
Sun without shadows, black world, one sample per pixel, film filter off).
One render fixes the angle γ between light and view; a sweep of γ gives
every sphere's pixels a spread of (θl, θv, φ) (from the Normal pass), so one
sweep measures every paint at once.  Each paint's pixels are compared with
``Paint.brdf``·cos θl by ``lut.bench.binned_errors``: the fidelity measure
(``lut.render.measure``: relative RMS of radiance, every bin of its 5° × 5°
× 10° grid counted once, a smooth paint's mirror left out), whole and over
the grazing band (θl >= 60°).  Printed beside it: the errors the EEVEE fit
reports (``Fit.error``, ``Fit.grazing_error``: what the panel shows).  And,
for the viewport against the final render, the same pixels against Cycles'
render of the same materials (``--cycles``)."""

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
from lut.render import measure as fidelity  # noqa: E402

#: Light-view angles of the sweep (degrees).
GAMMAS = tuple(range(0, 176, 10))
#: Pixels across a sphere: enough samples for the bins, few enough that the
#: model's evaluation on them (rough types: quadrature) stays quick.
CELL = 48


def measure(paints, directory, gammas=GAMMAS, cycles=False, cell=CELL, raw=None, eevee_mode="EXACT", samples=1):
    """Per (label, lut.Paint) of ``paints`` (materials baked in
    ``directory``): {"label", "paint", "eevee" (rendered error), "eevee_fit"
    and "cycles_fit" (the errors the fits report), "bins"}, and with
    ``cycles`` "cycles" (the same spheres in Cycles against the model) and
    "eevee_vs_cycles" (EEVEE's pixels against Cycles'); each error also as
    "<key>_grazing", over the grazing band.  ``raw``: a dict to receive each
    paint's samples.  ``eevee_mode``: the scene's EEVEE mode the materials
    are baked in; ``samples``: EEVEE's samples per pixel (one is all an
    "EXACT" fit needs; a "CONVERGED" one is drawn at a final render's 64).
    The add-on must be registered."""
    from addon import api
    from scripts.calibrate_eevee import SphereScene

    scene = SphereScene([None] * len(paints), cell=cell)
    scene.scene.paint_lut.eevee_mode = eevee_mode
    scene.scene.eevee.taa_render_samples = samples
    rows = []
    for sphere, (label, paint) in zip(scene.objects, paints, strict=True):
        material = api.new_material(label, paint, directory=directory)
        sphere.data.materials.append(material)
        reported = api.fit_errors(material)
        row = {"label": label, "paint": paint}
        for engine in ("EEVEE", "CYCLES"):
            fit = reported.get(engine)
            row[f"{engine.lower()}_fit"] = None if fit is None else fit.error
            row[f"{engine.lower()}_fit_grazing"] = None if fit is None else fit.grazing
        rows.append(row)
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
        smooth = row["paint"].slope == 0
        model = row["paint"].brdf(tl, tv, ph) * np.cos(tl)[:, None]
        row["eevee"], row["eevee_grazing"], row["bins"] = bench.binned_errors(tl, tv, ph, rgb, model, smooth=smooth)
        if raw is not None:
            raw[row["label"]] = (tl, tv, ph, rgb, model, None if cycles_samples is None else cycles_samples[i][3])
        if cycles_samples is not None:
            crgb = cycles_samples[i][3]
            row["cycles"], row["cycles_grazing"], _ = bench.binned_errors(tl, tv, ph, crgb, model, smooth=smooth)
            row["eevee_vs_cycles"], row["eevee_vs_cycles_grazing"], _ = bench.binned_errors(
                tl, tv, ph, rgb, crgb, smooth=smooth
            )
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
    """{class: (worst, median, count)} of ``key`` over the rows, smooth and
    rough (rows without the figure left out)."""
    out = {}
    for name, rough in (("smooth", False), ("rough", True)):
        values = [r[key] for r in rows if (r["paint"].slope > 0) == rough and r.get(key) is not None]
        if values:
            out[name] = (max(values), float(np.median(values)), len(values))
    return out


def _pair(row, key) -> str:
    """A row's figure, whole / grazing band."""
    whole, grazing = row.get(key), row.get(f"{key}_grazing")
    shown = [" n/a  " if v is None else f"{v:6.2%}" for v in (whole, grazing)]
    return " / ".join(shown)


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
        "--eevee-mode",
        choices=("EXACT", "CONVERGED"),
        default="EXACT",
        help="the scene's EEVEE mode the materials are baked in (CONVERGED: rendered at --samples, default 64)",
    )
    parser.add_argument("--samples", type=int, help="EEVEE samples per pixel (default 1 for EXACT, 64 for CONVERGED)")
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
    if args.eevee_mode == "CONVERGED" and args.out == default_out:
        args.out = default_out.with_name(f"eevee_fidelity-converged-{version}.json")
    import addon

    addon.register()
    start = time.time()
    with tempfile.TemporaryDirectory() as tmp:
        samples = args.samples or (64 if args.eevee_mode == "CONVERGED" else 1)
        rows = measure(
            paints, args.luts or pathlib.Path(tmp), cycles=args.cycles, eevee_mode=args.eevee_mode, samples=samples
        )
    report = {"blender": version, "seed": args.seed, "eevee_mode": args.eevee_mode, "samples": samples, "paints": {}}
    figures = ("eevee", "eevee_fit", "bins", "cycles", "cycles_fit", "eevee_vs_cycles")
    for row in rows:
        report["paints"][row["label"]] = {
            "rough": row["paint"].slope > 0,
            **{k: row.get(k) for k in figures},
            **{f"{k}_grazing": row.get(f"{k}_grazing") for k in figures if k != "bins"},
        }
        extra = ""
        if "cycles" in row:
            extra = f"  Cycles {_pair(row, 'cycles')}  EEVEE vs Cycles {_pair(row, 'eevee_vs_cycles')}"
        print(
            f"{row['label']:28s} EEVEE {_pair(row, 'eevee')}  fit reports {_pair(row, 'eevee_fit')}"
            f"  ({row['bins']} bins){extra}"
        )
    print("(each figure: whole measure / grazing band, theta_l >= 60 degrees)")
    report["summary"] = {}
    for key in ("eevee", "cycles", "eevee_vs_cycles"):
        engine = "CYCLES" if key == "cycles" else "EEVEE"
        for band in ("", "_grazing"):
            for name, (worst, median, count) in summary(rows, key + band).items():
                report["summary"][f"{key}{band} {name}"] = {"worst": worst, "median": median, "count": count}
                goal = fidelity.goals(engine, name == "smooth")[1 if band else 0]
                met = sum(
                    1
                    for r in rows
                    if (r["paint"].slope > 0) == (name == "rough")
                    and r.get(key + band) is not None
                    and r[key + band] <= goal
                )
                print(
                    f"{key + band:24s} {name:6s} n={count:2d} worst {worst:.2%} median {median:.2%};"
                    f" {met} within {goal:.0%}"
                )
    files.atomic_write_text(args.out, json.dumps(report, indent=2) + "\n")
    print(f"Blender {version}: {len(rows)} paints in {time.time() - start:.0f} s; wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
