"""Does EEVEE render a sum of closures as the sum of their single responses,
at one sample per pixel?  The assumption an EEVEE fit rests on.

Spheres under a delta Sun (``scripts/calibrate_eevee.SphereScene``): the
sums ``CASES`` of closures of ``TERMS`` (Add Shader; the Metallic lobes
through Mix Shader factors, as the add-on builds them), and every closure
of ``TERMS`` alone with its weight.  Per sum and light angle γ it
prints the ratio of the summed render to the sum of the single renders (its
mean, and its spread over the pixels: EEVEE evaluating only some closures
per pixel, or choosing them at random, shows as a spread).

    .venv/bin/python scripts/eevee_additivity.py"""

from __future__ import annotations

import math
import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from lut.render.closures import Closure  # noqa: E402
from scripts.calibrate_eevee import SphereScene  # noqa: E402

#: (closure, weight) in the order the sums take them: two diffuse closures
#: first (same type), then microfacet lobes of three roughnesses.
TERMS = [
    (Closure("lambert"), 0.3),
    (Closure("retro_toon", 0.3, 0.2), 0.2),
    (Closure("metallic", ior=1.5, roughness=0.5), 0.7),
    (Closure("glossy", roughness=0.3), 0.5),
    (Closure("glossy", roughness=0.7), 0.4),
    (Closure("metallic", ior=1.5, roughness=0.2), 0.6),
    (Closure("lambert"), 0.25),
    (Closure("metallic", ior=1.5, roughness=0.9), 0.8),
    (Closure("retro_glossy", roughness=0.8), 0.4),
    (Closure("metallic", ior=1.5, roughness=0.0), 0.9),
]
#: The sums measured: indices into ``TERMS``.  Prefixes of TERMS, and pairs
#: and triples that tell which closures EEVEE keeps apart.
CASES = {
    "first 2": [0, 1],
    "first 3": [0, 1, 2],
    "first 5": [0, 1, 2, 3, 4],
    "all 8": list(range(8)),
    "2 Lambert": [0, 6],
    "Lambert + Glossy": [0, 3],
    "Lambert + Metallic": [0, 2],
    "2 Glossy": [3, 4],
    "Glossy + Metallic": [3, 5],
    "2 Metallic": [2, 5],
    "Lambert + Glossy + Metallic": [0, 3, 5],
    "retro + Glossy + Metallic": [1, 3, 5],
    "all 7 but retro": [0, 2, 3, 4, 5, 6, 7],
    "retro + Glossy": [1, 3],
    "retro + 2 Lambert": [1, 0, 6],
    "3 reflection": [3, 4, 2],
    "4 reflection": [3, 4, 2, 5],
    "Lambert + 3 reflection": [0, 3, 4, 2],
    "2 Lambert + 2 reflection": [0, 6, 3, 2],
    "Lambert + retro glossy + mirror": [0, 8, 9],
}
GAMMAS = (0.0, 30.0, 60.0)


def measure(gammas=GAMMAS, cases=CASES, terms=TERMS, cell=64):
    """{(case, γ): (sum render, Σ single renders)} per lit pixel, red channel."""
    materials = [[terms[i] for i in idx] for idx in cases.values()] + [[t] for t in terms]
    scene = SphereScene(materials, cell=cell)
    out = {}
    for gamma in gammas:
        spheres = scene.render(math.radians(gamma))
        singles = [s[3][:, 0] for s in spheres[len(cases) :]]
        for i, (name, idx) in enumerate(cases.items()):
            out[(name, gamma)] = (spheres[i][3][:, 0], np.sum([singles[j] for j in idx], axis=0))
    return out


def main(argv=None):
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", nargs="*", default=list(CASES), help="names of CASES to measure")
    args = parser.parse_args(argv)
    for (name, gamma), (summed, parts) in measure(cases={k: CASES[k] for k in args.cases}).items():
        lit = parts > 1e-3 * parts.max()
        r = summed[lit] / parts[lit]
        print(
            f"{name:28s} gamma {gamma:3.0f}: sum/parts mean {r.mean():.4f}, pixel std {r.std():.4f}, "
            f"range {r.min():.3f}-{r.max():.3f}, "
            f"relative RMS {np.sqrt(np.mean((summed - parts) ** 2) / np.mean(parts**2)):.4f}"
        )


if __name__ == "__main__":
    main()
