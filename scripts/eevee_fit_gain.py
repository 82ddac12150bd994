"""What the EEVEE calibration buys: the EEVEE fit of a paint type made with
``lut.render.eevee.evaluate`` (EEVEE's measured closures) in place of
``Closure.evaluate`` (Cycles' formulas), rendered by EEVEE and measured
against the model like ``scripts/render_fidelity.py`` (the plane oracle of
addon/scenes.py on its EEVEE grid, cos-weighted relative RMS).

    .venv/bin/python scripts/eevee_fit_gain.py [--paints satin matte]

Per paint it prints the error of an EEVEE fit made with Cycles' formulas
and of the add-on's, made with the calibrated evaluator
(``lut.render.fitting.fit_lut(..., calibration=...)``), each rendered by EEVEE and
as ``lut.render.eevee`` predicts it."""

from __future__ import annotations

import argparse
import pathlib
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402

from addon import nodes  # noqa: E402
from addon.scenes import EEVEE, GRID_EEVEE, Oracle, paints, relative_rms  # noqa: E402
from lut.render import bake as render_bake  # noqa: E402
from lut.render import eevee, fitting  # noqa: E402


def _grams(table, fit, evaluate, grid):
    """The fit's residual and target Gram matrices on ``grid`` with its
    closures evaluated by ``evaluate`` (``fitting``'s acceptance error)."""
    return fitting._acceptance_grams(table, fit.closures, fit.cos_view, fit.weights, evaluate, grid)


def rendered_error(oracle, paint, fit, weights_path, label):
    """EEVEE's relative RMS for ``fit`` wired into a fresh material."""
    fitting.write_fit(fit, weights_path)
    material = oracle.material(label)
    group = nodes.build_group(fit, weights_path)
    nodes.wire(material, {"EEVEE": group}, render_bake.node_inputs(paint, fit.internal_reflectance))
    return relative_rms(oracle, paint, GRID_EEVEE)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--paints", nargs="*", default=["glossy white", "satin", "matte", "glossy red", "green CARC"])
    args = parser.parse_args(argv)
    version = bpy.app.version[:2]

    def calibrated(closure, tl, tv, ph):
        return eevee.evaluate(closure, tl, tv, ph, version=version)

    directory = pathlib.Path(tempfile.mkdtemp(prefix="eevee_fit_gain"))
    oracle = Oracle(engine=EEVEE)
    all_paints = paints()
    for name in args.paints:
        paint = all_paints[name]
        baked = render_bake.bake_for_render(paint, directory, targets=("EEVEE",), eevee_calibration=version)
        table, default = baked.lut, baked.fits["EEVEE"]
        amps = table.amplitudes(paint)
        variants = {
            "Cycles formulas": fitting.fit_lut(table, "EEVEE"),
            "calibrated (add-on)": default,
        }
        for i, (label, fit) in enumerate(variants.items()):
            # The error each fit should have in EEVEE if its closures render as
            # measured, on the rendered grid.
            res, ref = _grams(table, fit, calibrated, GRID_EEVEE)
            predicted = fitting.acceptance_error(res, ref, amps)
            got = rendered_error(oracle, paint, fit, directory / f"fit-{i}-{table.key[:8]}.exr", f"{name} {i}")
            kinds = ", ".join(f"{c.kind}" + (f" r{c.roughness:g}" if c.kind in ("glossy", "metallic") else "")
                              for c in fit.closures)  # fmt: skip
            print(
                f"{name:13s} {label:26s} EEVEE render {got:.4f}  predicted {predicted:.4f}  [{kinds}]",
                flush=True,
            )


if __name__ == "__main__":
    main()
