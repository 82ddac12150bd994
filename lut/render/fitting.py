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
   facet lobes are sharp), reflected about the view, up to lights
   ``MAX_LIGHT`` from the normal (past the measure's 75°, weighted
   ``BEYOND_WEIGHT`` there, so the fall-off toward the horizon is held,
   not extrapolated); each row is radiance
   L = f·cos θl weighted by its share of the fidelity measure
   (``lut.render.measure``: uniform in θl and φ, dθl dφ = dω/sin θl with
   dω_l = 4 (h·v) dω_h) and nothing further; for an exponential Cycles
   type whose facet term misses a goal on those rows, also the exact
   mirror direction of each view at a small weight (``FALLBACK_ROW_SETS``,
   ``mirror_rows``: the measure's grid holds it, and a cusp-like peak
   narrower than its steps weighs there as its top), kept only where it
   holds between the grid's points too (``gains_everywhere``).  Targets
   come from the LUT.
2. Selection.  Forward selection: from the target's candidate closures,
   repeatedly add the one that most reduces the sum over components of the
   squared relative error on the measure, views weighted by their share of
   it (uniform in θv) (ranked by least squares over all views at once,
   the best few checked by non-negative least squares, all of them when
   none of those helps: near-collinear Toon ramps mislead the
   unconstrained ranking), until the render
   cost budget (closures per material) is spent or the error is far below
   target.  The selection is made on each set of rows of ``DEFAULT_ROW_SETS``
   and the one nearest the goals kept (then ``FALLBACK_ROW_SETS``, step 1).  Where a component's error on the
   measure (step 4) is then still above the target (some colour of the type would miss it),
   the selection is made again with a few closures more (``EXTRA_BUDGET``)
   and kept if it lowers that error.  Grey closures (no colour input)
   serve the facet component only and keep weights <= 1 (a Mix Shader
   factor clamps there).
3. Weights.  Non-negative least squares per view and component over the
   chosen closures (``lut.render.nnls``).
4. Error.  The fidelity measure (``lut.render.measure``), whole and over
   the grazing band: the closures, with the weights the node group reads
   (the texture's nearest column), against the paper's model itself (not
   the LUT), at every geometry of the measure's grid.  Stored as Gram
   matrices of the residuals and targets per component, so the error of
   any colour is ``Fit.error(amplitudes)`` (``Fit.grazing_error``): the
   panel shows it live.

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
from . import closures, measure
from .closures import Closure
from .nnls import nnls_gram_batch, solve_spd

#: Fit format version: bumped when the weights file layout or the fit changes.
#: It is part of the weights file's name (``fit_path``), so a new release
#: never overwrites a file that an older release's node groups still read.
FIT_VERSION = 14

#: Goals of the fidelity measure (whole domain) per engine and kind of
#: paint (``lut.render.measure.GOALS``; the grazing band's are twice these).
TARGET_ERROR = {e: {k: g[0] for k, g in kinds.items()} for e, kinds in measure.GOALS.items()}

#: Closures per material (render cost grows with their number; the mirror
#: of a smooth type comes on top).  EEVEE evaluates few closures per pixel.
BUDGET = {"CYCLES": 8, "EEVEE": 3}
#: Closures a fit may add beyond ``BUDGET`` where a component misses a goal of
#: the fidelity measure within it (``shortfall``): only the types that need them (very
#: rough facets, strongly back-scattering pigments) pay the render cost.
EXTRA_BUDGET = {"CYCLES": 4, "EEVEE": 0}

#: How an EEVEE fit is drawn (``validate_eevee_mode``).  EEVEE keeps one
#: closure per bin (one diffuse, two reflection) in each pixel and sample,
#: picked at random in proportion to its weight and rescaled so that the
#: mean over samples is the closures' sum (``closure_select`` in EEVEE's
#: GLSL).  "EXACT": at most the closures EEVEE sums exactly at one sample
#: (``BUDGET["EEVEE"]``); "CONVERGED": where that misses a goal of the
#: measure, up to ``CONVERGED_BUDGET`` closures (+ ``CONVERGED_EXTRA``),
#: exact once samples average them (``lut.render.eevee.spread`` says how
#: noisy, ``samples_needed`` how many samples it takes).  A type whose exact fit meets its goals keeps it in
#: either mode: it renders noise-free at one sample.
EEVEE_MODES = ("EXACT", "CONVERGED")
#: The mode a bake fits EEVEE in unless told otherwise.
DEFAULT_EEVEE_MODE = "CONVERGED"
CONVERGED_BUDGET = 8
CONVERGED_EXTRA = 4
#: A converged fit is kept where it brings the fit this much nearer its
#: goals (its ``shortfall``) than the exact one: noise for less is no gain.
CONVERGED_GAIN = 0.8

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
#: Lights are fitted up to this polar angle: the measure's 75° and a margin,
#: so the fit follows the light-side fall-off to where the measure ends.
MAX_LIGHT = np.radians(85.0)
#: Lights beyond the measure's range (``MEASURE_LIGHT``, 75°) are fitted with
#: this weight (in amplitude): enough to hold the fall-off toward the
#: horizon, not so much that the fit gives up the measured range for it.
#: Measured on ``lut.bench.random_paints(24)``: at full weight a Gaussian
#: slope 2.9 fits to 15.2% and a Gaussian slope 0.21 to 3.5%, at 0.1 to
#: 8.1% and 1.3% (0.3: 8.1% and 1.9%).
MEASURE_LIGHT = measure.GRID[0][-1]
BEYOND_WEIGHT = 0.1
#: Views are evaluated at most this far from the normal (θv = 90° exactly is
#: a degenerate direction).
MAX_VIEW = np.radians(89.5)

#: Views up to this polar angle drive the selection fully (the measure's
#: range and a margin); views beyond count a tenth.
SELECTION_VIEW = np.radians(80.0)

_CANDIDATES_CHECKED = 4

#: The rows a fit is made on, tried in turn until one meets its goals (the fit kept is the one
#: nearest its goals on the measure, ``shortfall``): "hemisphere", light
#: directions of a half-vector grid weighted by their share of the measure
#: (a continuous integral, dense about the mirror); "mirror", those and the
#: exact mirror direction of each view weighted as one cell of the
#: measure's lattice (``mirror_rows``); "lattice", the hemisphere's rows and
#: the measure's whole lattice of lights about each view, its exact mirror
#: included; "grazing" and "grazing-mirror", the hemisphere's rows (and the
#: mirror's) with the grazing band emphasised.  The measure counts each of
#: its geometries once, and its grid holds the exact mirror of every one of
#: its views (θl and θv share their steps), so a lobe much narrower than its
#: 5° steps weighs there as much as its peak value at the mirror: the
#: integral alone under-weights that peak, the lattice alone the shape
#: between its points, and the integral plus the mirror point does neither.
#: A fit of the whole measure may give up the grazing band, which has goals
#: of its own.  Measured on ``lut.bench.random_paints(24)``: near-smooth
#: exponential slopes 8.2% -> 3.2% (the lattice), a smooth back-scattering
#: paint's grazing band 9.4% -> 5.6% (the emphasis); with the mirror point,
#: exponential slopes 0.08-0.12 4.0-6.3% -> 1.4-2.2%, and between the
#: measure's points (``measure.BETWEEN_GRID``) 1.6%, 2.5% and 3.5% ->
#: 1.7%, 3.5% and 3.2% (docs/fidelity.md).
ROW_SETS = ("hemisphere", "mirror", "lattice", "grazing", "grazing-mirror", "grazing-cusp")
#: The row sets a fit tries by default, per target.  Not the lattice: it fits
#: the measure's points at the cost of the shape between them, which a render
#: of a curved object shows (a near-smooth exponential slope: 2.9% on the
#: measure's grid, 6.7% on every pixel of a sphere, binned).  Nor the mirror
#: sets, for the same reason: they draw an exponential slope's cusp to its
#: top at the grid's exact mirror points (random paint #6 of
#: ``lut.bench.random_paints``: 5.34% -> 2.24% on the grid), but every pixel
#: of a sphere, binned on the grid (``lut.bench.binned_errors``, what an
#: artist sees), measured worse on each exponential type checked: random #6
#: 2.23% -> 5.28%, #21 1.64% -> 3.96%, dark #15 2.14% -> 3.19%, dark #1
#: 3.27% -> 4.57% (``measure.BETWEEN_GRID``, lights alone shifted, did not
#: show it).  They stay a choice (``row_sets``) for the grid's own points.
#: EEVEE fits keep the rows they were measured on (docs/eevee.md).
DEFAULT_ROW_SETS = {
    "CYCLES": ("hemisphere", "grazing"),
    "EEVEE": ("hemisphere", "grazing"),
}
#: The rows a default fit of an exponential type (whose facet term peaks in
#: a cusp) tries next where its facet term misses a goal on the default
#: sets' rows (on the measure's grid): "grazing-cusp", the "grazing" rows and
#: each view's mirror point at ``CUSP_WEIGHT`` of the mirror sets' weight.
#: Both fits are then scored on the grid and on its two checks between its
#: points (``measure.BETWEEN_GRID``, lights shifted half a step, and
#: ``measure.SHIFTED_GRID``, all three angles shifted), component by
#: component, and the new one is kept only where no component gets worse
#: past its goal and the whole gains (``gains_everywhere``): the type's
#: worst component alone (``shortfall``) hid a facet term going 4.8% ->
#: 8.4% on dark #17 behind its single-scattering term.  Neither check alone
#: tells a sphere's binned pixels apart (random #6: the lights-alone check
#: rejects a fit whose pixels are worse, the shifted one does not;
#: docs/fidelity.md).  EEVEE fits keep their measured rows.
FALLBACK_ROW_SETS = {"CYCLES": ("grazing-cusp",), "EEVEE": ()}
#: The mirror point's weight in the "grazing-cusp" rows, in amplitude (its
#: share of the fit is the square), relative to one lattice cell's
#: (``mirror_rows``).  Measured on near-smooth exponential types, grid ->
#: every pixel binned (200,000 random geometries): random #21 6.34% ->
#: 2.87% on the grid, 2.07% -> 1.60% binned; at twice this weight the
#: binned figure rose to 4.45%.
CUSP_WEIGHT = 0.25
#: How much a fallback fit must lower the sum of squares of its components'
#: goal ratios to be kept (``gains_everywhere``): less is a tie.
FALLBACK_GAIN = 0.02
#: The "grazing" row sets: the hemisphere's rows with lights in the grazing
#: band weighted this much more (in amplitude), for types whose fall-off
#: toward the horizon the plain measure gives up to gain elsewhere.
GRAZING_EMPHASIS = 2.0


def validate_eevee_mode(mode: str) -> str:
    """``mode`` if it is one of ``EEVEE_MODES``; a clear error otherwise."""
    if mode not in EEVEE_MODES:
        raise ValueError(f"eevee_mode must be one of {', '.join(EEVEE_MODES)}, got {mode!r}")
    return mode


def validate_row_set(row_set: str) -> str:
    if row_set not in ROW_SETS:
        raise ValueError(f"row_sets must be some of {', '.join(ROW_SETS)}, got {row_set!r}")
    return row_set


@dataclasses.dataclass
class Fit:
    """A paint type's closure fit for one render target.

    closures   the chosen closures (K)
    weights    (K, C, M, T): w_kc at view cosines ``cos_view`` (M), per tile
               T (1, or 3 for a dispersive type: one per RGB channel)
    residual   (T, C, C) and ``reference`` (T, C, C): Gram matrices of the
               rendered radiance's residual and of the model's radiance per
               component on the fidelity measure's grid
               (``lut.render.measure``), giving ``error`` for any colour
    grazing_residual, grazing_reference: the same over the grazing band
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
    grazing_residual: np.ndarray | None = None
    grazing_reference: np.ndarray | None = None
    eevee_mode: str = "EXACT"
    #: An OSL variant's: the ``content_key`` of the SVM fit it was made
    #: from (a cached variant of another Cycles fit is stale).
    base_key: str = ""
    #: An EEVEE fit's: the (whole, grazing band) goals its closures were
    #: chosen against (how many, which mode's); a cached EEVEE fit chosen
    #: against other goals is fitted again (``stale_goals``).
    chosen_for: tuple | None = None

    @property
    def stale_goals(self) -> bool:
        """Whether an EEVEE fit's closures were chosen against goals other
        than today's (``measure.GOALS``; a fit written before its file
        recorded them was chosen against earlier goals).  Cycles' goals
        are those of every fit this format has written."""
        if self.target != "EEVEE":
            return False
        return self.chosen_for is None or tuple(self.chosen_for) != tuple(self.goals)

    @property
    def sums_exactly(self) -> bool:
        """Whether EEVEE draws these closures exactly at one sample: at most
        one diffuse normal and two reflection closures (a smooth type's
        mirror is one of them); Cycles always does."""
        if self.target != "EEVEE":
            return True
        from . import eevee

        return eevee.sums_exactly(self.closures, self.mirror)

    @functools.cached_property
    def noisiest_spread(self) -> float:
        """EEVEE's per-pixel spread at one sample for the type's noisiest
        colour (``eevee.type_spread``; 0 where it sums exactly), computed
        once per fit: the material stores it, a bake's status reports it."""
        from . import eevee

        return eevee.type_spread(self)

    @property
    def rough(self) -> bool:
        return float(self.type["slope"]) > 0

    @property
    def osl(self) -> bool:
        """Whether it is the OSL variant of a Cycles fit (``fit_osl``): its
        closures include signed ramp knots, which only OSL draws."""
        return any(c.osl for c in self.closures)

    @property
    def draws_ramps(self) -> bool:
        """Whether an OSL variant's ramps carry weight: a variant whose ramps
        did not pay (``fit_osl``) draws its SVM fit alone, and the add-on
        renders the SVM group for it."""
        return any(self.closures[k].osl for k, _ in self.rows)

    @property
    def goals(self) -> tuple[float, float]:
        """(whole, grazing band) goals of the measure for this fit (the OSL
        variant's are its own, ``measure.GOALS["OSL"]``)."""
        return measure.goals("OSL" if self.osl else self.target, not self.rough)

    @property
    def target_error(self) -> float:
        return self.goals[0]

    @property
    def rows(self) -> list:
        """(closure index, component index) pairs that carry weight: the
        rows of the weights texture, bottom to top."""
        used = np.abs(self.weights).max(axis=(2, 3)) > 0  # a ramp knot's weight is signed
        return [(k, c) for k in range(len(self.closures)) for c in range(len(COMPONENTS)) if used[k, c]]

    def component_errors(self) -> dict:
        """The relative error of each component alone (None where it is nil)."""
        return component_errors(self.residual, self.reference)

    def error(self, amplitudes) -> float:
        """The fidelity measure (``lut.render.measure``) of a paint with these
        amplitudes ((3 channels, 3 components): ``Paint.amplitudes``), as the
        node group renders it against the paper's model."""
        return reported_error(self.grams(), amplitudes)

    def grazing_error(self, amplitudes) -> float:
        """The same over the grazing band (θl ≥ 60°)."""
        return reported_errors(self.grams(), amplitudes)[1]

    def radiance(self, amplitudes, theta_l, theta_v, phi, rounding=None) -> np.ndarray:
        """The RGB radiance per unit irradiance, (N, 3), that the node group
        renders at geometries (θl, θv, φ) (1-D arrays) for a paint with these
        amplitudes: the closures as the target draws them (``evaluator_for``:
        EEVEE's measured responses for a calibrated fit) with the weights the
        texture gives (nearest view column); a smooth type's mirror (a
        delta) is not included.  What ``error`` measures against the model.

        For EEVEE, the mean over samples with each closure colour as its
        G-buffer keeps it (``eevee.mean_radiance``), rounded as ``rounding``
        says (``eevee.COLOUR_ROUNDINGS``; default ``eevee.COLOUR_ROUNDING``,
        "none" for full floats).  ``error``, formed from the fit's Gram
        matrices, is that of full floats."""
        tl, tv, ph = (np.ravel(np.asarray(a, dtype=float)) for a in (theta_l, theta_v, phi))
        evaluate = evaluator_for(self.target, self.calibration)
        values = np.array([evaluate(c, tl, tv, ph) for c in self.closures]).reshape(len(self.closures), tl.size)
        amps = np.asarray(amplitudes, dtype=float)  # (3 channels, C)
        colours = closure_colours(read_weights(self.weights, self.cos_view, np.cos(tv), columns=True), amps)
        if self.target != "EEVEE":
            return np.einsum("kn,knh->nh", values, colours)
        from . import eevee

        facet = float(np.mean(amps[:, 0]))
        mirror_n = self.n if self.mirror else None
        return eevee.mean_radiance(
            self.closures, colours, values, mirror_n, facet, eevee.COLOUR_ROUNDING if rounding is None else rounding
        )

    def grams(self) -> dict:
        """The Gram matrices the reported errors come from, as lists (what a
        material stores to show its errors for any colour): residual,
        reference, grazing_residual and grazing_reference."""
        out = {"residual": self.residual.tolist(), "reference": self.reference.tolist()}
        for name in ("grazing_residual", "grazing_reference"):
            value = getattr(self, name)
            out[name] = None if value is None else value.tolist()
        return out

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
            "eevee_mode": self.eevee_mode,
            **({"base_key": self.base_key} if self.base_key else {}),
            **({"chosen_for": list(self.chosen_for)} if self.chosen_for is not None else {}),
        }


def component_errors(residual, reference) -> dict:
    """{component: relative error of that component alone} from the
    measure's Gram matrices (T, C, C), summed over tiles; None where it is nil."""
    out = {}
    for c, name in enumerate(COMPONENTS):
        ref = reference[:, c, c].sum()
        out[name] = float(np.sqrt(residual[:, c, c].sum() / ref)) if ref > 0 else None
    return out


def reported_errors(grams: dict, amplitudes) -> tuple[float, float]:
    """(whole, grazing band) fidelity measure of a colour from a fit's Gram
    matrices (``Fit.grams``); the grazing figure is the whole one where the
    grams lack the band."""
    whole = gram_error(grams["residual"], grams["reference"], amplitudes)
    if grams.get("grazing_residual") is None:
        return whole, whole
    return whole, gram_error(grams["grazing_residual"], grams["grazing_reference"], amplitudes)


def between_errors(fitted: Fit, paint, amplitudes) -> tuple[float, float]:
    """(whole, grazing band) ε of a fit's radiance against the paper's model
    at the geometries of ``measure.BETWEEN_GRID``, between the measure's own
    (none at the mirror direction): a check that the fit holds between the
    points it is measured at.  ``paint``: a ``lut.Paint`` of the fit's type,
    ``amplitudes`` its ``Paint.amplitudes``."""
    tl, tv, ph = measure.points(fitted.mirror, measure.BETWEEN_GRID)
    model = paint.brdf(tl, tv, ph) * np.cos(tl)[:, None]
    return measure.errors(fitted.radiance(amplitudes, tl, tv, ph), model, tl)


def reported_error(grams: dict, amplitudes) -> float:
    """The fidelity measure a fit reports for a colour (``Fit.error``)."""
    return reported_errors(grams, amplitudes)[0]


def gram_error(residual, reference, amplitudes) -> float:
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
    square root of the row's share of the fidelity measure (uniform in θl
    and φ); rows beyond ``max_light`` have weight 0."""
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
    # The fidelity measure samples θl and φ uniformly, not solid angle:
    # dθl dφ = dω / sin θl (bounded near the normal, where rows are few).
    d_measure = d_omega / np.maximum(np.sin(theta_l), MIN_SIN)
    weight = np.where(ok, np.sqrt(d_measure), 0.0) * np.where(theta_l > MEASURE_LIGHT, BEYOND_WEIGHT, 1.0)
    return theta_l, phi, weight


def lattice_rows(theta_v, max_light=MAX_LIGHT):
    """The fidelity measure's own lattice about each view: lights at the
    measure's θl steps (to ``max_light``) and φ steps, plus the mirror
    direction of the view (the measure's grid holds the exact mirror of
    each of its views).  (θl, φ, row weight), shape (M, R): weight the
    square root of the lattice cell dθl dφ, as ``light_rows``."""
    step_l = measure.GRID[0][1] - measure.GRID[0][0]
    tl = np.arange(0.0, max_light + 1e-9, step_l)
    ph = measure.GRID[2]
    tl, ph = (a.ravel() for a in np.meshgrid(tl, ph, indexing="ij"))
    m_ = np.asarray(theta_v).size
    theta_l = np.concatenate([np.broadcast_to(tl, (m_, tl.size)), np.asarray(theta_v).reshape(m_, 1)], axis=1)
    phi = np.concatenate([np.broadcast_to(ph, (m_, ph.size)), np.zeros((m_, 1))], axis=1)
    weight = np.full(theta_l.shape, np.sqrt(step_l * (measure.GRID[2][1] - measure.GRID[2][0])))
    weight = weight * np.where(theta_l > MEASURE_LIGHT + 1e-9, BEYOND_WEIGHT, 1.0)
    weight[:, -1] = np.where(np.asarray(theta_v) <= max_light, weight[:, -1], 0.0)
    return theta_l, phi, weight


def mirror_rows(theta_v, weight=1.0):
    """The exact mirror direction of each view (θl = θv, φ = 0), which the
    measure's grid holds for each of its views: (θl, φ, row weight), shape
    (M, 1), weight the square root of one lattice cell dθl dφ (as
    ``lattice_rows``), nil for views past the measure's (``measure.GRID``).
    Beside the hemisphere's rows, which stand for the measure's integral,
    it gives the peak a lattice cell's weight.  Those rows count both halves
    of the azimuth (``light_rows``), twice the measure's φ 0-180°, so this is
    half the mirror point's share of the grid; the full share (a weight
    sqrt(2) times this) was measured and not kept: the randomised set's rough
    median 1.89% -> 2.71%, between the measure's points 1.98% -> 2.24%, the
    dark set's 4.64% -> 4.58%.  ``weight``: a further factor on it (in
    amplitude: its share of the fit is the square)."""
    theta_v = np.asarray(theta_v, dtype=float).reshape(-1, 1)
    cell = (measure.GRID[0][1] - measure.GRID[0][0]) * (measure.GRID[2][1] - measure.GRID[2][0])
    weight = np.where(theta_v <= measure.GRID[1][-1] + 1e-9, float(weight) * np.sqrt(cell), 0.0)
    return theta_v.copy(), np.zeros_like(theta_v), weight


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
    x = solve_spd(sub, g)
    err = norm[:, 0, None] - np.sum(x * g, axis=-1)
    return _relative(np.maximum(err, 0.0), norm)


def _relative(err, norm):
    """The relative squared error over all views, Σ_v w_v·err_v / Σ_v
    w_v·‖b_v‖², each view v weighted by its share w_v of the fidelity
    measure (``view_measure``): the measure's own ratio, radiance residual
    over radiance, summed over the geometries it counts.  err (M, ...);
    norm (M, 2): each view's ‖b_v‖² and w_v."""
    total = float(np.sum(norm[:, 0] * norm[:, 1]))
    return np.tensordot(norm[:, 1], err, axes=(0, 0)) / max(total, 1e-300)


def view_measure(theta_v):
    """Each fitted view's share of the fidelity measure, which is uniform in
    θv: the width in θv of the interval of view cosines it stands for, a
    tenth beyond ``SELECTION_VIEW`` (outside the measure's range: fitted,
    but not chosen for)."""
    cos_v = np.cos(np.asarray(theta_v, dtype=float))
    edges = np.concatenate(([cos_v[0]], 0.5 * (cos_v[1:] + cos_v[:-1]), [cos_v[-1]]))
    width = np.abs(np.diff(np.arccos(np.clip(edges, -1.0, 1.0))))
    return width * np.where(np.asarray(theta_v) <= SELECTION_VIEW, 1.0, 0.1)


def _nnls_fit(gram, rhs, norm, idx, upper, start=None):
    """Per-view NNLS weights on closures ``idx``: (x (M, s), relative squared
    error).  ``start`` (M, s): a warm start (``nnls.nnls_gram_batch``), the
    weights of the same closures but the last.  ``_nnls_fits`` of one target."""
    x, rel = _nnls_fits(gram, rhs[:, None], norm[:, None], idx, upper, None if start is None else start[:, None])
    return x[:, 0], rel[0]


def _nnls_fits(gram, rhs, norm, idx, upper, start=None):
    """``_nnls_fit`` of several targets on the same closures ``idx`` at
    once: rhs (M, P, K), norm (M, P, 2), start (M, P, s) or None; returns
    (x (M, P, s), relative squared errors (P,)).  Each (view, target) is its
    own problem in one batch, with the same solution as alone."""
    idx = list(idx)
    m_, p_ = rhs.shape[:2]
    sub = np.repeat(gram[:, idx][:, :, idx], p_, axis=0)  # (M·P, s, s): view m's Gram for each target
    g = rhs[:, :, idx].reshape(m_ * p_, len(idx))
    n0 = norm[:, :, 0].reshape(-1)
    scale = np.maximum(np.abs(np.diagonal(sub, axis1=-2, axis2=-1)).max(axis=-1), 1e-300)
    # Unconstrained solutions first (all problems at once); NNLS only where
    # a weight leaves its bounds.
    x = solve_spd(sub + 1e-13 * scale[:, None, None] * np.eye(len(idx)), g)
    bad = (np.any(x < 0, axis=1) | np.any(x > upper, axis=1)) & (n0 > 0)
    if bad.any():
        warm = None if start is None else start.reshape(m_ * p_, len(idx))[bad]
        x[bad] = nnls_gram_batch(sub[bad], g[bad], upper=upper, start=warm)
    x[n0 == 0] = 0.0
    err = n0 - 2 * np.sum(x * g, axis=1) + np.einsum("ns,nst,nt->n", x, sub, x)
    err = np.maximum(err, 0.0).reshape(m_, p_)
    rel = [float(_relative(err[:, q], norm[:, q])) for q in range(p_)]
    return x.reshape(m_, p_, len(idx)), rel


def _select(gram, rhs, norm, allowed, upper, cost, budget, goal, caps=None, start=()):
    """Forward selection of closures for every (tile, component) target.
    gram (M, K, K); rhs (M, P, K), norm (M, P, 2) over P targets; allowed
    (P, K); upper (K,); caps: (mask over K, most closures of the mask);
    goal: the relative squared error below which selection stops; start:
    closures chosen already (the steps a selection within a smaller budget
    shares with this one: ``shared``).  Returns (the chosen closure indices
    in order, how many of the first of them any larger budget would choose
    too: those picked while no candidate was out of the budget)."""
    targets = [p for p in range(rhs.shape[1]) if norm[:, p, 0].sum() > 0]
    chosen: list[int] = list(start)
    errors = {p: 1.0 for p in targets}
    solutions = {p: np.zeros((gram.shape[0], 0)) for p in targets}  # each target's weights on its chosen closures
    for p in targets:
        idx = [k for k in chosen if allowed[p, k]]
        if idx:
            solutions[p], errors[p] = _nnls_fit(gram, rhs[:, p], norm[:, p], idx, upper[idx])
    spent = int(sum(cost[k] for k in chosen))
    shared = None
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
        if shared is None and spent + cost.max() > budget:
            shared = len(chosen)  # from here on the budget may exclude a candidate
        proxy = np.zeros(len(cands))
        for p in targets:
            base = [k for k in chosen if allowed[p, k]]
            ok = [i for i, k in enumerate(cands) if allowed[p, k]]
            proxy += errors[p]
            if ok:
                new = _ls_errors(gram, rhs[:, p], norm[:, p], base, [cands[i] for i in ok])
                proxy[ok] += np.minimum(new, errors[p]) - errors[p]
        current = sum(errors.values())
        best, best_gain, best_errors, best_solutions = None, 0.0, None, None
        order = np.argsort((proxy - current) / cost[cands])
        for rank, i in enumerate(order):
            if rank >= _CANDIDATES_CHECKED and best is not None:
                break  # the proxy's best few were checked and one helps
            k = cands[i]
            trial, trial_solutions = dict(errors), dict(solutions)
            groups = {}  # the targets k serves, by the closures each would be fitted on
            for p in targets:
                if allowed[p, k]:
                    groups.setdefault(tuple(j for j in chosen + [k] if allowed[p, j]), []).append(p)
            for idx, ps in groups.items():
                warm = np.stack([np.pad(solutions[p], ((0, 0), (0, 1))) for p in ps], axis=1)  # k enters last, at zero
                x, rel = _nnls_fits(gram, rhs[:, ps], norm[:, ps], idx, upper[list(idx)], warm)
                for q, p in enumerate(ps):
                    trial_solutions[p], trial[p] = x[:, q], rel[q]
            gain = (current - sum(trial.values())) / cost[k]  # error reduction per unit of render cost
            if gain > max(best_gain, 1e-9):
                best, best_gain, best_errors, best_solutions = k, gain, trial, trial_solutions
        if best is None:
            break
        chosen.append(best)
        spent += cost[best]
        errors, solutions = best_errors, best_solutions
    return chosen, len(chosen) if shared is None else shared


# ---------------------------------------------------------------------- fit


def nearest_column(columns: int, cos_v) -> np.ndarray:
    """The column of a weights texture of ``columns`` columns (cos θv =
    j/(columns - 1)) that a Closest lookup at view cosines ``cos_v`` reads."""
    return np.clip(np.rint(np.asarray(cos_v) * (columns - 1)).astype(int), 0, columns - 1)


def closure_colours(weights, amplitudes) -> np.ndarray:
    """Σ_c a_c·w_kc: each closure's colour (K, N, 3) from the weights it reads
    (K, C, N, T: one tile for every channel, or one per channel) and a
    paint's amplitudes (3 channels, C)."""
    amps = np.asarray(amplitudes, dtype=float)
    if weights.shape[-1] == 1:
        return np.einsum("kcn,hc->knh", weights[..., 0], amps)
    return np.einsum("kcnh,hc->knh", weights, amps)


def texture_weights(weights, cos_view, cos_v):
    """The weights (K, C, N, T) a node group reads at view cosines ``cos_v``
    (N,) from a fit's weights at ``cos_view`` (M): the column of its weights
    texture nearest to each cos θv (``texture_u``), the texture holding the
    weights resampled linearly to ``texture_views(M)`` columns."""
    columns = view_cosines(texture_views(len(cos_view)))
    texture = resample_views(weights, cos_view, columns)
    return texture[:, :, nearest_column(len(columns), cos_v), :]


def read_weights(weights, cos_view, cos_v, columns=False):
    """The weights (K, C, N, T) a node group reads at view cosines ``cos_v``
    (N,): with ``columns``, ``weights`` are the weights texture's own
    columns at ``cos_view`` (a ``Fit``'s) and the column nearest to each
    view is read; else they are weights fitted at ``cos_view``, read as
    ``texture_weights``."""
    if columns:
        return weights[:, :, nearest_column(len(cos_view), cos_v), :]
    return texture_weights(weights, cos_view, cos_v)


@functools.lru_cache(maxsize=6)
def _model_radiance(type_json: str, single_nodes, diffuse_nodes, smooth: bool, grid: str = "measure"):
    """The paper's model at the geometries of one of ``measure.GRIDS``
    (``measure.points``): (θl, θv, φ) and each colour-free component's
    radiance f·cos θl (N, T, C), computed once per paint type and grid."""
    from ..paint.core import Paint

    paint = Paint.from_dict(json.loads(type_json))
    opts = {}
    if single_nodes is not None:
        opts = {"single_nodes": single_nodes, "diffuse_nodes": diffuse_nodes}
    tl, tv, ph = measure.points(smooth, measure.GRIDS[grid])
    return (tl, tv, ph), paint.components(tl, tv, ph, **opts) * np.cos(tl)[:, None, None]


def model_radiance(lut, grid="measure"):
    """``_model_radiance`` of a loaded LUT's paint type, with the LUT's own
    quadrature sizes, on the grid named ``grid`` (``measure.GRIDS``)."""
    if grid not in measure.GRIDS:
        raise ValueError(f"grid must be one of {', '.join(measure.GRIDS)}, got {grid!r}")
    meta = lut.meta
    single = tuple(meta["single_nodes"]) if "single_nodes" in meta else None
    diffuse = tuple(meta["diffuse_nodes"]) if "diffuse_nodes" in meta else None
    smooth = float(meta["type"]["slope"]) == 0.0
    return _model_radiance(json.dumps(meta["type"], sort_keys=True), single, diffuse, smooth, grid)


def measure_grams(model, basis, cos_view, weights, evaluate, *, columns=False, values=None):
    """The fidelity measure's Gram matrices of a fit: (residual, reference)
    over the whole grid and over the grazing band, each (T, C, C), from the
    model's radiance ``model`` (``model_radiance``: points and (N, T, C)) and
    the closures ``basis`` with the weights the node group reads: those of
    ``texture_weights`` for weights fitted at ``cos_view``, or with
    ``columns`` the weights texture's own columns at ``cos_view``, read at
    the column nearest to each view; ``values``: the closures' responses at
    the model's points (K, N), where already evaluated."""
    (tl, tv, ph), target = model
    if values is None:
        values = np.array([evaluate(c, tl, tv, ph) for c in basis]).reshape(len(basis), tl.size)  # (K, N); K may be 0
    fitted = np.einsum("kn,kcnt->ntc", values, read_weights(weights, cos_view, np.cos(tv), columns))
    r = fitted - target
    band = measure.grazing(tl)

    def grams(sel):
        return np.einsum("ntc,ntd->tcd", r[sel], r[sel]), np.einsum("ntc,ntd->tcd", target[sel], target[sel])

    return grams(slice(None)), grams(band)


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
    row_sets=None,
    eevee_mode=DEFAULT_EEVEE_MODE,
    converged_budget=CONVERGED_BUDGET,
    converged_extra=CONVERGED_EXTRA,
    converged_gain=CONVERGED_GAIN,
) -> Fit:
    """Fit a loaded LUT (``lut.lutfiles.baking.LUT``) onto the closures of a render
    target (module docstring).  ``budget``, ``extra_budget``: closures per
    material, and how many more while a component misses the target
    (defaults ``BUDGET``, ``EXTRA_BUDGET``).  ``calibration``: for EEVEE, the
    Blender line whose measured closure responses to fit with (``lut.render.eevee``;
    None: Cycles' formulas, EEVEE's own rendering unmodelled).  ``row_sets``:
    the rows to fit on, tried in turn (``ROW_SETS``) until a fit meets its
    goals; the fit kept is the one nearest them (``shortfall``); None: the
    target's ``DEFAULT_ROW_SETS``, then for an exponential type whose facet
    term misses a goal on them its ``FALLBACK_ROW_SETS``, kept only where
    ``gains_everywhere``.
    Where a set with the mirror point is tried, each fit's shortfall is the
    largest of its shortfalls on the measure's grid, on
    ``measure.BETWEEN_GRID`` and on ``measure.SHIFTED_GRID``.
    ``eevee_mode``: for EEVEE, "EXACT" or "CONVERGED" (``EEVEE_MODES``):
    where the exact fit misses a goal, a converged one of up to
    ``converged_budget`` closures (+ ``converged_extra``) is fitted too and
    kept where its shortfall, viewport noise counted in, is below
    ``converged_gain`` times the exact fit's (``CONVERGED_GAIN``)."""
    target = closures.validate_target(target)
    eevee_mode = validate_eevee_mode(eevee_mode) if target == "EEVEE" else "EXACT"
    evaluate = evaluator_for(target, calibration)
    budget = BUDGET[target] if budget is None else int(budget)
    if budget < 1:
        raise ValueError(f"budget must be a whole number >= 1, got {budget!r}")
    extra_budget = EXTRA_BUDGET[target] if extra_budget is None else int(extra_budget)
    if extra_budget < 0:
        raise ValueError(f"extra_budget must be a whole number >= 0, got {extra_budget!r}")
    row_sets_default = row_sets is None
    if row_sets is None:
        row_sets = DEFAULT_ROW_SETS[target]
    row_sets = tuple(validate_row_set(r) for r in row_sets)
    if not row_sets:
        raise ValueError(f"row_sets must name at least one of {', '.join(ROW_SETS)}")
    meta = lut.meta
    type_dict = meta["type"]
    # A calibrated EEVEE (Blender 5) draws the Metallic BSDF as measured,
    # whatever Cycles makes of it: its lobes are Metallic ones.
    metallic = exact_metallic or (target == "EEVEE" and calibration is not None)
    basis = closures.candidates(type_dict, target, metallic)
    cos_view = view_cosines(views)
    theta_v = np.arccos(np.clip(cos_view, np.cos(MAX_VIEW), 1.0))
    model = model_radiance(lut)
    best = None
    exact = target == "EEVEE"
    smooth = float(type_dict["slope"]) == 0.0
    goals = measure.goals(target, smooth)

    def checked_ratios(fitted):
        """``goal_ratios`` of a fit, each the largest of those on the
        measure's grid and on its two checks between the grid's points
        (``measure.BETWEEN_GRID``, ``measure.SHIFTED_GRID``)."""
        out = goal_ratios(*fitted[2:4], goals)
        for name in ("between", "shifted"):
            grams = measure_grams(model_radiance(lut, name), fitted[0], cos_view, fitted[1], evaluate)
            off = goal_ratios(*grams, goals)
            out = {k: max(v, off.get(k, 0.0)) for k, v in out.items()}
        return out

    def checked(fitted):
        """The fit with its shortfall the largest of ``checked_ratios``."""
        return (*fitted[:-1], max(checked_ratios(fitted).values(), default=0.0))

    def fit_on(row_set, extra=extra_budget):
        theta_l, phi, row_w = _rows(row_set, theta_v, grid)
        return _fit_rows(
            lut, target, evaluate, basis, theta_v, theta_l, phi, row_w, model, budget, extra, exact
        )  # fmt: skip

    # Where a set of rows holds the mirror point, every fit is scored
    # between the measure's points too: a fit must not buy the measure's
    # mirror points with the shape between them.
    checks_all = any(_has_mirror(r) for r in row_sets)
    # The cusp is the exponential distribution's: P(ζ) ∝ exp(-√6 ζ / s)
    # peaks with a kink at zero slope (``lut.models.distributions``, after
    # SCATMECH's Exponential_Slope_Distribution_Function).  Gaussian types
    # are not refitted: on both sets none gained, at 0.7 s of fit each.
    cusp = not smooth and type_dict.get("distribution") == "exponential"
    fallback = FALLBACK_ROW_SETS[target] if (row_sets_default and cusp) else ()
    for row_set in row_sets:
        fitted = fit_on(row_set)
        if checks_all:
            fitted = checked(fitted)
        if best is None or fitted[-1] < best[-1]:
            best, best_rows = fitted, row_set
        if best[-1] <= 1.0:  # every colour of the type meets both goals: the next sets need not be tried
            break
    facet = [v for (c, _), v in goal_ratios(*best[2:4], goals).items() if c == "facet"]
    if fallback and max(facet, default=0.0) > 1.0:
        # The facet term misses on the default rows (the cusp is its; a miss
        # of the other components alone is not refitted):
        # try the mirror point at a small weight,
        # and keep it only where it brings every component nearer its goals
        # (or keeps it within them) on the grid and between the grid's
        # points alike (``gains_everywhere``, both fits checked).
        # Within the budget alone: the extra closures' second selection
        # took this fit from 0.3 s to 0.7-1.5 s and changed no fit it kept
        # (random #21: the same 8 closures either way).
        before = checked_ratios(best)
        for row_set in fallback:
            fitted = fit_on(row_set, extra=0)
            after = checked_ratios(fitted)
            if gains_everywhere(before, after):
                best, best_rows, before = (*fitted[:-1], max(after.values())), row_set, after
    if eevee_mode == "CONVERGED" and best[-1] > 1.0:
        # Past EEVEE's exact bins: more closures, averaged over samples,
        # kept where they bring the fit nearer its goals by CONVERGED_GAIN.
        wide = closures.candidates(type_dict, target, metallic, converged=True)
        noise = functools.partial(
            _viewport_spread,
            points=model[0],
            mirror=float(type_dict["slope"]) == 0.0,
            n=reference_index(type_dict["n"]),
            cos_view=cos_view,
            calibration=calibration,
        )
        # On the rows the exact fit did best on (each set of rows costs a
        # selection of up to 12 closures and a noise estimate per step).
        theta_l, phi, row_w = _rows(best_rows, theta_v, grid)
        fitted = _fit_rows(
            lut, target, evaluate, wide, theta_v, theta_l, phi, row_w, model,
            int(converged_budget), int(converged_extra), False, noise,
        )  # fmt: skip
        if fitted[-1] < float(converged_gain) * best[-1]:
            best = fitted
    basis_kept, weights, whole, band, _ = best
    n = reference_index(type_dict["n"])
    dense = view_cosines(texture_views(views))
    return Fit(
        target=target,
        exact_metallic=bool(exact_metallic),
        type=type_dict,
        closures=basis_kept,
        cos_view=dense,
        weights=resample_views(weights, cos_view, dense),
        residual=whole[0],
        reference=whole[1],
        mirror=float(type_dict["slope"]) == 0.0,
        n=n,
        internal_reflectance=lut.internal_reflectance,
        lut_key=lut.key,
        calibration=tuple(calibration) if (calibration is not None and target == "EEVEE") else None,
        grazing_residual=band[0],
        grazing_reference=band[1],
        eevee_mode=eevee_mode,
        chosen_for=measure.goals(target, float(type_dict["slope"]) == 0.0) if target == "EEVEE" else None,
    )


# ---------------------------------------------------------------------- OSL ramps

#: Phong ramp exponents of the OSL variant: one ``phong_ramp`` closure per
#: exponent beside the one ``diffuse_ramp`` (``closures.ramp_closures``).
OSL_EXPONENTS = (1.0, 8.0)
#: Whether the OSL variant adds a diffuse ramp about the view direction
#: (``closures.ramp_closures``: for back-scattering paints, a smooth one of
#: g -0.49 from 2.86% / 7.67% to 1.95% / 4.62% on the measure).
OSL_RETRO = True
#: The least share by which the ramp about the view must lower the type's
#: shortfall (``shortfall``, on the OSL goals) to be kept: each ramp costs
#: render time on every pixel (the OSL variant renders at about 4x its SVM
#: group), and on rough types it buys a few hundredths of the error.
OSL_RETRO_GAIN = 0.05
#: Ridge of the ramp knots' least squares, relative to the mean diagonal of
#: each view's Gram matrix: knots few rows reach (a Phong ramp's top knots
#: at grazing views) stay near zero instead of following noise of the LUT.
OSL_RIDGE = 1e-3
#: Lights (θl, degrees) and azimuths (φ) where the variant's radiance is
#: made non-negative, at every view of every texture column's cell
#: (``osl_check_views``): the whole upper hemisphere, finer toward the
#: horizon, where the SVM closures fade as cos θl and a diffuse ramp keeps
#: its first knot (diffuse_ramp has no cos θl: its value at the horizon).
OSL_CHECK_LIGHTS = np.radians(
    np.concatenate(
        [np.arange(0.0, 75.0, 5.0), [75.0, 77.5, 80.0, 82.0, 84.0, 85.5, 87.0, 88.0, 89.0, 89.5, 89.8, 89.99]]
    )
)
OSL_CHECK_AZIMUTHS = np.radians(np.arange(0.0, 181.0, 15.0))
#: Offsets (dθl, φ) about each view's mirror direction (θl = θv, φ = 0)
#: checked as well: the SVM closures' sharp lobes fall off there faster
#: than the Phong ramps' broad ones.
OSL_CHECK_MIRROR = (
    np.radians([-10.0, -6.0, -3.0, -1.5, 0.0, 1.5, 3.0, 6.0, 10.0]),
    np.radians(np.arange(0.0, 46.0, 3.0)),
)
#: The share of the SVM closures' radiance that stays, at least, at a
#: checked geometry (the ramps may take away the rest): headroom for the
#: geometries between the checked ones.
OSL_MARGIN = 0.25
#: The most oblique view the bound is checked at (a view at 90° sees nothing).
OSL_CHECK_VIEW = np.radians(89.9)


def osl_check_views(columns: int) -> np.ndarray:
    """View cosines (columns + 1,) of the edges of the weights texture's
    cells: column j (cos θv = j/(columns - 1)) is read over the views
    between entries j and j + 1 (``nearest_column``), clipped to views up
    to ``OSL_CHECK_VIEW``.  The bound is checked at both edges of a cell:
    a column's weights are constant over it and the closures vary slowly
    across it (a cell is 1/(columns - 1) wide in cos θv: under a degree of
    θv from 20° on), which the margin (``OSL_MARGIN``) covers."""
    return np.clip((np.arange(columns + 1) - 0.5) / (columns - 1), np.cos(OSL_CHECK_VIEW), 1.0)


def osl_check_values(svm_closures, ramps, columns: int):
    """The SVM closures' and the ramps' responses where the bound is checked
    for a weights texture of ``columns`` columns: (V, R, K) and (V, R, Q) at
    the views ``osl_check_views`` and, per view, the lights
    ``OSL_CHECK_LIGHTS`` x ``OSL_CHECK_AZIMUTHS`` and those about its mirror
    (``OSL_CHECK_MIRROR``)."""
    theta_v = np.arccos(osl_check_views(columns))[:, None]
    tl, ph = (a.ravel() for a in np.meshgrid(OSL_CHECK_LIGHTS, OSL_CHECK_AZIMUTHS, indexing="ij"))
    near_l, near_ph = (a.ravel() for a in np.meshgrid(*OSL_CHECK_MIRROR, indexing="ij"))
    tl = np.concatenate(
        [np.broadcast_to(tl, (len(theta_v), tl.size)), np.clip(theta_v + near_l, 0.0, OSL_CHECK_LIGHTS[-1])], axis=1
    )
    ph = np.broadcast_to(np.concatenate([ph, near_ph]), tl.shape)
    tv = np.broadcast_to(theta_v, tl.shape)
    return tuple(closures.evaluate_all(c, tl, tv, ph) for c in (svm_closures, ramps))


def svm_check_radiance(values, weights):
    """The SVM closures' radiance (weights (K, C, N, T) at the weights
    texture's N columns) where ``values`` (``osl_check_values``) were
    evaluated, for each column at its cell's lower and upper edge: two
    arrays (N, R, T, C)."""
    svm_v = values[0]
    n_cols = weights.shape[2]
    return [_per_column(svm_v[edge : edge + n_cols], weights) for edge in range(2)]


def _per_column(values, weights):
    """Σ_k values[n, r, k]·weights[k, c, n, t] as (N, R, T, C), N views or
    texture columns: a batched matrix product per n (numpy's einsum is
    several times slower at these sizes)."""
    k_, c_, n_, t_ = weights.shape
    per = np.transpose(weights, (2, 0, 3, 1)).reshape(n_, k_, t_ * c_)
    return np.matmul(values, per).reshape(n_, values.shape[1], t_, c_)


def nonnegative_factor(values, svm, knots, margin=0.0):
    """The largest factor in [0, 1] per (column, tile, component), (N, T, C),
    by which the ramps' correction (knots (Q, C, N, T) at the weights
    texture's N columns) can be scaled so that the component's radiance,
    the SVM closures' (``svm_check_radiance``) plus the ramps', is nowhere
    negative where ``values`` (``osl_check_values``) were evaluated: at
    both edges of each column's cell (``osl_check_views``: the column's
    weights are read over the whole cell); ``margin``: the share of the SVM
    radiance that stays at a checked point, at least."""
    ramp_v = values[1]
    n_cols = knots.shape[2]
    factor = np.ones((n_cols, knots.shape[3], knots.shape[1]))
    for edge in range(2):  # each column's cell, its lower and upper edge
        corr = _per_column(ramp_v[edge : edge + n_cols], knots)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(corr < 0, (1.0 - margin) * np.maximum(svm[edge], 0.0) / -corr, np.inf)
        factor = np.minimum(factor, ratio.min(axis=1))
    return np.clip(factor, 0.0, 1.0)


def _solve_free(system, rhs, free):
    """``solve_spd`` with the unknowns outside ``free`` (a mask like rhs)
    held at 0: their rows and columns replaced by the identity's."""
    both = free[..., :, None] & free[..., None, :]
    held = np.where(free, 0.0, 1.0)[..., None] * np.eye(free.shape[-1])
    return solve_spd(np.where(both, system, 0.0) + held, np.where(free, rhs, 0.0))


def fit_osl(
    lut,
    base: Fit,
    *,
    exponents=OSL_EXPONENTS,
    retro=OSL_RETRO,
    ridge=OSL_RIDGE,
    grid=LIGHT_GRID,
    row_set="hemisphere",
    nonnegative=True,
) -> Fit:
    """The OSL variant of a Cycles fit ``base`` (``fit_lut``): its closures
    and weights unchanged, plus the knots of one diffuse ramp, one Phong
    ramp per exponent and (``retro``) a diffuse ramp about the view, kept
    where it lowers the shortfall by ``OSL_RETRO_GAIN`` and not fitted to
    the facet term (``closures.ramp_closures``) with **signed** weights,
    fitted per view, tile and component to the residual radiance the SVM
    closures leave on the rows ``row_set`` (``ROW_SETS``) by ridge least
    squares (``ridge``, ``OSL_RIDGE``).

    Bounded so that no colour renders negative radiance: the diffuse ramp's
    first knot (its value at the horizon, where the SVM closures fade) is
    held >= 0, and per column of the weights texture, tile and component
    the ramps' correction is scaled down until the component's radiance
    (SVM closures plus ramps) is non-negative over the hemisphere of lights
    at every view the column is read at (``nonnegative_factor``); a
    colour's radiance is a sum of components with non-negative amplitudes,
    so every colour of the type is non-negative there too.  The ramps are
    kept only where they bring the fit nearer its goals on the measure
    (``shortfall`` against the OSL goals, ``measure.GOALS["OSL"]``);
    otherwise the variant is ``base`` with zero ramps.  Where OSL is off, the add-on renders ``base``'s
    closures alone: exactly the SVM fit.  A dispersive type (a weight per
    channel: several tiles) keeps zero ramps: the ramps' weights texture
    packs three knots into one texel's channels (``texels``)."""
    if base.target != "CYCLES" or base.osl:
        raise ValueError(f"base must be an SVM Cycles fit, got a {base.target}{' OSL' if base.osl else ''} fit")
    ridge = float(ridge)
    if not ridge >= 0:
        raise ValueError(f"ridge must be >= 0, got {ridge!r}")
    exponents = tuple(float(e) for e in exponents)
    if any(not 0 <= e <= 1e3 for e in exponents):
        raise ValueError(f"exponents must lie in [0, 1000], got {exponents!r}")
    views = (len(base.cos_view) - 1) // VIEW_SUBDIVISION + 1
    cos_view = view_cosines(views)
    w_base = base.weights[:, :, ::VIEW_SUBDIVISION, :]  # the views the base was fitted at
    theta_v = np.arccos(np.clip(cos_view, np.cos(MAX_VIEW), 1.0))
    ramps = closures.ramp_closures(exponents, retro=bool(retro))

    if base.weights.shape[3] > 1:  # dispersive: the ramps' texels pack three knots (texels), not three tiles
        return dataclasses.replace(
            base,
            closures=list(base.closures) + ramps,
            weights=np.concatenate([base.weights, np.zeros((len(ramps), *base.weights.shape[1:]))]),
            base_key=content_key(base),
        )
    theta_l, phi, row_w = _rows(validate_row_set(row_set), theta_v, grid)
    tv = np.broadcast_to(theta_v[:, None], theta_l.shape)
    drawn = _per_column(closures.evaluate_all(base.closures, theta_l, tv, phi), w_base)  # (M, R, T, C)
    ramp = closures.evaluate_all(ramps, theta_l, tv, phi)  # (M, R, Q)
    target = lut.components(theta_l, tv, phi) * np.cos(theta_l)[..., None, None]  # (M, R, T, C)
    aw = ramp * row_w[..., None]
    gram = np.einsum("mrq,mrs->mqs", aw, aw)
    rhs = np.einsum("mrq,mrtc->mtcq", aw, (target - drawn) * row_w[..., None, None])
    scale = np.trace(gram, axis1=1, axis2=2) / len(ramps)
    lam = np.maximum(ridge * scale, 1e-12 * np.maximum(scale, 1e-300))
    system = gram + lam[:, None, None] * np.eye(len(ramps))
    system = np.broadcast_to(system[:, None, None], (*rhs.shape, len(ramps)))
    dense = view_cosines(texture_views(views))
    k_ = len(base.closures)
    basis = list(base.closures) + ramps
    model = model_radiance(lut)
    goals = measure.goals("OSL", base.mirror)
    values = osl_check_values(base.closures, ramps, len(dense)) if nonnegative else None
    svm_check = svm_check_radiance(values, resample_views(w_base, cos_view, dense)) if nonnegative else None
    (tl_m, tv_m, ph_m), _ = model
    at_model = closures.evaluate_all(basis, tl_m, tv_m, ph_m).T  # (K + Q, N): the measure's points
    is_retro = np.array([c.kind == "retro_ramp" for c in ramps])
    first_knots = np.array([c.kind == "diffuse_ramp" and c.knot == 0 for c in ramps])

    def variant(free):
        """The bounded variant with the ramp knots ``free`` (a mask like
        rhs) fitted and the others 0: (weights, whole, band, shortfall)."""
        free = free.copy()
        knots = _solve_free(system, rhs, free)  # (M, T, C, Q)
        if nonnegative:
            # The diffuse ramp's first knot is its value at the horizon, where
            # the SVM closures fade as cos θl: it must not be negative.  Where
            # the free solution makes it so, solve again with it held at 0.
            # (Holding the ramp about the view's first knot too, its value at
            # the horizon seen head-on, was measured: no better, and the
            # smooth g -0.49 paint 1.95% -> 1.96%.)
            held = free & (knots < 0) & first_knots
            if held.any():
                knots = _solve_free(system, rhs, free & ~held)
        weights = resample_views(
            np.concatenate([w_base, np.transpose(knots, (3, 2, 0, 1))], axis=0), cos_view, dense
        )  # (K + Q, C, N, T): the weights texture's columns
        if nonnegative:
            # Non-negative radiance: scale each column's correction, per tile
            # and component, by the largest factor <= 1 that keeps it so
            # everywhere the column is read (a colour is a sum of components
            # with non-negative amplitudes, so every colour is too).
            factor = nonnegative_factor(values, svm_check, weights[k_:], margin=OSL_MARGIN)
            weights[k_:] *= np.transpose(factor, (2, 0, 1))[None] * (1.0 - 1e-6)
        whole, band = measure_grams(model, basis, dense, weights, _cycles, columns=True, values=at_model)
        return weights, whole, band, shortfall(whole, band, goals)

    # The facet term is the interface's reflection about the mirror: the
    # ramp about the view (a retro-reflection lobe) is not fitted to it.
    free = np.ones(rhs.shape, dtype=bool)
    free[:, :, COMPONENTS.index("facet"), :] = ~is_retro
    weights, whole, band, short = variant(free)
    base_short = shortfall((base.residual, base.reference), (base.grazing_residual, base.grazing_reference), goals)
    if is_retro.any():
        # The ramp about the view is a fourth ramp each pixel shades: kept
        # where it brings the type nearer its goals by OSL_RETRO_GAIN than
        # the best without it (the other ramps, or the SVM fit alone).
        without = variant(free & ~is_retro)
        if short > (1.0 - OSL_RETRO_GAIN) * min(without[3], base_short):
            weights, whole, band, short = without
    if short >= base_short:
        weights[k_:] = 0.0  # the ramps do not pay: the SVM fit as it is
        whole, band = (base.residual, base.reference), (base.grazing_residual, base.grazing_reference)
    return dataclasses.replace(
        base,
        closures=basis,
        cos_view=dense,
        weights=weights,
        residual=whole[0],
        reference=whole[1],
        grazing_residual=band[0],
        grazing_reference=band[1],
        base_key=content_key(base),
    )


def _viewport_spread(kept, weights, values, *, points, mirror, n, cos_view, calibration):
    """{component: per-pixel spread (``eevee.spread_of``) of EEVEE's render
    of closures ``kept`` with ``weights`` at ``eevee.VIEWPORT_SAMPLES``} for
    the colour of that component alone (a black paint is all facet), or of
    every component at once where that is noisier (a closure serving
    several components is picked by its whole colour, which need not follow
    its contribution), on the measure's geometries ``points``, where the
    closures' responses are ``values``."""
    from . import eevee

    version = tuple(calibration) if calibration is not None else None

    def spread(amps):
        return eevee.spread_of(
            kept, weights, cos_view, mirror, n, amps, points, version, eevee.VIEWPORT_SAMPLES, values
        )

    mixed = spread(np.ones((3, len(COMPONENTS))))
    spreads = [max(spread(amps), mixed) for amps in eevee.component_colours(len(COMPONENTS))]
    return dict(zip(COMPONENTS, spreads, strict=True))


def shortfall(whole, band, goals, spreads=None) -> float:
    """How far a fit is from its goals: the largest ratio of a component's
    error to its goal, over the whole measure and its grazing band (the
    error of the type's worst colour, where that component dominates);
    below 1 every colour of the type meets both goals.  ``spreads``
    ({component: per-pixel spread}, ``_viewport_spread``): each error is
    then a pixel's whole deviation from the model, sqrt(error² + spread²)."""
    return max(goal_ratios(whole, band, goals, spreads).values(), default=0.0)


def goal_ratios(whole, band, goals, spreads=None) -> dict:
    """Each component's error over its goal, whole and over the grazing band:
    {(component, "whole" | "grazing"): ratio} (``shortfall`` is the largest);
    nil components are left out."""
    spreads = spreads or {}
    out = {}
    for part, grams, goal in (("whole", whole, goals[0]), ("grazing", band, goals[1])):
        for name, e in component_errors(*grams).items():
            if e is not None:
                out[name, part] = float(np.hypot(e, spreads.get(name, 0.0)) / goal)
    return out


def gains_everywhere(before: dict, after: dict, margin=FALLBACK_GAIN) -> bool:
    """Whether a fit's ``goal_ratios`` ``after`` improve on ``before``: no
    component's ratio rises past the larger of its old value and its goal
    (1), and their sum of squares drops by ``margin`` at least."""
    if set(after) != set(before):
        return False
    if any(after[k] > max(before[k], 1.0) for k in before):
        return False
    return sum(v * v for v in after.values()) < (1.0 - margin) * sum(v * v for v in before.values())


def _extra_rows(row_set):
    """The rows a row set (``ROW_SETS``) adds to the hemisphere's: a function
    of the views, each holding the exact mirror point of every view; None
    for the sets without them."""
    return {
        "lattice": lattice_rows,
        "mirror": mirror_rows,
        "grazing-mirror": mirror_rows,
        "grazing-cusp": functools.partial(mirror_rows, weight=CUSP_WEIGHT),
    }.get(row_set)


def _has_mirror(row_set) -> bool:
    """Whether a row set (``ROW_SETS``) holds the exact mirror point of each view."""
    return _extra_rows(row_set) is not None


def _rows(row_set, theta_v, grid):
    """The fit's rows of a row set (``ROW_SETS``): (θl, φ, weight), (M, R)."""
    rows = light_rows(theta_v, grid)
    extra = _extra_rows(row_set)
    if extra is not None:
        rows = tuple(np.concatenate([x, y], axis=1) for x, y in zip(rows, extra(theta_v), strict=True))
    theta_l, phi, weight = rows
    if row_set.startswith("grazing"):
        weight = np.where(theta_l >= measure.GRAZING, GRAZING_EMPHASIS, 1.0) * weight
    return theta_l, phi, weight


def _fit_rows(
    lut, target, evaluate, basis, theta_v, theta_l, phi, row_w, model, budget, extra_budget, exact, noise=None
):
    """Select closures and fit their weights on the given rows (``exact``:
    within the closures EEVEE sums exactly at one sample; ``noise``: for a
    converged EEVEE fit, the spread of closures and weights at the
    viewport's samples, ``_viewport_spread``: of the selection's first n
    closures, those nearest the goals with their spread counted in,
    ``shortfall``, are kept); returns
    (closures kept, weights (K, C, M, T), the measure's whole and grazing
    Gram matrices, the worst component's error on the measure)."""
    type_dict = lut.meta["type"]
    cos_view = view_cosines(len(theta_v))
    tv = np.broadcast_to(theta_v[:, None], theta_l.shape)
    comps = lut.components(theta_l, tv, phi) * (np.cos(theta_l) * row_w)[..., None, None]  # (M, R, T, C)
    m_, r_, t_, c_ = comps.shape
    a = np.stack([evaluate(c, theta_l, tv, phi) for c in basis], axis=-1) * row_w[..., None]  # (M, R, K)
    gram = np.matmul(np.swapaxes(a, 1, 2), a)  # (M, K, K); a batched product, faster than einsum here
    b = comps.reshape(m_, r_, t_ * c_)
    rhs = np.matmul(np.swapaxes(b, 1, 2), a)  # (M, P, K)
    norm = np.einsum("mrp,mrp->mp", b, b)
    # Views count by their share of the measure; views beyond its range
    # still get their weights but count less in the selection.
    norm = np.stack([norm, np.broadcast_to(view_measure(theta_v)[:, None], norm.shape)], axis=-1)
    grey = np.array([c.grey for c in basis])
    facet = COMPONENTS.index("facet")
    allowed = np.array([[not grey[k] or p % c_ == facet for k in range(len(basis))] for p in range(t_ * c_)])
    upper = np.array([c.max_weight for c in basis])
    cost = np.array([c.cost for c in basis])
    mirror = float(type_dict["slope"]) == 0.0  # a smooth interface: its mirror is a closure of its own
    target_error = TARGET_ERROR[target]["smooth" if mirror else "rough"]
    goal = 0.25 * target_error
    caps = None
    if exact:
        from . import eevee

        # EEVEE sums one diffuse normal and two reflection closures exactly
        # per pixel; beyond that it picks closures at random (noise).  A
        # smooth type's mirror is one of the two.
        caps = (np.array([eevee.is_reflection(c) for c in basis]), eevee.EXACT_REFLECTION_CLOSURES - mirror)

    def weights_of(chosen, response=evaluate):
        """NNLS weights of the chosen closures, the kept closures and their
        measure's Gram matrices (whole, grazing band; each closure's
        response at the measure's geometries from ``response``)."""
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
        return kept, weights[keep], *measure_grams(model, kept, cos_view, weights[keep], response)

    goals = measure.goals(target, mirror)

    def score(whole, band):
        return shortfall(whole, band, goals)

    if noise is not None:
        # Each closure past EEVEE's exact ones makes the render noisier: of
        # the selection's steps, keep the one whose pixels at the viewport's
        # samples are nearest the model (bias and spread together).
        chosen, _ = _select(gram, rhs, norm, allowed, upper, cost, budget + extra_budget, goal**2, caps)
        (tl, tv, ph), _ = model
        values = {}  # each chosen closure's response at the measure's geometries, computed once

        def cached(closure, *_):
            if closure not in values:
                values[closure] = evaluate(closure, tl, tv, ph)
            return values[closure]

        from . import eevee

        best = None
        for n in range(1, len(chosen) + 1):
            if eevee.sums_exactly([basis[k] for k in chosen[:n]], mirror) and n < len(chosen):
                continue  # the exact fit, made on its own, does better with as few
            fitted = weights_of(chosen[:n], cached)
            noisy = shortfall(*fitted[2:], goals, noise(*fitted[:2], [values[c] for c in fitted[0]]))
            if best is None or noisy < best[-1]:
                best = (*fitted, noisy)
        return best if best is not None else (*weights_of([], cached), float("inf"))
    chosen, shared = _select(gram, rhs, norm, allowed, upper, cost, budget, goal**2, caps)
    basis_kept, weights, whole, band = weights_of(chosen)
    if extra_budget > 0 and score(whole, band) > 1.0:
        # Some colour of this type misses a goal: select again with the
        # extra closures (from the steps both budgets take alike), and keep
        # that choice if it misses by less.
        wider, _ = _select(
            gram, rhs, norm, allowed, upper, cost, budget + extra_budget, goal**2, caps, start=chosen[:shared]
        )
        more = weights_of(wider)
        if score(*more[2:]) < score(whole, band):
            basis_kept, weights, whole, band = more
    return basis_kept, weights, whole, band, score(whole, band)


# ---------------------------------------------------------------------- files


def fit_path(
    lut_path, target="CYCLES", exact_metallic=True, calibration=None, eevee_mode=DEFAULT_EEVEE_MODE, osl=False
) -> pathlib.Path:
    """The weights file of a target beside its LUT:
    ``paintfit-cycles-f<FIT_VERSION>-<key>.exr`` (``paintfit-cycles4-…`` for
    Blender 4.2-4.5's lobes; ``paintfit-cyclesosl-…`` for the OSL variant,
    ``fit_osl``), ``paintfit-eevee-…`` (``paintfit-eevee50-…``
    when fitted with Blender 5.0's measured EEVEE responses; a converged
    EEVEE fit ends its name with ``c``: ``paintfit-eevee50c-…``)."""
    lut_path = pathlib.Path(lut_path)
    if osl and target != "CYCLES":
        raise ValueError(f"an OSL variant exists for target 'CYCLES' only, got {target!r}")
    name = closures.validate_target(target).lower() + ("" if exact_metallic else "4") + ("osl" if osl else "")
    if target == "EEVEE" and calibration is not None:
        name += "".join(str(int(v)) for v in calibration[:2])
    if target == "EEVEE" and validate_eevee_mode(eevee_mode) == "CONVERGED":
        name += "c"
    return lut_path.with_name(lut_path.name.replace("paintlut-", f"paintfit-{name}-f{FIT_VERSION}-"))


def texels(basis, rows, tiles=1) -> list:
    """The rows of a fit's weights texture, bottom to top, for closures
    ``basis`` with weight rows ``rows`` (``Fit.rows``) and ``tiles`` weights
    per view (``Fit.weights.shape[3]``).  Each texture row is a triple of
    slots, what its R, G and B channels hold: ``(k, c)`` (the weights of
    closure k, component c) or None.

    * One weight per view (``tiles`` 1): three SVM rows share a texture row,
      one per channel, so a node group reads them with one lookup (a
      twelve-closure group: 11 lookups instead of 33, its Cycles render
      5-10% faster, measured back to back).  Rows are taken in order.
    * One weight per channel (a dispersive type, ``tiles`` 3): each SVM row
      has a texture row of its own, ``((k, c),) * 3``, channel t holding
      tile t.
    * Each OSL ramp (its knots, ``closures.ramp_closures``) and component:
      three knots of the same ramp side by side, ``((k0, c), (k1, c),
      (k2, c))``, the Script node reading the whole colour, so a ramp's
      eight knots take three lookups."""
    used = set(map(tuple, rows))
    svm = [(k, c) for k, c in map(tuple, rows) if not basis[k].osl]
    if tiles > 1:
        out = [(row,) * 3 for row in svm]
    else:
        out = [_triple(svm[start : start + 3]) for start in range(0, len(svm), 3)]
    families = {}
    for k, closure in enumerate(basis):
        if closure.osl:
            families.setdefault((closure.kind, closure.exponent), []).append(k)
    for knots in families.values():
        for c in range(len(COMPONENTS)):
            for start in range(0, len(knots), 3):
                triple = _triple([(k, c) if (k, c) in used else None for k in knots[start : start + 3]])
                if any(slot is not None for slot in triple):
                    out.append(triple)
    return out


def _triple(slots) -> tuple:
    slots = tuple(slots)
    return slots + (None,) * (3 - len(slots))


def _image(fitted: Fit) -> np.ndarray:
    tiles = fitted.weights.shape[3]
    layout = texels(fitted.closures, fitted.rows, tiles)
    image = np.zeros((max(len(layout), 1), len(fitted.cos_view), 3), dtype=np.float32)
    for r, slots in enumerate(layout):
        for channel, slot in enumerate(slots):
            if slot is not None:
                image[r, :, channel] = fitted.weights[slot[0], slot[1], :, channel if tiles > 1 else 0]
    return image[::-1]  # EXR rows run top to bottom


def _hash(header_json: str, image: np.ndarray) -> str:
    h = hashlib.sha256(header_json.encode())
    h.update(np.ascontiguousarray(image, dtype="<f4").tobytes())
    return h.hexdigest()


def content_key(fitted: Fit) -> str:
    """What identifies a fit's content: the hash its weights file carries
    (its header and weights texture), the same for a fit and its file read
    back."""
    return _hash(lutfile.canonical_json(fitted.header()), _image(fitted))


def write_fit(fitted: Fit, path) -> pathlib.Path:
    """Write a fit's weights texture and header atomically: row r (counted
    from the bottom, where a Blender image has v = 0) holds at the view
    cosines the weights of the slots of ``texels(...)[r]`` in its R, G and
    B channels; the header (JSON) and a content hash let ``read_fit``
    rebuild and verify it."""
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
        for r, slots in enumerate(texels(basis, h["rows"], tiles)):
            for channel, slot in enumerate(slots):
                if slot is not None:
                    weights[slot[0], slot[1], :, channel if tiles > 1 else 0] = pixels[::-1][r, :, channel]
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
            grazing_residual=np.array(h["grazing_residual"], dtype=float),
            grazing_reference=np.array(h["grazing_reference"], dtype=float),
            eevee_mode=validate_eevee_mode(h.get("eevee_mode", "EXACT")),
            base_key=h.get("base_key", ""),
            chosen_for=tuple(float(g) for g in h["chosen_for"]) if h.get("chosen_for") is not None else None,
        )
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        if isinstance(exc, lutfile.LUTError):
            raise
        raise lutfile.LUTError(f"{path}: malformed weights header ({exc})") from None
