"""EEVEE render fidelity of paint materials on the randomised acceptance set,
for the running Blender line (the README's EEVEE column).

    .venv/bin/python scripts/eevee_fidelity.py [--random 24] [--seed 2026] [--out FILE.json]
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
on 5° × 5° × 15° bins.  Printed beside it: the error the EEVEE fit predicts
on the acceptance grid (what the panel shows).  And, for the viewport
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

from lut import bench, fitting, lutfile  # noqa: E402

#: Light-view angles of the sweep (degrees).
GAMMAS = tuple(range(0, 176, 10))
#: Pixels across a sphere: enough samples for the bins, few enough that the
#: model's evaluation on them (rough types: quadrature) stays quick.
CELL = 48


def measure(paints, directory, gammas=GAMMAS, cycles=False, cell=CELL, raw=None):
    """[(label, paint, rendered error, predicted error, bins, Cycles error or
    None)] for (label, lut.Paint) ``paints``, their materials baked in
    ``directory``; ``raw``: a dict to receive each paint's samples."""
    import bpy

    import addon
    from addon import api
    from scripts.calibrate_eevee import SphereScene

    addon.register()
    scene = SphereScene([None] * len(paints), cell=cell)
    results = []
    for sphere, (label, paint) in zip(scene.objects, paints, strict=True):
        material = api.new_material(label, paint, directory=directory)
        sphere.data.materials.append(material)
        results.append(api.fit_errors(material).get("EEVEE", (None,))[0])
    samples = _sweep(scene, gammas)
    cycles_samples = None
    if cycles:
        scene.scene.render.engine = "CYCLES"
        scene.scene.cycles.samples = 16
        scene.scene.cycles.use_denoising = False
        cycles_samples = _sweep(scene, gammas)
        scene.scene.render.engine = "BLENDER_EEVEE" if bpy.app.version >= (5, 0, 0) else "BLENDER_EEVEE_NEXT"
    out = []
    for i, (label, paint) in enumerate(paints):
        tl, tv, ph, rgb = samples[i]
        model = paint.brdf(tl, tv, ph) * np.cos(tl)[:, None]
        error, bins = bench.binned_error(tl, tv, ph, rgb, model)
        if raw is not None:
            raw[label] = (tl, tv, ph, rgb, model)
        versus = None
        if cycles_samples is not None:
            versus = _versus(samples[i], cycles_samples[i])
        out.append((label, paint, error, results[i], bins, versus))
    return out


def _sweep(scene, gammas):
    """Per sphere: the concatenated (θl, θv, φ, radiance) of the sweep."""
    per = [[] for _ in scene.objects]
    for gamma in gammas:
        for i, s in enumerate(scene.render(math.radians(gamma))):
            per[i].append(s)
    return [tuple(np.concatenate([x[j] for x in s]) for j in range(4)) for s in per]


def _versus(eevee_samples, cycles_samples):
    """EEVEE's pixels against Cycles' (the same pixels, the same geometry):
    the binned relative RMS with Cycles as the reference."""
    tl, tv, ph, rgb = eevee_samples
    return bench.binned_error(tl, tv, ph, rgb, cycles_samples[3])[0]


def summary(rows):
    """{class: (worst, median, count)} of the rendered errors, smooth and rough."""
    out = {}
    for name, rough in (("smooth", False), ("rough", True)):
        values = [r[2] for r in rows if (r[1].slope > 0) == rough]
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
    args = parser.parse_args(argv)
    paints = bench.random_paints(args.random, args.seed)
    start = time.time()
    with tempfile.TemporaryDirectory() as tmp:
        rows = measure(paints, pathlib.Path(tmp), cycles=args.cycles)
    report = {"blender": version, "seed": args.seed, "paints": {}}
    for label, paint, error, predicted, bins, versus in rows:
        report["paints"][label] = {
            "rough": paint.slope > 0,
            "eevee": error,
            "eevee_fit": predicted,
            "bins": bins,
            "eevee_vs_cycles": versus,
        }
        extra = "" if versus is None else f"  vs Cycles {versus:6.2%}"
        shown = "" if predicted is None else f"{predicted:6.2%}"
        print(f"{label:28s} EEVEE {error:6.2%}  fit reports {shown}  ({bins} bins){extra}", flush=True)
    targets = fitting.TARGET_ERROR["EEVEE"]
    report["summary"] = {}
    for name, (worst, median, count) in summary(rows).items():
        report["summary"][name] = {"worst": worst, "median": median, "count": count}
        met = sum(1 for r in rows if (r[1].slope > 0) == (name == "rough") and r[2] <= targets[name])
        print(f"{name:6s} n={count:2d} worst {worst:.2%} median {median:.2%}; {met} within {targets[name]:.0%}")
    lutfile.atomic_write_bytes(args.out, (json.dumps(report, indent=2) + "\n").encode())
    print(f"Blender {version}: {len(rows)} paints in {time.time() - start:.0f} s; wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
