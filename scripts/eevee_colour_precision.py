"""How precisely EEVEE keeps a closure's colour: spheres of one white
closure scaled by decreasing weights, each render against the weight-1
render times the weight (red channel, summed over the lit pixels).  EEVEE
stores closure colours in a 10-bit unsigned normalised buffer (steps of
1/1023, a shared exponent above 1), so dark colours lose relative
precision.

    .venv/bin/python scripts/eevee_colour_precision.py"""

from __future__ import annotations

import math
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from lut.render.closures import Closure  # noqa: E402
from scripts.calibrate_eevee import SphereScene  # noqa: E402

#: Colour weights measured, and the closures (a diffuse and a reflection one).
WEIGHTS = (1.0, 0.5, 0.2, 0.1, 0.05, 0.03, 0.02, 0.01, 0.005)
CLOSURES = (Closure("lambert"), Closure("glossy", roughness=0.6), Closure("retro_glossy", roughness=0.8))


def measure(weights=WEIGHTS, kinds=CLOSURES, gamma=0.4):
    """{(closure kind, weight): rendered / (weight × rendered at weight 1)}."""
    materials = [[(c, w)] for c in kinds for w in weights]
    spheres = SphereScene(materials, cell=48).render(gamma, erode=2)
    out = {}
    for i, c in enumerate(kinds):
        base = spheres[i * len(weights)][3][:, 0].sum() / weights[0]
        for j, w in enumerate(weights):
            out[(c.kind, w)] = float(spheres[i * len(weights) + j][3][:, 0].sum() / (w * base))
    return out


def main() -> int:
    result = measure(gamma=math.radians(25.0))
    print("| weight | " + " | ".join(c.kind for c in CLOSURES) + " |")
    print("|---" * (len(CLOSURES) + 1) + "|")
    for w in WEIGHTS:
        print(f"| {w:g} | " + " | ".join(f"{result[(c.kind, w)]:.4f}" for c in CLOSURES) + " |")
    worst = {c.kind: max(abs(result[(c.kind, w)] - 1.0) for w in WEIGHTS if w >= 0.02) for c in CLOSURES}
    print("largest deviation for weights >= 0.02: " + ", ".join(f"{k} {v:.1%}" for k, v in worst.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
