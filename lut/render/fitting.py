"""The fit of a paint type's LUT onto Blender closures, per view angle.

A paint's non-delta BRDF is Σ_c a_c·B_c (``lut.lutfiles.baking``): colour-free
angular components B_c scaled by colour amplitudes a_c.  Each component is
fitted on its own as Σ_k w_kc(θv)·b_k(l, v) over closures b_k
(``lut.render.closures``), so a node group renders any colour of the type by giving
closure k the colour Σ_c a_c·w_kc(θv): the colour is a node input, never a
bake.

The fit, per render target (``fit_lut``):

1. Rows.  For each of M view cosines, light directions on a grid of half
   vectors around the normal (θh = π/2·u², dense near the mirror, where
   facet lobes are sharp), reflected about the view; each row weighted by
   its solid angle (dω_l = 4 (h·v) dω_h) and by cos θl, as the acceptance
   measure weights radiance.  Targets come from the LUT, never the model.
2. Selection.  Forward selection: from the target's candidate closures,
   repeatedly add the one that most reduces the sum over components of the
   squared relative error (ranked by least squares over all views at once,
   the best few checked by non-negative least squares, all of them when
   none of those helps: near-collinear Toon ramps mislead the
   unconstrained ranking), until the render
   cost budget (closures per material) is spent or the error is far below
   target.  Where a component's error on the acceptance grid (step 4) is
   then still above the target (some colour of the type would miss it),
   the selection is made again with a few closures more (``EXTRA_BUDGET``)
   and kept if it lowers that error.  Grey closures (no colour input)
   serve the facet component only and keep weights <= 1 (a Mix Shader
   factor clamps there).
3. Weights.  Non-negative least squares per view and component over the
   chosen closures (``lut.render.nnls``).
4. Error.  On the acceptance grid (θl, θv <= 75°, azimuths off the mirror)
   and on a dense grid of the same range (``DENSE_GRID``): the closures
   with their weights interpolated linearly in cos θv, against the LUT.
   Stored as Gram matrices of the residuals and targets per component, so
   the cos-weighted relative RMS of any colour, the larger of the two
   grids', is ``Fit.error(amplitudes)``: the panel shows it live.

The weights file (``write_fit``) is a Non-Color float EXR with one row per
(closure, component) pair in use and ``TEXTURE_VIEWS`` columns (the fitted
views' weights, linear between them, read by the nearest column), plus a
header with everything a node group is built from, so a fit read back
renders identically."""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import pathlib

import numpy as np

from ..lutfiles import format as lutfile
from ..paint.core import COMPONENTS, reference_index
from . import closures
from .closures import Closure
from .nnls import nnls_gram_batch

#: Fit format version: bumped when the weights file layout or the fit changes.
#: It is part of the weights file's name (``fit_path``), so a new release
#: never overwrites a file that an older release's node groups still read.
FIT_VERSION = 6

#: The acceptance measure's geometries: θl, θv <= 75° and azimuths away from
#: the exact mirror direction (φ = 0); the Cycles oracle tests use the same.
ACCEPTANCE_GRID = (
    np.radians([0.0, 15.0, 30.0, 45.0, 60.0, 75.0]),
    np.radians([5.0, 20.0, 35.0, 50.0, 65.0, 75.0]),
    np.array([0.4, 1.1, 1.9, 2.6, 3.1]),
)

#: The dense measure the fit's reported error also covers: θl 0-75° and
#: θv 5-75° in 5° steps, azimuths 20-180° in 10° steps, less the points
#: within 5° of the mirror direction (the acceptance grid's own distance
#: from it).  Between the acceptance grid's points a lobe a few degrees wide
#: can be far off unseen: EEVEE's sharp GGX lobes, fitted to 9-11% there,
#: are 19-21% off here.
DENSE_GRID = (
    np.radians(np.arange(0.0, 75.1, 5.0)),
    np.radians(np.arange(5.0, 75.1, 5.0)),
    np.radians(np.arange(20.0, 180.1, 10.0)),
)
MIRROR_EXCLUSION = np.radians(5.0)

#: Targets of the acceptance error (cos-weighted relative RMS): smooth and
#: rough types, per render target.  EEVEE's are its own (it approximates
#: every closure).
TARGET_ERROR = {"CYCLES": {"smooth": 0.02, "rough": 0.05}, "EEVEE": {"smooth": 0.03, "rough": 0.08}}

#: Closures per material (render cost grows with their number; the mirror
#: of a smooth type comes on top).  EEVEE evaluates few closures per pixel.
BUDGET = {"CYCLES": 8, "EEVEE": 3}
#: Closures a fit may add beyond ``BUDGET`` where a component's acceptance
#: error is above the target within it: only the types that need them (very
#: rough facets, strongly back-scattering pigments) pay the render cost.
EXTRA_BUDGET = {"CYCLES": 4, "EEVEE": 0}

#: Views the weights are fitted at, and the light grid of each view.
VIEWS = 24
#: Columns of the weights texture: the fitted weights, linear in cos θv
#: between the views, sampled this densely (every fitted view is a column)
#: so the node group can read them with Closest interpolation.  EEVEE
#: samples an image of Linear interpolation through mipmaps, which average
#: neighbouring rows (other closures' weights) wherever the lookup's
#: coordinate changes quickly across pixels: measured on a smooth paint,
#: 10.1% off the model with Linear, 4.2% with Closest on the fitted views.
#: Nearest-column lookup on this grid is within 1/(2·(TEXTURE_VIEWS - 1))
#: in cos θv of the linear interpolation.
VIEW_SUBDIVISION = 8
TEXTURE_VIEWS = VIEW_SUBDIVISION * (VIEWS - 1) + 1
LIGHT_GRID = (24, 24)
#: sin θl below which a row's measure dθl dφ = dω/sin θl is not raised further.
MIN_SIN = np.sin(np.radians(5.0))
#: Lights beyond this polar angle are not fitted (their cos θl weight is nil).
MAX_LIGHT = np.radians(88.0)
#: Views are evaluated at most this far from the normal (θv = 90° exactly is
#: a degenerate direction).
MAX_VIEW = np.radians(89.5)

#: Views up to this polar angle drive the selection fully (the acceptance
#: measure's range and a margin); views beyond count a tenth.
SELECTION_VIEW = np.radians(80.0)

_CANDIDATES_CHECKED = 4


@dataclasses.dataclass
class Fit:
    """A paint type's closure fit for one render target.

    closures   the chosen closures (K)
    weights    (K, C, M, T): w_kc at view cosines ``cos_view`` (M), per tile
               T (1, or 3 for a dispersive type: one per RGB channel)
    residual   (T, C, C) and ``reference`` (T, C, C): Gram matrices of the
               fit's residual and of the LUT's components on the acceptance
               grid (cos-weighted), giving ``error`` for any colour
    dense_residual, dense_reference: the same on ``DENSE_GRID`` (None for
               a fit made without them)
    mirror     whether the type has a smooth interface's mirror (a delta,
               rendered by a mirror closure of weight ``Surface Reflection``)
    """

    target: str
    exact_metallic: bool
    type: dict
    closures: list
    cos_view: np.ndarray
    weights: np.ndarray
    residual: np.ndarray
    reference: np.ndarray
    mirror: bool
    n: float
    internal_reflectance: float
    lut_key: str = ""
    calibration: tuple | None = None
    dense_residual: np.ndarray | None = None
    dense_reference: np.ndarray | None = None

    @property
    def rough(self) -> bool:
        return float(self.type["slope"]) > 0

    @property
    def target_error(self) -> float:
        return TARGET_ERROR[self.target]["rough" if self.rough else "smooth"]

    @property
    def rows(self) -> list:
        """(closure index, component index) pairs that carry weight: the
        rows of the weights texture, bottom to top."""
        used = self.weights.max(axis=(2, 3)) > 0
        return [(k, c) for k in range(len(self.closures)) for c in range(len(COMPONENTS)) if used[k, c]]

    def component_errors(self) -> dict:
        """The relative error of each component alone (None where it is nil)."""
        return component_errors(self.residual, self.reference)

    def error(self, amplitudes) -> float:
        """Cos-weighted relative RMS of a paint with these amplitudes ((3
        channels, 3 components): ``Paint.amplitudes``): the larger of its
        values on the acceptance grid and on ``DENSE_GRID``, so neither a
        grid point nor a lobe between the grid's points is seen better
        than it renders."""
        return reported_error(self.grams(), amplitudes)

    def grams(self) -> dict:
        """The Gram matrices the reported error comes from, as lists (what a
        material stores to show its error for any colour): residual,
        reference, dense_residual and dense_reference (None without them)."""
        dense = self.dense_residual is not None
        return {
            "residual": self.residual.tolist(),
            "reference": self.reference.tolist(),
            "dense_residual": self.dense_residual.tolist() if dense else None,
            "dense_reference": self.dense_reference.tolist() if dense else None,
        }

    def header(self) -> dict:
        return {
            "fit_version": FIT_VERSION,
            "target": self.target,
            "exact_metallic": self.exact_metallic,
            "type": self.type,
            "closures": [c.to_dict() for c in self.closures],
            "rows": self.rows,
            "views": len(self.cos_view),
            "tiles": self.weights.shape[3],
            "mirror": self.mirror,
            "n": self.n,
            "internal_reflectance": self.internal_reflectance,
            **self.grams(),
            "lut_key": self.lut_key,
            "calibration": list(self.calibration) if self.calibration else None,
        }


def component_errors(residual, reference) -> dict:
    """{component: relative error of that component alone} from acceptance
    Gram matrices (T, C, C), summed over tiles; None where it is nil."""
    out = {}
    for c, name in enumerate(COMPONENTS):
        ref = reference[:, c, c].sum()
        out[name] = float(np.sqrt(residual[:, c, c].sum() / ref)) if ref > 0 else None
    return out


def reported_error(grams: dict, amplitudes) -> float:
    """The error a fit reports for a colour (``Fit.error``) from its Gram
    matrices (``Fit.grams``): the larger of the acceptance grid's and the
    dense grid's (where the grams have it)."""
    grid = acceptance_error(grams["residual"], grams["reference"], amplitudes)
    if grams.get("dense_residual") is None:
        return grid
    return max(grid, acceptance_error(grams["dense_residual"], grams["dense_reference"], amplitudes))


def acceptance_error(residual, reference, amplitudes) -> float:
    """sqrt(Σ_ch aᵀRa / Σ_ch aᵀTa): the relative RMS of a colour (amplitudes
    a, (3 channels, C)) from the Gram matrices R of the residuals and T of
    the targets ((tiles, C, C): one tile for every channel, or one each)."""
    a = np.asarray(amplitudes, dtype=float)
    residual, reference = np.asarray(residual, dtype=float), np.asarray(reference, dtype=float)
    num = den = 0.0
    for ch in range(3):
        t = ch if residual.shape[0] == 3 else 0
        num += a[ch] @ residual[t] @ a[ch]
        den += a[ch] @ reference[t] @ a[ch]
    return float(np.sqrt(max(num, 0.0) / den)) if den > 0 else 0.0


# ---------------------------------------------------------------------- rows


def view_cosines(views=VIEWS):
    """The weights texture's columns: cos θv = j/(M - 1)."""
    return np.linspace(0.0, 1.0, views)


def texture_views(views=VIEWS) -> int:
    """Columns of the weights texture for weights fitted at ``views`` views
    (``TEXTURE_VIEWS`` for the default): ``VIEW_SUBDIVISION`` per interval."""
    return VIEW_SUBDIVISION * (int(views) - 1) + 1


def texture_u(views):
    """(scale, offset) of the weights texture's lookup u = scale·cos θv +
    offset: column j, centred at u = (j + 0.5)/M, holds cos θv = j/(M - 1),
    so the texel under u (Closest interpolation) is the column nearest to
    cos θv."""
    return (views - 1) / views, 0.5 / views


def resample_views(weights, cos_view, dense):
    """Weights (K, C, M, T) at view cosines ``cos_view``, linearly
    interpolated at the view cosines ``dense`` (K, C, len(dense), T): the
    texture's columns, or the views of points where the fit is measured."""
    k_, c_, _, t_ = weights.shape
    out = np.empty((k_, c_, len(dense), t_))
    for k in range(k_):
        for c in range(c_):
            for t in range(t_):
                out[k, c, :, t] = np.interp(dense, cos_view, weights[k, c, :, t])
    return out


def light_rows(theta_v, grid=LIGHT_GRID, max_light=MAX_LIGHT):
    """Light directions for each view: (θl, φ, row weight), shape
    (M, R).  Half vectors h at θh = π/2·u² (u at interval midpoints) and
    azimuths in [0, π] (the half with y < 0 mirrors it), reflected about
    the view v: l = 2(h·v)h - v, dω_l = 4(h·v) dω_h.  The weight is the
    square root of dω_l times cos θl (the acceptance measure's weight on
    radiance); rows below ``max_light`` have weight 0."""
    n_u, n_phi = grid
    u = (np.arange(n_u) + 0.5) / n_u
    theta_h = 0.5 * np.pi * u * u
    d_theta = np.pi * u / n_u
    phi_h = (np.arange(n_phi) + 0.5) / n_phi * np.pi
    th, ph = np.meshgrid(theta_h, phi_h, indexing="ij")
    dth = np.broadcast_to(d_theta[:, None], th.shape)
    th, ph, dth = th.ravel(), ph.ravel(), dth.ravel()
    hx, hy, hz = np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)
    tv = np.asarray(theta_v, dtype=float)[:, None]
    vx, vz = np.sin(tv), np.cos(tv)
    hv = hx * vx + hz * vz
    lx, ly, lz = 2 * hv * hx - vx, 2 * hv * hy, 2 * hv * hz - vz
    d_omega = 2.0 * 4.0 * np.abs(hv) * np.sin(th) * dth * (np.pi / n_phi)  # x2: both halves in azimuth
    ok = (hv > 0) & (lz > np.cos(max_light))
    theta_l = np.arccos(np.clip(np.where(ok, lz, 1.0), -1.0, 1.0))
    # The model puts the light at azimuth π: rotate the viewer (azimuth 0) with it.
    phi = np.pi - np.arctan2(np.where(ok, ly, 0.0), np.where(ok, lx, -1.0))
    phi = np.mod(phi + np.pi, 2 * np.pi) - np.pi
    # The acceptance measure samples θl and φ uniformly, not solid angle:
    # dθl dφ = dω / sin θl (bounded near the normal, where rows are few).
    d_measure = d_omega / np.maximum(np.sin(theta_l), MIN_SIN)
    weight = np.where(ok, np.sqrt(d_measure) * np.cos(theta_l), 0.0)
    return theta_l, phi, weight


# ---------------------------------------------------------------------- selection


def _ls_errors(gram, rhs, norm, base, cands):
    """Relative squared error (``_relative``) of the unconstrained least
    squares fit on ``base`` + [k] for each k in ``cands``: (len(cands),).
    gram (M, K, K), rhs (M, K), norm (M, 2): each view's squared target
    norm and its weight in the selection."""
    idx = np.array([list(base) + [k] for k in cands])  # (Kc, s)
    sub = gram[:, idx[:, :, None], idx[:, None, :]]  # (M, Kc, s, s)
    g = rhs[:, idx]  # (M, Kc, s)
    scale = np.maximum(np.abs(np.diagonal(sub, axis1=-2, axis2=-1)).max(axis=-1), 1e-300)
    sub = sub + 1e-10 * scale[..., None, None] * np.eye(idx.shape[1])
    x = np.linalg.solve(sub, g[..., None])[..., 0]
    err = norm[:, 0, None] - np.sum(x * g, axis=-1)
    return _relative(np.maximum(err, 0.0), norm)


def _relative(err, norm):
    """The views' relative squared errors err/‖b‖², averaged with the views'
    weights: every view counts by its relative error, as the acceptance
    measure's views do, not by its radiance (which grows without bound
    toward grazing views for rough facet terms)."""
    rel = np.where(norm[:, 0] > 0, 1.0, 0.0) * norm[:, 1] / np.maximum(norm[:, 0], 1e-300)
    return np.tensordot(rel, err, axes=(0, 0)) / max(float(np.sum(norm[:, 1] * (norm[:, 0] > 0))), 1e-300)


def _nnls_fit(gram, rhs, norm, idx, upper):
    """Per-view NNLS weights on closures ``idx``: (x (M, s), relative squared error)."""
    idx = list(idx)
    sub = gram[:, idx][:, :, idx]  # (M, s, s)
    g = rhs[:, idx]
    scale = np.maximum(np.abs(np.diagonal(sub, axis1=-2, axis2=-1)).max(axis=-1), 1e-300)
    # Unconstrained solutions first (all views at once); NNLS only where a
    # weight leaves its bounds.
    x = np.linalg.solve(sub + 1e-13 * scale[:, None, None] * np.eye(len(idx)), g[..., None])[..., 0]
    bad = (np.any(x < 0, axis=1) | np.any(x > upper, axis=1)) & (norm[:, 0] > 0)
    if bad.any():
        x[bad] = nnls_gram_batch(sub[bad], g[bad], upper=upper)
    x[norm[:, 0] == 0] = 0.0
    err = norm[:, 0] - 2 * np.sum(x * g, axis=1) + np.einsum("ms,mst,mt->m", x, sub, x)
    return x, float(_relative(np.maximum(err, 0.0), norm))


def _select(gram, rhs, norm, allowed, upper, cost, budget, goal, caps=None):
    """Forward selection of closures for every (tile, component) target.
    gram (M, K, K); rhs (M, P, K), norm (M, P, 2) over P targets; allowed
    (P, K); upper (K,); caps: (mask over K, most closures of the mask);
    goal: the relative squared error below which selection stops.  Returns
    the chosen closure indices in order."""
    targets = [p for p in range(rhs.shape[1]) if norm[:, p, 0].sum() > 0]
    chosen: list[int] = []
    errors = {p: 1.0 for p in targets}
    spent = 0
    while targets:
        if max(errors.values()) < goal:
            break
        if spent >= budget:
            break
        capped = caps is not None and sum(caps[0][k] for k in chosen) >= caps[1]
        cands = [
            k
            for k in range(gram.shape[1])
            if k not in chosen
            and allowed[targets, k].any()
            and spent + cost[k] <= budget
            and not (capped and caps[0][k])
        ]
        if not cands:
            break
        proxy = np.zeros(len(cands))
        for p in targets:
            base = [k for k in chosen if allowed[p, k]]
            ok = [i for i, k in enumerate(cands) if allowed[p, k]]
            proxy += errors[p]
            if ok:
                new = _ls_errors(gram, rhs[:, p], norm[:, p], base, [cands[i] for i in ok])
                proxy[ok] += np.minimum(new, errors[p]) - errors[p]
        current = sum(errors.values())
        best, best_gain, best_errors = None, 0.0, None
        order = np.argsort((proxy - current) / cost[cands])
        for rank, i in enumerate(order):
            if rank >= _CANDIDATES_CHECKED and best is not None:
                break  # the proxy's best few were checked and one helps
            k = cands[i]
            trial = dict(errors)
            for p in targets:
                if allowed[p, k]:
                    idx = [j for j in chosen + [k] if allowed[p, j]]
                    trial[p] = _nnls_fit(gram, rhs[:, p], norm[:, p], idx, upper[idx])[1]
            gain = (current - sum(trial.values())) / cost[k]  # error reduction per unit of render cost
            if gain > max(best_gain, 1e-9):
                best, best_gain, best_errors = k, gain, trial
        if best is None:
            break
        chosen.append(best)
        spent += cost[best]
        errors = best_errors
    return chosen


# ---------------------------------------------------------------------- fit


def mirror_distance(theta_l, theta_v, phi):
    """Angle between the view and the mirror direction of the light (light
    at azimuth π, φ = 0 the mirror's azimuth)."""
    cos = np.cos(theta_l) * np.cos(theta_v) + np.sin(theta_l) * np.sin(theta_v) * np.cos(phi)
    return np.arccos(np.clip(cos, -1.0, 1.0))


def grid_points(grid=ACCEPTANCE_GRID, mirror_exclusion=0.0):
    """The (θl, θv, φ) points of a grid's axes, flat, less those within
    ``mirror_exclusion`` of the mirror direction."""
    tl, tv, ph = (a.ravel() for a in np.meshgrid(*grid, indexing="ij"))
    keep = mirror_distance(tl, tv, ph) >= mirror_exclusion
    return tl[keep], tv[keep], ph[keep]


def dense_points():
    """``grid_points`` of ``DENSE_GRID`` without ``MIRROR_EXCLUSION``."""
    return grid_points(DENSE_GRID, MIRROR_EXCLUSION)


def _acceptance_grams(lut, basis, cos_view, weights, evaluate, grid=ACCEPTANCE_GRID, points=None):
    """(residual, reference) Gram matrices (T, C, C) on ``grid`` (default
    ``ACCEPTANCE_GRID``) or at ``points`` (θl, θv, φ)."""
    tl, tv, ph = grid_points(grid) if points is None else points
    cos_l = np.cos(tl)
    target = lut.components(tl, tv, ph) * cos_l[:, None, None]  # (N, T, C)
    values = np.array([evaluate(c, tl, tv, ph) for c in basis]).reshape(len(basis), tl.size)  # (K, N); K may be 0
    fitted = np.einsum("kn,kcnt->ntc", values, resample_views(weights, cos_view, np.cos(tv)))
    r = (fitted - target) * cos_l[:, None, None]
    ref = target * cos_l[:, None, None]
    return np.einsum("ntc,ntd->tcd", r, r), np.einsum("ntc,ntd->tcd", ref, ref)


def _cycles(closure, theta_l, theta_v, phi):
    return closure.evaluate(theta_l, theta_v, phi)


def evaluator_for(target, calibration=None):
    """How the target renders each closure: Cycles' formulas
    (``Closure.evaluate``), or for EEVEE with a ``calibration`` (a Blender
    line with measured tables, ``lut.render.eevee``) EEVEE's own responses."""
    if target == "EEVEE" and calibration is not None:
        from . import eevee

        return functools.partial(eevee.evaluate, version=tuple(calibration))
    return _cycles


def fit_lut(
    lut,
    target="CYCLES",
    *,
    exact_metallic=True,
    budget=None,
    extra_budget=None,
    views=VIEWS,
    grid=LIGHT_GRID,
    calibration=None,
) -> Fit:
    """Fit a loaded LUT (``lut.lutfiles.baking.LUT``) onto the closures of a render
    target (module docstring).  ``budget``, ``extra_budget``: closures per
    material, and how many more while a component misses the target
    (defaults ``BUDGET``, ``EXTRA_BUDGET``).  ``calibration``: for EEVEE, the
    Blender line whose measured closure responses to fit with (``lut.render.eevee``;
    None: Cycles' formulas, EEVEE's own rendering unmodelled)."""
    target = closures.validate_target(target)
    evaluate = evaluator_for(target, calibration)
    budget = BUDGET[target] if budget is None else int(budget)
    if budget < 1:
        raise ValueError(f"budget must be a whole number >= 1, got {budget!r}")
    extra_budget = EXTRA_BUDGET[target] if extra_budget is None else int(extra_budget)
    if extra_budget < 0:
        raise ValueError(f"extra_budget must be a whole number >= 0, got {extra_budget!r}")
    meta = lut.meta
    type_dict = meta["type"]
    # A calibrated EEVEE (Blender 5) draws the Metallic BSDF as measured,
    # whatever Cycles makes of it: its lobes are Metallic ones.
    metallic = exact_metallic or (target == "EEVEE" and calibration is not None)
    basis = closures.candidates(type_dict, target, metallic)
    cos_view = view_cosines(views)
    theta_v = np.arccos(np.clip(cos_view, np.cos(MAX_VIEW), 1.0))
    theta_l, phi, row_w = light_rows(theta_v, grid)
    tv = np.broadcast_to(theta_v[:, None], theta_l.shape)
    comps = lut.components(theta_l, tv, phi) * (np.cos(theta_l) * row_w)[..., None, None]  # (M, R, T, C)
    m_, r_, t_, c_ = comps.shape
    a = np.stack([evaluate(c, theta_l, tv, phi) for c in basis], axis=-1) * row_w[..., None]  # (M, R, K)
    gram = np.einsum("mrk,mrl->mkl", a, a)
    b = comps.reshape(m_, r_, t_ * c_)
    rhs = np.einsum("mrk,mrp->mpk", a, b)
    norm = np.einsum("mrp,mrp->mp", b, b)
    # Views beyond the acceptance measure's range still get their weights but
    # count less in the selection.
    view_weight = np.where(theta_v <= SELECTION_VIEW, 1.0, 0.1)
    norm = np.stack([norm, np.broadcast_to(view_weight[:, None], norm.shape)], axis=-1)
    grey = np.array([c.grey for c in basis])
    facet = COMPONENTS.index("facet")
    allowed = np.array([[not grey[k] or p % c_ == facet for k in range(len(basis))] for p in range(t_ * c_)])
    upper = np.array([c.max_weight for c in basis])
    cost = np.array([c.cost for c in basis])
    mirror = float(type_dict["slope"]) == 0.0  # a smooth interface: its mirror is a closure of its own
    target_error = TARGET_ERROR[target]["smooth" if mirror else "rough"]
    goal = 0.25 * target_error
    caps = None
    if target == "EEVEE":
        from . import eevee

        # EEVEE sums one diffuse normal and two reflection closures exactly
        # per pixel; beyond that it picks closures at random (noise).  A
        # smooth type's mirror is one of the two.
        caps = (np.array([eevee.is_reflection(c) for c in basis]), eevee.EXACT_REFLECTION_CLOSURES - mirror)

    def weights_of(chosen):
        """NNLS weights of the chosen closures, the kept closures and their
        acceptance Gram matrices."""
        weights = np.zeros((len(chosen), c_, m_, t_))
        for p in range(t_ * c_):
            idx = [i for i, k in enumerate(chosen) if allowed[p, k]]
            if not idx or norm[:, p, 0].sum() == 0:
                continue
            cols = [chosen[i] for i in idx]
            x, _ = _nnls_fit(gram, rhs[:, p], norm[:, p], cols, upper[cols])
            weights[idx, p % c_, :, p // c_] = x.T
        if t_ > 1:  # a grey closure has one weight for every channel: the tiles' mean
            g = [i for i, k in enumerate(chosen) if grey[k]]
            weights[g] = weights[g].mean(axis=-1, keepdims=True)
        keep = [i for i in range(len(chosen)) if weights[i].max() > 0]
        kept = [basis[chosen[i]] for i in keep]
        return (kept, weights[keep], *_acceptance_grams(lut, kept, cos_view, weights[keep], evaluate))

    def worst_component(grams):
        """The largest relative error of one component (the error of the
        type's worst colour, where that component dominates)."""
        return max((e for e in component_errors(*grams).values() if e is not None), default=0.0)

    chosen = _select(gram, rhs, norm, allowed, upper, cost, budget, goal**2, caps)
    basis_kept, weights, residual, reference = weights_of(chosen)
    if extra_budget > 0 and worst_component((residual, reference)) > target_error:
        # Some colour of this type misses the target: select again with the
        # extra closures, and keep that choice if it lowers the worst
        # component's error.
        more = weights_of(_select(gram, rhs, norm, allowed, upper, cost, budget + extra_budget, goal**2, caps))
        if worst_component(more[2:]) < worst_component((residual, reference)):
            basis_kept, weights, residual, reference = more
    dense_grams = _acceptance_grams(lut, basis_kept, cos_view, weights, evaluate, points=dense_points())
    n = reference_index(type_dict["n"])
    dense = view_cosines(texture_views(views))
    return Fit(
        target=target,
        exact_metallic=bool(exact_metallic),
        type=type_dict,
        closures=basis_kept,
        cos_view=dense,
        weights=resample_views(weights, cos_view, dense),
        residual=residual,
        reference=reference,
        mirror=mirror,
        n=n,
        internal_reflectance=lut.internal_reflectance,
        lut_key=lut.key,
        calibration=tuple(calibration) if (calibration is not None and target == "EEVEE") else None,
        dense_residual=dense_grams[0],
        dense_reference=dense_grams[1],
    )


# ---------------------------------------------------------------------- files


def fit_path(lut_path, target="CYCLES", exact_metallic=True, calibration=None) -> pathlib.Path:
    """The weights file of a target beside its LUT:
    ``paintfit-cycles-f<FIT_VERSION>-<key>.exr`` (``paintfit-cycles4-…`` for
    Blender 4.2-4.5's lobes), ``paintfit-eevee-…`` (``paintfit-eevee50-…``
    when fitted with Blender 5.0's measured EEVEE responses)."""
    lut_path = pathlib.Path(lut_path)
    name = closures.validate_target(target).lower() + ("" if exact_metallic else "4")
    if target == "EEVEE" and calibration is not None:
        name += "".join(str(int(v)) for v in calibration[:2])
    return lut_path.with_name(lut_path.name.replace("paintlut-", f"paintfit-{name}-f{FIT_VERSION}-"))


def _image(fitted: Fit) -> np.ndarray:
    rows = fitted.rows
    image = np.zeros((max(len(rows), 1), len(fitted.cos_view), 3), dtype=np.float32)
    for r, (k, c) in enumerate(rows):
        image[r] = np.broadcast_to(fitted.weights[k, c], (len(fitted.cos_view), 3))
    return image[::-1]  # EXR rows run top to bottom


def _hash(header_json: str, image: np.ndarray) -> str:
    h = hashlib.sha256(header_json.encode())
    h.update(np.ascontiguousarray(image, dtype="<f4").tobytes())
    return h.hexdigest()


def write_fit(fitted: Fit, path) -> pathlib.Path:
    """Write a fit's weights texture and header atomically: row r (counted
    from the bottom, where a Blender image has v = 0) holds the weights of
    ``rows[r]`` at the view cosines; the header (JSON) and a content hash
    let ``read_fit`` rebuild and verify it."""
    image = _image(fitted)
    header_json = lutfile.canonical_json(fitted.header())
    return lutfile.write_exr(path, image, {"paintfit:header": header_json, "paintfit:hash": _hash(header_json, image)})


def read_fit(path) -> Fit:
    """A fit written by ``write_fit``, verified against its hash; raises
    lut.LUTError for a missing, damaged or foreign file."""
    pixels, attrs = lutfile._read_image(path, ("paintfit:header", "paintfit:hash"), "weights file")
    header_json, digest = attrs["paintfit:header"], attrs["paintfit:hash"]
    if not isinstance(header_json, str) or digest != _hash(header_json, pixels):
        raise lutfile.LUTError(f"{path}: not a Paint LUT weights file, or altered or damaged")
    try:
        h = json.loads(header_json)
        if h.get("fit_version") != FIT_VERSION:
            raise lutfile.LUTError(f"{path}: weights format {h.get('fit_version')}; this version reads {FIT_VERSION}")
        basis = [Closure(**c) for c in h["closures"]]
        views, tiles = int(h["views"]), int(h["tiles"])
        weights = np.zeros((len(basis), len(COMPONENTS), views, tiles))
        for r, (k, c) in enumerate(h["rows"]):
            weights[k, c] = pixels[::-1][r, :, :tiles]
        return Fit(
            target=h["target"],
            exact_metallic=bool(h["exact_metallic"]),
            type=h["type"],
            closures=basis,
            cos_view=view_cosines(views),
            weights=weights,
            residual=np.array(h["residual"], dtype=float),
            reference=np.array(h["reference"], dtype=float),
            mirror=bool(h["mirror"]),
            n=float(h["n"]),
            internal_reflectance=float(h["internal_reflectance"]),
            lut_key=h.get("lut_key", ""),
            calibration=tuple(h["calibration"]) if h.get("calibration") else None,
            dense_residual=None if h.get("dense_residual") is None else np.array(h["dense_residual"], dtype=float),
            dense_reference=None if h.get("dense_reference") is None else np.array(h["dense_reference"], dtype=float),
        )
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        if isinstance(exc, lutfile.LUTError):
            raise
        raise lutfile.LUTError(f"{path}: malformed weights header ({exc})") from None
