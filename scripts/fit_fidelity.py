"""Fit fidelity on randomised sets without Blender: the error each engine's
closure fit reports for a paint (the panel's figure; Cycles renders land
within 0.5% of it plus a tenth), per paint and as worst and median: the
fidelity measure (``lut.render.measure``) over its whole grid and over the
grazing band (θl >= 60°), each against its goal (``measure.goals``); and
the Cycles fit between the measure's points ("CYCLES between": the grid of
``measure.BETWEEN_GRID``, lights shifted half a step, none at the mirror),
a check that a fit does not buy the measure's points with the shape
between them.

    .venv/bin/python scripts/fit_fidelity.py [--set dark|random] [--count 24] [--seed N]
    .venv/bin/python scripts/fit_fidelity.py --limits
    .venv/bin/python scripts/fit_fidelity.py --set random --budgets 3 5 8

``--budgets``: the Cycles fit's error against its closure budget (render
cost grows with each closure: ``scripts/render_cost.py --per-kind``), each
budget without extra closures, beside the default (``BUDGET`` and
``EXTRA_BUDGET`` where a goal is missed).

``--set random`` is the randomised set of ``lut.bench.random_paints``;
``--set dark`` the dark, facet-dominated rough paints of
``lut.bench.dark_paints``.  Cycles is fitted as Blender 5 renders it
(exact dielectric Metallic lobes) and as Blender 4.2-4.5 do (GGX lobes);
EEVEE against Blender 5.0's measured closure responses; "OSL" is Cycles'
OSL variant (``lut.render.fitting.fit_osl``), against its own goals."""

from __future__ import annotations

import argparse
import json
import pathlib
import sys
import tempfile

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from lut import bench  # noqa: E402
from lut.lutfiles import files  # noqa: E402
from lut.render import bake as render_bake  # noqa: E402
from lut.render import fitting, measure  # noqa: E402

SETS = {"random": bench.random_paints, "dark": bench.dark_paints}

#: Black-pigment paints (facet term alone but for a trace of diffuse) for
#: ``--limits``: how far more closures take the Cycles fit of a facet term.
LIMIT_TYPES = (("gaussian", 1.0), ("gaussian", 2.0), ("exponential", 2.0), ("exponential", 3.0))


def limits(directory, budgets=(8, 12, 40)):
    """[(distribution, slope, {budget: Cycles (whole, grazing) error})] of
    ``LIMIT_TYPES`` on ρ = 0.02, no single scattering, surface reflection 1."""
    from lut.lutfiles import baking
    from lut.paint.core import Paint

    rows = []
    for distribution, slope in LIMIT_TYPES:
        paint = Paint(rho=0.02, single=0.0, slope=slope, distribution=distribution, facet=1.0)
        table = baking.load_lut(baking.bake(paint, directory))
        amps = table.amplitudes(paint)
        errors = {}
        for b in budgets:
            fitted = fitting.fit_lut(table, "CYCLES", budget=b, extra_budget=0)
            errors[b] = (fitted.error(amps), fitted.grazing_error(amps))
        rows.append((distribution, slope, errors))
    return rows


def budget_tradeoff(paints, directory, budgets):
    """{budget label: [(paint, (whole, grazing) error, closures counted)]}
    of the Cycles fit of each paint within each budget (no extra closures),
    and of the default fit ("default")."""
    from lut.lutfiles import baking

    rows = {f"{b}": [] for b in budgets} | {"default": []}
    for _, paint in paints:
        table = baking.load_lut(baking.bake(paint, directory))
        amps = table.amplitudes(paint)
        for label, kwargs in [(f"{b}", {"budget": b, "extra_budget": 0}) for b in budgets] + [("default", {})]:
            fitted = fitting.fit_lut(table, "CYCLES", **kwargs)
            counted = sum(c.cost for c in fitted.closures)
            rows[label].append((paint, (fitted.error(amps), fitted.grazing_error(amps)), counted))
    return rows


def fidelity(paints, directory):
    """[(label, paint, {"CYCLES", "OSL" (Cycles' OSL variant), "CYCLES 4.x",
    "EEVEE": reported (whole, grazing band) error; "CYCLES between": the
    Cycles fit between the measure's points, ``fitting.between_errors``})]."""
    rows = []
    for label, paint in paints:
        status = render_bake.bake_for_render(paint, directory, eevee_calibration=(5, 0), osl=True)
        errors = status.all_errors(paint)
        errors["CYCLES between"] = fitting.between_errors(status.fits["CYCLES"], paint, status.lut.amplitudes(paint))
        errors["CYCLES 4.x"] = render_bake.bake_for_render(
            paint, directory, targets=("CYCLES",), exact_metallic=False
        ).all_errors(paint)["CYCLES"]
        rows.append((label, paint, errors))
    return rows


#: The two figures of each fit: the measure's whole grid and its grazing band.
BANDS = ("whole", "grazing")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--set", choices=sorted(SETS), default="dark")
    parser.add_argument("--count", type=int, default=24)
    parser.add_argument("--seed", type=int, help="the set's seed (default: the set's own)")
    parser.add_argument("--out", type=pathlib.Path, help="write the figures to this JSON file")
    parser.add_argument(
        "--limits", action="store_true", help="instead: black-pigment facet terms fitted with 8, 12 and 40 closures"
    )
    parser.add_argument(
        "--budgets", type=int, nargs="+", help="instead: the Cycles fit within each of these closure budgets"
    )
    args = parser.parse_args(argv)
    if args.budgets:
        kwargs = {} if args.seed is None else {"seed": args.seed}
        with tempfile.TemporaryDirectory() as tmp:
            tradeoff = budget_tradeoff(SETS[args.set](args.count, **kwargs), pathlib.Path(tmp), args.budgets)
        print(
            "| budget | kind | closures (median, most) | worst whole / grazing"
            " | median whole / grazing | within goals |"
        )
        print("|---|---|---|---|---|---|")
        for label, rows in tradeoff.items():
            for name, rough in (("smooth", False), ("rough", True)):
                chosen = [(e, n) for p, e, n in rows if (p.slope > 0) == rough]
                if not chosen:
                    continue
                errors = np.array([e for e, _ in chosen])
                counts = [n for _, n in chosen]
                goals = measure.goals("CYCLES", not rough)
                within = sum(e[0] <= goals[0] and e[1] <= goals[1] for e in errors)
                print(
                    f"| {label} | {name} | {np.median(counts):g}, {max(counts)} "
                    f"| {errors[:, 0].max():.2%} / {errors[:, 1].max():.2%} "
                    f"| {np.median(errors[:, 0]):.2%} / {np.median(errors[:, 1]):.2%} "
                    f"| {within} of {len(errors)} |"
                )
        return 0
    if args.limits:
        with tempfile.TemporaryDirectory() as tmp:
            for distribution, slope, errors in limits(pathlib.Path(tmp)):
                shown = ", ".join(f"{b} closures {e[0]:.2%} (grazing {e[1]:.2%})" for b, e in errors.items())
                print(f"{distribution} slope {slope:g}, rho 0.02: {shown}", flush=True)
        return 0
    kwargs = {} if args.seed is None else {"seed": args.seed}
    paints = SETS[args.set](args.count, **kwargs)
    with tempfile.TemporaryDirectory() as tmp:
        rows = fidelity(paints, pathlib.Path(tmp))
    keys = ("CYCLES", "OSL", "CYCLES 4.x", "EEVEE", "CYCLES between")
    print("| paint | " + " | ".join(f"{k} | {k} grazing" for k in keys) + " |")
    print("|---" * (2 * len(keys) + 1) + "|")
    for label, _, errors in rows:
        print(f"| {label} | " + " | ".join(f"{errors[k][0]:.2%} | {errors[k][1]:.2%}" for k in keys) + " |")
    report = {
        "set": args.set,
        "paints": {
            label: {k: dict(zip(BANDS, e, strict=True)) for k, e in errors.items()} for label, _, errors in rows
        },
        "summary": {},
    }
    for name, rough in (("smooth", False), ("rough", True)):
        chosen = [(p, e) for _, p, e in rows if (p.slope > 0) == rough]
        if not chosen:
            continue
        for key in keys:
            # "CYCLES between" is held to Cycles' goals.
            goals = measure.goals({"EEVEE": "EEVEE", "OSL": "OSL"}.get(key, "CYCLES"), not rough)
            for band, goal in zip(BANDS, goals, strict=True):
                which = BANDS.index(band)
                values = np.array([e[key][which] for _, e in chosen])
                misses = [f"{p.distribution[:3]} {p.slope:g}" for p, e in chosen if e[key][which] > goal]
                report["summary"][f"{key} {band} {name}"] = {
                    "worst": float(values.max()),
                    "median": float(np.median(values)),
                    "within": int(len(values) - len(misses)),
                    "goal": goal,
                    "count": len(values),
                }
                missed = f" (misses: {', '.join(misses)})" if misses else ""
                print(
                    f"{key:10s} {band:7s} {name:6s} n={len(values):2d} worst {values.max():.2%}"
                    f" median {np.median(values):.2%}; {len(values) - len(misses)} within {goal:.0%}{missed}"
                )
    if args.out:
        files.atomic_write_text(args.out, json.dumps(report, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
