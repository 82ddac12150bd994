"""What the EEVEE calibration buys: the EEVEE fit of a paint type made with
``lut.render.eevee.evaluate`` (EEVEE's measured closures) in place of
``Closure.evaluate`` (Cycles' formulas), rendered by EEVEE and measured
against the model like ``scripts/render_fidelity.py`` (the plane oracle of
addon/scenes.py on its EEVEE grid, the fidelity measure ``lut.render.measure``,
whole and over the grazing band θl >= 60°).

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
import numpy as np  # noqa: E402

from addon import nodes  # noqa: E402
from addon.scenes import EEVEE, GRID_EEVEE, Oracle, grid_points, oracle_errors, paints  # noqa: E402
from lut.paint.core import Paint  # noqa: E402
from lut.render import bake as render_bake  # noqa: E402
from lut.render import eevee, fitting  # noqa: E402


def predicted_errors(table, fit, evaluate, paint, grid):
    """(whole, grazing band) fidelity measure of ``fit`` at ``paint``'s colours
    on the oracle's ``grid`` (``addon.scenes.grid_points``) with its closures
    evaluated by ``evaluate``, through the weights the node group reads,
    against the paper's model (``fitting.measure_grams``)."""
    tl, tv, ph = grid_points(paint, grid)
    kind = Paint.from_dict(table.meta["type"])
    nodes_ = {k: tuple(table.meta[k]) for k in ("single_nodes", "diffuse_nodes") if k in table.meta}
    model = (tl, tv, ph), kind.components(tl, tv, ph, **nodes_) * np.cos(tl)[:, None, None]
    # The weights at the fitted views (every VIEW_SUBDIVISION-th column of the texture).
    views = fit.weights[:, :, :: fitting.VIEW_SUBDIVISION]
    cos_view = fit.cos_view[:: fitting.VIEW_SUBDIVISION]
    whole, band = fitting.measure_grams(model, fit.closures, cos_view, views, evaluate)
    grams = {"residual": whole[0], "reference": whole[1], "grazing_residual": band[0], "grazing_reference": band[1]}
    return fitting.reported_errors(grams, table.amplitudes(paint))


def rendered_errors(oracle, paint, fit, weights_path, label):
    """EEVEE's (whole, grazing band) fidelity measure for ``fit`` wired into a
    fresh material."""
    fitting.write_fit(fit, weights_path)
    material = oracle.material(label)
    group = nodes.build_group(fit, weights_path)
    nodes.wire(material, {"EEVEE": group}, render_bake.node_inputs(paint, fit.internal_reflectance))
    return oracle_errors(oracle, paint, GRID_EEVEE)


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
        baked = render_bake.bake_for_render(
            paint, directory, targets=("EEVEE",), eevee_calibration=version, eevee_mode="EXACT"
        )  # the exact fits, rendered at one sample
        table, default = baked.lut, baked.fits["EEVEE"]
        amps = table.amplitudes(paint)
        variants = {
            "Cycles formulas": fitting.fit_lut(table, "EEVEE", eevee_mode="EXACT"),
            "calibrated (add-on)": default,
        }
        for i, (label, fit) in enumerate(variants.items()):
            # The error each fit should have in EEVEE if its closures render as
            # measured, on the rendered grid.
            predicted = predicted_errors(table, fit, calibrated, paint, GRID_EEVEE)
            got = rendered_errors(oracle, paint, fit, directory / f"fit-{i}-{table.key[:8]}.exr", f"{name} {i}")
            reported = (fit.error(amps), fit.grazing_error(amps))
            kinds = ", ".join(f"{c.kind}" + (f" r{c.roughness:g}" if c.kind in ("glossy", "metallic") else "")
                              for c in fit.closures)  # fmt: skip
            print(
                f"{name:13s} {label:26s} EEVEE render {got[0]:.4f} / {got[1]:.4f}"
                f"  predicted {predicted[0]:.4f} / {predicted[1]:.4f}"
                f"  fit reports {reported[0]:.4f} / {reported[1]:.4f}  [{kinds}]",
                flush=True,
            )
    print("(each figure: whole measure / grazing band, theta_l >= 60 degrees)")


if __name__ == "__main__":
    main()
