"""What the EEVEE calibration buys: the EEVEE fit of a paint type made with
``lut.eevee.evaluate`` (EEVEE's measured closures) in place of
``Closure.evaluate`` (Cycles' formulas), rendered by EEVEE and measured
against the model like ``scripts/render_fidelity.py`` (the plane oracle of
tests/blender_oracle.py on its EEVEE grid, cos-weighted relative RMS).

    .venv/bin/python scripts/eevee_fit_gain.py [--paints satin matte]

Per paint it prints the error of the add-on's EEVEE fit (Cycles' formulas),
of the same fit made with the calibrated evaluator, and of that fit with a
retro Toon candidate added (in EEVEE a Lambert lobe about the view
direction), each with the fit's own predicted error.  The fit is
``lut.fitting.fit_lut``'s procedure, rebuilt here from its pieces with the
basis evaluated by a given function; nothing in the repository is patched."""

from __future__ import annotations

import argparse
import pathlib
import sys
import tempfile

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]

import bpy  # noqa: E402
from blender_oracle import EEVEE, GRID_EEVEE, Oracle, paints, relative_rms  # noqa: E402

from addon import nodes  # noqa: E402
from lut import closures, eevee, fitting, render  # noqa: E402
from lut.closures import Closure  # noqa: E402
from lut.paint import COMPONENTS  # noqa: E402


def fit_with(table, basis, evaluate, target="EEVEE", budget=None):
    """``fitting.fit_lut`` over the candidates ``basis``, every closure
    evaluated by ``evaluate(closure, θl, θv, φ)`` (its steps, in order)."""
    budget = fitting.BUDGET[target] if budget is None else budget
    type_dict = table.meta["type"]
    cos_view = fitting.view_cosines()
    theta_v = np.arccos(np.clip(cos_view, np.cos(fitting.MAX_VIEW), 1.0))
    theta_l, phi, row_w = fitting.light_rows(theta_v)
    tv = np.broadcast_to(theta_v[:, None], theta_l.shape)
    comps = table.components(theta_l, tv, phi) * (np.cos(theta_l) * row_w)[..., None, None]
    m_, r_, t_, c_ = comps.shape
    a = np.stack([evaluate(c, theta_l, tv, phi) for c in basis], axis=-1) * row_w[..., None]
    gram = np.einsum("mrk,mrl->mkl", a, a)
    b = comps.reshape(m_, r_, t_ * c_)
    rhs = np.einsum("mrk,mrp->mpk", a, b)
    norm = np.einsum("mrp,mrp->mp", b, b)
    view_weight = np.where(theta_v <= fitting.SELECTION_VIEW, 1.0, 0.1)
    norm = np.stack([norm, np.broadcast_to(view_weight[:, None], norm.shape)], axis=-1)
    grey = np.array([c.grey for c in basis])
    facet = COMPONENTS.index("facet")
    allowed = np.array([[not grey[k] or p % c_ == facet for k in range(len(basis))] for p in range(t_ * c_)])
    upper = np.array([c.max_weight for c in basis])
    cost = np.array([c.cost for c in basis])
    goal = 0.25 * fitting.TARGET_ERROR[target]["rough" if float(type_dict["slope"]) > 0 else "smooth"]
    chosen = fitting._select(gram, rhs, norm, allowed, upper, cost, budget, goal**2)
    weights = np.zeros((len(chosen), c_, m_, t_))
    for p in range(t_ * c_):
        idx = [i for i, k in enumerate(chosen) if allowed[p, k]]
        if not idx or norm[:, p, 0].sum() == 0:
            continue
        cols = [chosen[i] for i in idx]
        x, _ = fitting._nnls_fit(gram, rhs[:, p], norm[:, p], cols, upper[cols])
        weights[idx, p % c_, :, p // c_] = x.T
    if t_ > 1:
        g = [i for i, k in enumerate(chosen) if grey[k]]
        weights[g] = weights[g].mean(axis=-1, keepdims=True)
    keep = [i for i in range(len(chosen)) if weights[i].max() > 0]
    kept = [basis[chosen[i]] for i in keep]
    weights = weights[keep]
    residual, reference = _grams(table, kept, cos_view, weights, evaluate)
    n = type_dict["n"]
    n = float(n if not isinstance(n, list) else sum(c / 0.5893 ** (2 * k) for k, c in enumerate(n)))
    return fitting.Fit(
        target=target,
        exact_metallic=True,
        type=type_dict,
        closures=kept,
        cos_view=cos_view,
        weights=weights,
        residual=residual,
        reference=reference,
        mirror=float(type_dict["slope"]) == 0.0,
        n=n,
        internal_reflectance=table.internal_reflectance,
        lut_key=table.key,
    )


def _grams(table, basis, cos_view, weights, evaluate, grid=fitting.ACCEPTANCE_GRID):
    """``fitting._acceptance_grams`` with the closures evaluated by ``evaluate``, on ``grid``."""
    tl, tv, ph = (a.ravel() for a in np.meshgrid(*grid, indexing="ij"))
    cos_l = np.cos(tl)
    target = table.components(tl, tv, ph) * cos_l[:, None, None]
    values = np.stack([evaluate(c, tl, tv, ph) for c in basis], axis=0)
    k_, c_, _, t_ = weights.shape
    w = np.empty((k_, c_, tl.size, t_))
    for k in range(k_):
        for c in range(c_):
            for t in range(t_):
                w[k, c, :, t] = np.interp(np.cos(tv), cos_view, weights[k, c, :, t])
    r = (np.einsum("kn,kcnt->ntc", values, w) - target) * cos_l[:, None, None]
    ref = target * cos_l[:, None, None]
    return np.einsum("ntc,ntd->tcd", r, r), np.einsum("ntc,ntd->tcd", ref, ref)


def rendered_error(oracle, paint, fit, weights_path, label):
    """EEVEE's relative RMS for ``fit`` wired into a fresh material."""
    fitting.write_fit(fit, weights_path)
    material = oracle.material(label)
    group = nodes.build_group(fit, weights_path)
    nodes.wire(material, {"EEVEE": group}, render.node_inputs(paint, fit.internal_reflectance))
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
        baked = render.bake_for_render(paint, directory, targets=("EEVEE",))
        table, default = baked.lut, baked.fits["EEVEE"]
        amps = table.amplitudes(paint)
        basis = closures.candidates(table.meta["type"], "EEVEE")
        variants = {
            "Cycles formulas (add-on)": default,
            "calibrated": fit_with(table, basis, calibrated),
            "calibrated + retro Toon": fit_with(table, basis + [Closure("retro_toon", 0.3, 0.2)], calibrated),
        }
        for i, (label, fit) in enumerate(variants.items()):
            # The error each fit should have in EEVEE if its closures render as
            # measured, on the rendered grid.
            res, ref = _grams(table, fit.closures, fit.cos_view, fit.weights, calibrated, GRID_EEVEE)
            predicted = fitting.acceptance_error(res, ref, amps)
            got = rendered_error(oracle, paint, fit, directory / f"fit-{i}-{table.key[:8]}.exr", f"{name} {i}")
            kinds = ", ".join(f"{c.kind}" + (f" r{c.roughness:g}" if c.kind in ("glossy", "metallic") else "")
                              for c in fit.closures)  # fmt: skip
            print(
                f"{name:13s} {label:26s} EEVEE render {got:.4f}  predicted with lut.eevee {predicted:.4f}  [{kinds}]",
                flush=True,
            )


if __name__ == "__main__":
    main()
