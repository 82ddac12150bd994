"""Do EEVEE's calibration tables hold on a flat plane at grazing geometries?

Each closure alone (white, weight 1, built as ``scripts/calibrate_eevee``
builds it) on the plane oracle (``addon.scenes.Oracle``: a delta Sun, an
orthographic camera, a black world; EEVEE at one sample), rendered at
``GEOMETRIES`` and divided by what the tables give there
(``lut.render.eevee.evaluate``, the tables of the running Blender's
line).  A ratio of 1 is a table that is right.  The grazing mirror (θl, θv
60–75°, φ 0°) is where spheres' pixels thin out toward the silhouette, so
``scripts/calibrate_eevee.py`` fits that band to flat squares instead; this
checks it on the plane oracle, independently of both.

    .venv/bin/python scripts/eevee_table_check.py [--kind glossy] [--roughness 0.2 0.3 0.45 0.6]"""

from __future__ import annotations

import argparse
import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from lut.render import eevee  # noqa: E402
from lut.render.closures import Closure  # noqa: E402

#: (θl, θv, φ) in degrees: the grazing mirror and its neighbours, and one
#: geometry well inside the calibrated range (45°, 45°, 0°) as a control.
GEOMETRIES = ((75, 75, 0), (75, 65, 0), (65, 75, 0), (70, 70, 0), (65, 65, 0), (60, 60, 0), (75, 75, 15), (45, 45, 0))


def closure_of(kind: str, roughness: float) -> Closure:
    """The closure checked (a Metallic lobe at IOR 1.5)."""
    return Closure(kind, ior=1.5, roughness=roughness) if kind == "metallic" else Closure(kind, roughness=roughness)


def ratios(oracle, closure: Closure, calibration) -> list:
    """Rendered over tabled radiance of ``closure`` alone at ``GEOMETRIES``."""
    from scripts.calibrate_eevee import closure_shader

    tree = oracle.material(f"check-{closure.kind}-{closure.roughness:g}").node_tree
    tree.links.new(closure_shader(tree, closure, 1.0), tree.nodes["Material Output"].inputs["Surface"])
    theta_l, theta_v, phi = np.radians(GEOMETRIES).T
    tabled = eevee.evaluate(closure, theta_l, theta_v, phi, calibration)
    # One render per geometry: every pixel of the plane sees the same one.
    rendered = np.array([np.mean(oracle.radiance(*g)) for g in zip(theta_l, theta_v, phi, strict=True)])
    rendered /= oracle.irradiance
    return list(np.where(tabled > 0, rendered / np.where(tabled > 0, tabled, 1.0), np.nan))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--kind", default="glossy", choices=("glossy", "metallic", "retro_glossy"))
    parser.add_argument("--roughness", type=float, nargs="+", default=[0.2, 0.3, 0.387, 0.45, 0.531, 0.6])
    args = parser.parse_args(argv)
    import bpy

    from addon import scenes

    calibration = eevee.calibration_for(bpy.app.version)
    oracle = scenes.Oracle(engine=scenes.EEVEE)
    oracle.scene.render.resolution_x = oracle.scene.render.resolution_y = 8
    oracle.scene.eevee.taa_render_samples = 1
    print("| closure | " + " | ".join(f"{a}°, {b}°, {c}°" for a, b, c in GEOMETRIES) + " |")
    print("|---|" + "---|" * len(GEOMETRIES))
    for roughness in args.roughness:
        closure = closure_of(args.kind, roughness)
        row = ratios(oracle, closure, calibration)
        print(f"| {args.kind}, r = {roughness:g} | " + " | ".join(f"{r:.3f}" for r in row) + " |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
