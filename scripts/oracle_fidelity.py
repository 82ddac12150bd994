"""Rendered against reported: each paint of a randomised set made with the
add-on, rendered by the Cycles oracle at every geometry of the fidelity
measure (``lut.render.measure``, whole and grazing band), beside the figures
its fit reports (what the panel shows).

    .venv/bin/python scripts/oracle_fidelity.py [--set random|dark] [--count 24] [--out FILE.json]

About a minute a paint (4,560 renders of a plane: delta Sun, orthographic
camera, black world; addon/scenes.py)."""

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
from addon.scenes import Oracle, oracle_errors, paint_material  # noqa: E402
from lut import bench  # noqa: E402
from lut.lutfiles import files  # noqa: E402
from lut.render import measure  # noqa: E402

SETS = {"random": bench.random_paints, "dark": bench.dark_paints}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--set", choices=sorted(SETS), default="random")
    parser.add_argument("--count", type=int, default=24)
    parser.add_argument("--out", type=pathlib.Path, help="write the figures to this JSON file")
    args = parser.parse_args(argv)
    oracle = Oracle()
    addon.register()
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        for label, paint in SETS[args.set](args.count):
            _, result = paint_material(oracle, paint, pathlib.Path(tmp))
            reported = result.all_errors(paint)["CYCLES"]
            rendered = oracle_errors(oracle, paint)
            rows[label] = {"rough": paint.slope > 0, "rendered": list(rendered), "reported": list(reported)}
            print(
                f"| {label} | {rendered[0]:.2%} ({reported[0]:.2%}) | {rendered[1]:.2%} ({reported[1]:.2%}) |",
                flush=True,
            )
    for rough in (False, True):
        chosen = [r for r in rows.values() if r["rough"] == rough]
        if not chosen:
            continue
        goals = measure.goals("CYCLES", not rough)
        got = np.array([r["rendered"] for r in chosen])
        within = int(np.sum((got[:, 0] <= goals[0]) & (got[:, 1] <= goals[1])))
        worst = np.max([np.subtract(r["rendered"], r["reported"]) for r in chosen], axis=0)
        print(
            f"{'rough' if rough else 'smooth'}: worst {got[:, 0].max():.2%} / {got[:, 1].max():.2%}, median"
            f" {np.median(got[:, 0]):.2%} / {np.median(got[:, 1]):.2%} (whole / grazing); {within} of {len(chosen)}"
            f" within both goals; rendered minus reported at most {worst[0]:+.2%} / {worst[1]:+.2%}"
        )
    if args.out:
        files.atomic_write_text(args.out, json.dumps(rows, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
