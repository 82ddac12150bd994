"""How close EEVEE's lobes can come to a paint's facet term at all: per view,
the best Lambert + two-lobe combination EEVEE sums exactly, with each
view's own pair of roughnesses (which no node group offers: the fit's pair
is one for all views), from EEVEE's measured responses (``lut.render.eevee``).

    .venv/bin/python scripts/eevee_lobe_limit.py [--paints 2 13 17 21 23] [--version 5.0]

For each paint of ``lut.bench.random_paints`` named by its index, it bakes
the type's LUT and prints the facet component's relative RMS on the fit's
rows (``lut.render.fitting.light_rows``, the measure the fit minimises) for the
views of the fidelity measure's range (θv <= 75°): the add-on's fit, and the
per-view best pair out of 15 Glossy roughnesses.  Numpy only."""

from __future__ import annotations

import argparse
import functools
import itertools
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
from lut.render.closures import Closure  # noqa: E402
from lut.render.nnls import nnls_gram  # noqa: E402

ROUGHNESS = (0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0)


def facet_rows(table, basis, evaluate):
    """Per view: the Gram matrix, right-hand side and target norm of the
    facet component on the fit's rows; and the views' polar angles."""
    cos_view = fitting.view_cosines()
    theta_v = np.arccos(np.clip(cos_view, np.cos(fitting.MAX_VIEW), 1.0))
    theta_l, phi, row_w = fitting.light_rows(theta_v)
    tv = np.broadcast_to(theta_v[:, None], theta_l.shape)
    target = table.components(theta_l, tv, phi)[:, :, 0, 0] * np.cos(theta_l) * row_w
    a = np.stack([evaluate(c, theta_l, tv, phi) for c in basis], axis=-1) * row_w[..., None]
    return (
        np.einsum("mrk,mrl->mkl", a, a),
        np.einsum("mrk,mr->mk", a, target),
        np.einsum("mr,mr->m", target, target),
        theta_v,
    )


def _relative_error(gram, rhs, norm, idx):
    """Relative squared error of one view's non-negative fit on ``idx``."""
    g, b = gram[np.ix_(idx, idx)], rhs[idx]
    x = nnls_gram(g, b)
    return max((norm - 2 * x @ b + x @ g @ x) / norm, 0.0)


def per_view_best(gram, rhs, norm, lobes):
    """Per view, the smallest relative squared error of Lambert (index 0)
    and any two of the ``lobes`` (indices), non-negative weights."""
    best = np.ones(len(norm))
    for m in np.nonzero(norm > 0)[0]:
        best[m] = min(_relative_error(gram[m], rhs[m], norm[m], [0, j, k]) for j, k in itertools.combinations(lobes, 2))
    return best


def fitted(gram, rhs, norm, idx):
    """Per view relative squared error of the non-negative fit on ``idx``."""
    out = np.ones(len(norm))
    for m in np.nonzero(norm > 0)[0]:
        out[m] = _relative_error(gram[m], rhs[m], norm[m], idx)
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--paints", type=int, nargs="+", default=[2, 13, 17, 21, 23])
    parser.add_argument("--version", default="5.0", help="the Blender line's EEVEE tables")
    args = parser.parse_args(argv)
    version = tuple(int(v) for v in args.version.split("."))
    evaluate = functools.partial(eevee.evaluate, version=version)
    paints = bench.random_paints()
    with tempfile.TemporaryDirectory() as tmp:
        for i in args.paints:
            label, paint = paints[i]
            table = baking.load_lut(baking.bake(paint, pathlib.Path(tmp)))
            fit = fitting.fit_lut(table, "EEVEE", calibration=version, eevee_mode="EXACT")
            basis = [Closure("lambert")] + [Closure("glossy", roughness=r) for r in ROUGHNESS]
            chosen = [c for c in fit.closures if c.kind != "lambert"]
            basis += chosen
            gram, rhs, norm, theta_v = facet_rows(table, basis, evaluate)
            inside = (theta_v <= np.radians(75.0)) & (norm > 0)
            best = per_view_best(gram, rhs, norm, list(range(1, len(ROUGHNESS) + 1)))
            own = fitted(gram, rhs, norm, [0] + list(range(len(ROUGHNESS) + 1, len(basis))))
            lobes = ", ".join(f"{c.kind} {c.roughness:.2f}" for c in chosen)
            print(
                f"{label:28s} facet on the fit's rows: the fit ({lobes}) {np.sqrt(own[inside].mean()):.1%}; "
                f"best pair per view {np.sqrt(best[inside].mean()):.1%} "
                f"(views {np.sqrt(best[inside].min()):.1%}-{np.sqrt(best[inside].max()):.1%})"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
