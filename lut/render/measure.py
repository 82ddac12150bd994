"""The one fidelity measure of the render path: how far a rendered paint is
from the paper's model, as an artist sees it.

The relative RMS of rendered radiance L = f·cos θl per unit irradiance
normal to the light, over RGB and the geometries of ``GRID``:

    ε = sqrt( Σ_g Σ_ch |L_render − L_model|² / Σ_g Σ_ch |L_model|² )

with every geometry g of a grid uniform in θl ∈ [0°, 75°], θv ∈ [5°, 75°]
and φ ∈ [0°, 180°] counted once and nothing weighted further.  For a smooth
paint the geometries within ``MIRROR_EXCLUSION`` of the mirror direction are
left out (its mirror is a delta, rendered by a mirror closure of its own).
The grazing band ``GRAZING`` (θl ≥ 60°: terminators and rim lights) is
reported on its own too, with the same formula over its geometries.

The fit's rows (``lut.render.fitting``), its reported error (the panel,
``addon.api.fit_errors``, the batch report, the command line), the oracle
tests and the benchmarks all use this module.  docs/render.md states it."""

from __future__ import annotations

import numpy as np

#: The measure's grid: θl 0-75° and θv 5-75° in 5° steps, φ 0-180° in 10°
#: steps (φ = 0: the viewer on the far side from the light, the mirror
#: azimuth).
GRID = (
    np.radians(np.arange(0.0, 75.1, 5.0)),
    np.radians(np.arange(5.0, 75.1, 5.0)),
    np.radians(np.arange(0.0, 180.1, 10.0)),
)
#: The measure's grid with its lights shifted half a step (θl 2.5-72.5°):
#: geometries between the measure's, none of them at the mirror direction
#: (θl and θv no longer share their steps).  Not a measure of its own: a
#: check that a fit holds between the measure's points
#: (``lut.render.fitting.fit_lut``; the "CYCLES between" figures of
#: ``scripts/fit_fidelity.py``).
BETWEEN_GRID = (np.radians(np.arange(2.5, 75.0, 5.0)), GRID[1], GRID[2])
#: The measure's grid shifted half a step on all three axes (θl 2.5-72.5°,
#: θv 7.5-72.5°, φ 5-175°): geometries between the measure's in every
#: direction, as the pixels of a curved object fall.  A fit that draws a
#: cusp to its top at the measure's mirror points can hold with the lights
#: alone shifted (``BETWEEN_GRID``) and still miss here, or the other way
#: round: the fit checks both (``lut.render.fitting.fit_lut``).
SHIFTED_GRID = (BETWEEN_GRID[0], np.radians(np.arange(7.5, 75.0, 5.0)), np.radians(np.arange(5.0, 180.0, 10.0)))
#: The grids by name: the measure's own and its two checks.
GRIDS = {"measure": GRID, "between": BETWEEN_GRID, "shifted": SHIFTED_GRID}
#: Smooth paints: geometries this close to the mirror direction are left out.
MIRROR_EXCLUSION = np.radians(5.0)
#: The grazing band: lights at least this far from the normal.
GRAZING = np.radians(60.0)
#: The measure's goals, per engine, for smooth and rough paints: (whole
#: domain, grazing band).  EEVEE approximates every closure (it draws
#: microfacet lobes as GGX and diffuse ones as Lambert): its goals are its own,
#: for a render converged over its samples (a final render's 64), the grazing
#: band's twice the whole domain's.
GOALS = {
    "CYCLES": {"smooth": (0.02, 0.04), "rough": (0.05, 0.10)},
    "EEVEE": {"smooth": (0.05, 0.10), "rough": (0.10, 0.20)},
    # Cycles with Open Shading Language on (CPU, OptiX): the SVM fit plus
    # signed ramp closures (``lut.render.fitting.fit_osl``).
    "OSL": {"smooth": (0.01, 0.02), "rough": (0.03, 0.06)},
}


def mirror_distance(theta_l, theta_v, phi):
    """Angle between the view and the mirror direction of the light (light
    at azimuth π, φ = 0 the mirror's azimuth)."""
    cos = np.cos(theta_l) * np.cos(theta_v) + np.sin(theta_l) * np.sin(theta_v) * np.cos(phi)
    return np.arccos(np.clip(cos, -1.0, 1.0))


def grid_points(grid=GRID, mirror_exclusion=0.0):
    """The (θl, θv, φ) points of a grid's axes, flat, less those within
    ``mirror_exclusion`` of the mirror direction."""
    tl, tv, ph = (a.ravel() for a in np.meshgrid(*grid, indexing="ij"))
    keep = mirror_distance(tl, tv, ph) >= mirror_exclusion
    return tl[keep], tv[keep], ph[keep]


def points(smooth: bool, grid=GRID):
    """The measure's geometries (θl, θv, φ) for a smooth or a rough paint."""
    return grid_points(grid, MIRROR_EXCLUSION if smooth else 0.0)


def grazing(theta_l) -> np.ndarray:
    """Which geometries are in the grazing band."""
    return np.asarray(theta_l) >= GRAZING - 1e-9


def relative_rms(rendered, model) -> float:
    """ε of rendered against model radiance (any shape, RGB last): the
    module's formula over every element given."""
    rendered, model = np.asarray(rendered, dtype=float), np.asarray(model, dtype=float)
    den = float(np.sum(model**2))
    return float(np.sqrt(np.sum((rendered - model) ** 2) / den)) if den > 0 else 0.0


def errors(rendered, model, theta_l) -> tuple[float, float]:
    """(whole, grazing band) ε of radiance ``rendered`` against ``model``
    ((N, 3) at geometries of polar light angles ``theta_l`` (N,))."""
    band = grazing(theta_l)
    rendered, model = np.asarray(rendered, dtype=float), np.asarray(model, dtype=float)
    return relative_rms(rendered, model), relative_rms(rendered[band], model[band])


def goals(engine: str, smooth: bool) -> tuple[float, float]:
    """(whole, grazing band) goals of an engine for a smooth or rough paint."""
    return GOALS[engine]["smooth" if smooth else "rough"]
