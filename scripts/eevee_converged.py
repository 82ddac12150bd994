"""EEVEE's two modes measured on randomised sets: the fidelity measure
(``lut.render.measure``, whole / grazing band) of the exact fit (at most the
three closures EEVEE sums exactly at one sample) and of the converged one
(more closures, averaged over samples), with the converged render's
per-pixel spread at 1, 16 and 64 samples (``lut.render.eevee.spread``) and
the samples it needs (``samples_needed``).

    .venv/bin/python scripts/eevee_converged.py [--set random|dark] [--count 24]
    .venv/bin/python scripts/eevee_converged.py --budgets 3 5 8 12
    .venv/bin/python scripts/eevee_converged.py --render 2 6 21

``--budgets``: the trade-off per closure budget (the converged fit's
largest number of closures; 3 is the exact fit): worst and median error
and spread at 16 samples over the rough paints.  ``--render``: renders
those paints of the set (indices) with EEVEE on the plane oracle
(``addon/scenes.py``, its EEVEE grid, the mean of 16 × 16 pixels at one
sample) in both modes, against the model and against what the fit
predicts, and the spread at 1 and 16 samples at the geometry where the
converged fit is noisiest.  Errors use Blender 5.0's measured EEVEE
responses."""

from __future__ import annotations

import argparse
import pathlib
import sys
import tempfile

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from lut import bench  # noqa: E402
from lut.lutfiles import baking  # noqa: E402
from lut.render import eevee, fitting  # noqa: E402

SETS = {"random": bench.random_paints, "dark": bench.dark_paints}
CALIBRATION = (5, 0)


def fits(table, **converged):
    """(exact, converged) EEVEE fits of a loaded LUT."""
    exact = fitting.fit_lut(table, "EEVEE", calibration=CALIBRATION, eevee_mode="EXACT")
    conv = fitting.fit_lut(table, "EEVEE", calibration=CALIBRATION, eevee_mode="CONVERGED", **converged)
    return exact, conv


def modes(paints, directory):
    """Per paint: (label, paint, exact (whole, grazing), converged (whole,
    grazing), closures, sums exactly, spread at 1/16/64 samples, samples needed)."""
    rows = []
    for label, paint in paints:
        table = baking.load_lut(baking.bake(paint, directory))
        amps = table.amplitudes(paint)
        exact, conv = fits(table)
        spreads = [eevee.spread(conv, amps, s) for s in (1, 16, 64)]
        rows.append(
            (
                label, paint, (exact.error(amps), exact.grazing_error(amps)),
                (conv.error(amps), conv.grazing_error(amps)), len(conv.closures), conv.sums_exactly,
                spreads, eevee.samples_needed(conv, amps),
            )
        )  # fmt: skip
    return rows


def print_modes(rows) -> None:
    print("| paint | exact | converged | closures | spread 1 / 16 / 64 samples | samples needed |")
    print("|---|---|---|---|---|---|")
    for label, _, ex, cv, k, exact, spreads, samples in rows:
        kind = "exact" if exact else "converged"
        print(
            f"| {label} | {100 * ex[0]:.2f}% / {100 * ex[1]:.2f}% | {100 * cv[0]:.2f}% / "
            f"{100 * cv[1]:.2f}% | {k} ({kind}) | " + " / ".join(f"{100 * s:.1f}%" for s in spreads) + f" | {samples} |"
        )
    print()
    print("| paints | exact: worst | exact: median | converged: worst | converged: median | converged fits |")
    print("|---|---|---|---|---|---|")
    for name, smooth in (("smooth", True), ("rough", False)):
        sel = [r for r in rows if (r[1].slope == 0) == smooth]
        if not sel:
            continue
        ex = np.array([r[2] for r in sel])
        cv = np.array([r[3] for r in sel])
        count = sum(not r[5] for r in sel)
        print(
            f"| {name} ({len(sel)}) | {100 * ex[:, 0].max():.2f}% / {100 * ex[:, 1].max():.2f}% | "
            f"{100 * np.median(ex[:, 0]):.2f}% / {100 * np.median(ex[:, 1]):.2f}% | "
            f"{100 * cv[:, 0].max():.2f}% / {100 * cv[:, 1].max():.2f}% | "
            f"{100 * np.median(cv[:, 0]):.2f}% / {100 * np.median(cv[:, 1]):.2f}% | {count} |"
        )


def budgets(paints, directory, sizes) -> None:
    """The trade-off per closure budget over the rough paints of the set."""
    rough = [(label, paint) for label, paint in paints if paint.slope > 0]
    print("| budget | worst | median | spread at 16 samples: worst | median | converged fits |")
    print("|---|---|---|---|---|---|")
    tables = [(paint, baking.load_lut(baking.bake(paint, directory))) for _, paint in rough]
    for size in sizes:
        errors, spreads, count = [], [], 0
        for paint, table in tables:
            amps = table.amplitudes(paint)
            if size <= fitting.BUDGET["EEVEE"]:
                fit = fitting.fit_lut(table, "EEVEE", calibration=CALIBRATION, eevee_mode="EXACT")
            else:
                fit = fitting.fit_lut(
                    table, "EEVEE", calibration=CALIBRATION, eevee_mode="CONVERGED",
                    converged_budget=size, converged_extra=0,
                )  # fmt: skip
            errors.append(fit.error(amps))
            spreads.append(eevee.spread(fit, amps, eevee.VIEWPORT_SAMPLES))
            count += not fit.sums_exactly
        e, s = np.array(errors), np.array(spreads)
        print(
            f"| {size} | {100 * e.max():.2f}% | {100 * np.median(e):.2f}% | {100 * s.max():.1f}% | "
            f"{100 * np.median(s):.1f}% | {count} of {len(tables)} |"
        )


def render(paints, directory, indices) -> None:
    """EEVEE renders of both modes of the chosen paints (needs bpy)."""
    import bpy  # noqa: F401  (the add-on's scenes need Blender)

    from addon import nodes, scenes
    from lut.render import bake as render_bake
    from lut.render import measure

    oracle = scenes.Oracle(engine=scenes.EEVEE)
    oracle.scene.render.resolution_x = oracle.scene.render.resolution_y = 16
    print("| paint | mode | rendered | predicted | render vs predicted | spread at 1 / 16 samples (predicted) |")
    print("|---|---|---|---|---|---|")
    for i in indices:
        label, paint = paints[i]
        table = baking.load_lut(baking.bake(paint, directory))
        amps = table.amplitudes(paint)
        tl, tv, ph = scenes.grid_points(paint, scenes.GRID_EEVEE)
        model = paint.brdf(tl, tv, ph) * np.cos(tl)[:, None]
        for fit in fits(table):
            path = pathlib.Path(directory) / f"weights-{i}-{fit.eevee_mode}.exr"
            fitting.write_fit(fit, path)
            material = oracle.material(f"{label}-{fit.eevee_mode}")
            group = nodes.build_group(fit, path)
            nodes.wire(material, {"EEVEE": group}, render_bake.node_inputs(paint, fit.internal_reflectance))
            oracle.scene.eevee.taa_render_samples = 1
            got = np.array([oracle.radiance(*g) / oracle.irradiance for g in zip(tl, tv, ph, strict=True)])
            predicted = fit.radiance(amps, tl, tv, ph)
            rendered = measure.errors(got, model, tl)
            fitted = measure.errors(predicted, model, tl)
            noise = ""
            if not fit.sums_exactly:
                per_point = [eevee.spread(fit, amps, 1, ([a], [b], [c])) for a, b, c in zip(tl, tv, ph, strict=True)]
                g = int(np.argmax(per_point))
                measured = []
                for samples in (1, eevee.VIEWPORT_SAMPLES):
                    oracle.scene.eevee.taa_render_samples = samples
                    image = oracle.image(tl[g], tv[g], ph[g]).reshape(-1, 3)
                    measured.append(np.sqrt(image.var(axis=0).sum() / (image.mean(axis=0) ** 2).sum()))
                point = ([tl[g]], [tv[g]], [ph[g]])
                noise = (
                    f"θl {np.degrees(tl[g]):.0f}° θv {np.degrees(tv[g]):.0f}° φ {np.degrees(ph[g]):.0f}°: "
                    f"{100 * measured[0]:.0f}% ({100 * eevee.spread(fit, amps, 1, point):.0f}%) / "
                    f"{100 * measured[1]:.1f}% ({100 * eevee.spread(fit, amps, eevee.VIEWPORT_SAMPLES, point):.1f}%)"
                )
            print(
                f"| {label} | {fit.eevee_mode.lower()} ({len(fit.closures)}) | "
                f"{100 * rendered[0]:.2f}% / {100 * rendered[1]:.2f}% | "
                f"{100 * fitted[0]:.2f}% / {100 * fitted[1]:.2f}% | "
                f"{100 * measure.relative_rms(got, predicted):.2f}% | {noise} |",
                flush=True,
            )


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--set", choices=sorted(SETS), default="random")
    parser.add_argument("--count", type=int, default=24)
    parser.add_argument("--budgets", type=int, nargs="+", help="closure budgets to compare (3: the exact fit)")
    parser.add_argument("--render", type=int, nargs="+", metavar="INDEX", help="render these paints with EEVEE")
    args = parser.parse_args(argv)
    paints = SETS[args.set](args.count)
    directory = tempfile.mkdtemp(prefix="eevee_converged")
    if args.render:
        render(paints, directory, args.render)
    elif args.budgets:
        budgets(paints, directory, args.budgets)
    else:
        print_modes(modes(paints, directory))
    return 0


if __name__ == "__main__":
    sys.exit(main())
