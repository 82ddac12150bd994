"""Volume scattering under a rough interface (paper Sec. 2.5).

The paper averages the smooth-interface models over ~5000 random pairs of
facet normals per direction pair, one normal drawn for the incident ray and one
for the scattered ray from the slope distribution as seen by that ray
(Eq. 36).  Here the same average is computed by deterministic quadrature:

* **Visible-normal rule.**  For a direction u (towards the source or the
  viewer) the facets it meets have density P(ζ) max(cos ι, 0) sec θn per
  dζx dζy (Eq. 36), normalized exactly (each ray meets one facet; the paper's
  Eq. 37 approximates the normalization by cos θ).  We integrate it with a
  product rule: in the radial slope, Gauss rules of the measure 2πζP(ζ)dζ
  split where facets start to turn away from the ray
  (``distributions.split_radial_rule``), times the periodic trapezoid rule
  (full circle) or Gauss-Legendre (the arc where cos ι > 0) in the facet
  azimuth.  The rule moves smoothly with the direction, so results are
  smooth in angle, and it is deterministic, so no seed is needed.

* **Diffuse term** (Eq. 21 under a rough interface).  The substrate is
  depolarizing and its emitted radiance is uniform, so the BRDF factors:

      f = ρ / (π n² (1 - ρ r̄)) · c(θs) r(θi)ᵀ,

  r(θ) the first row of the facet-averaged entry transmittance Mueller matrix,
  c(θ) the first column of the exit one (by reciprocity the same functions),
  r̄ = 1 - (2/n²) ∫ r₀(θ) cos θ sin θ dθ the rough interface's internal
  hemispherical reflectance for diffuse light (the n² radiance law).  With a
  smooth interface this is exactly Eqs. 22-28.

* **Single-scatter term** (Eq. 7 under a rough interface).  For entry facet a
  and exit facet b, the internal directions follow from Snell's law at each
  facet, and the smooth-interface derivation of Eq. 20 carries over:

      f = Σ_ab w_a w_b · (T_a T_b / n²) · 2p(θ_ab) / (1 + cos²θ_ab)
            / (|cos θ'_a| + |cos θ'_b|) · M(J_b V_ab J_a),

  T the facets' beam transmittance factors n cos ι'/cos ι, θ'_a, θ'_b the
  internal angles to the mean normal (depth is measured along it), J_a, J_b
  the facet transmission Jones matrices and V_ab the projection dyadic (Eq. 4)
  in the internal s/p bases.  All N_entry × N_exit pairs are used.  Pairs
  whose refracted ray would travel back towards the surface are dropped.

Neither term includes shadowing, or rays that cross the interface more than
once, as in the paper.

The paper's random-pairs average itself is kept, as a check only, in
``reference.rough_single_random``.
"""

from __future__ import annotations

import concurrent.futures
import dataclasses
import functools
import os
import threading

import numpy as np

from . import _validate, distributions, fresnel, geometry, phase, smooth
from .geometry import cross, dot
from .mueller import jones_product_m00, jones_to_mueller

#: Default (radial nodes per segment, azimuthal nodes) of the visible-normal
#: rule; see docs/models.md for the error each reaches.
DIFFUSE_NODES = (16, 16)
SINGLE_NODES = (4, 6)
#: Above DIRECT_LIMIT distinct polar angles the 1-D diffuse functions are
#: tabulated on a uniform grid of TABLE_SIZE angles and interpolated linearly
#: (error about 3e-7 relative), cached per interface.
DIRECT_LIMIT = 1025
TABLE_SIZE = 1025
#: Pairs evaluated per chunk in the single-scatter sum: small enough for the
#: temporaries to stay in cache (32k pairs measured fastest on 2 cores).
CHUNK_PAIRS = 1 << 15


def visible_normals(theta, slope: float, distribution: str, nodes):
    """Visible-normal quadrature rule for directions u = (sin θ, 0, cos θ).

    A facet with slope ζ at azimuth φ (from u's azimuth) faces u where
    cos θ + ζ sin θ cos φ > 0, i.e. for every φ while ζ < cot θ and on an arc
    |φ| < arccos(-cot θ / ζ) beyond.  The radial integral is split at
    ζ = cot θ, or nearer the middle of the facets when that lies far in the
    tail (``distributions.split_radial_rule``, which has the Gauss rule of
    each piece): inside, the azimuth runs over the whole circle (periodic
    trapezoid rule, spectrally accurate); outside, over the visible arc
    (Gauss-Legendre).  Each facet's weight is
    its share of the projected area, max(cos ι, 0) sec θn (Eq. 36), and the
    weights are normalized to sum to 1.

    ``nodes`` = (radial nodes per segment, azimuthal nodes).  Returns (h, w):
    facet normals (..., M, 3) and weights (..., M), M = 2 · nodes[0] · nodes[1];
    the weights are 0 for θ >= π/2."""
    n_zeta, n_phi = nodes
    theta = np.asarray(theta, dtype=float)
    cos_t = np.cos(theta)
    sin_t = np.sin(theta)
    with np.errstate(divide="ignore"):
        # Directions at or below the horizon see facets only on arcs (and get
        # zero weight below); keep the split point at ζ >= 0.
        zeta_c = np.where(sin_t > 0.0, np.clip(cos_t, 0.0, None) / np.where(sin_t > 0.0, sin_t, 1.0), np.inf)
    t_c = distributions.radial_variable(zeta_c, slope, distribution)
    zeta, w_zeta = distributions.split_radial_rule(t_c, slope, distribution, n_zeta)
    cos_t, sin_t = cos_t[..., None], sin_t[..., None]
    reach = zeta * sin_t
    clipped = reach > cos_t
    ratio = -cos_t / np.where(clipped & (reach > 0.0), reach, 1.0)
    half = np.where(clipped, np.arccos(np.clip(ratio, -1.0, 1.0)), np.pi)
    x, w_x = np.polynomial.legendre.leggauss(n_phi)
    trap = (2.0 * np.arange(n_phi) + 1.0) / n_phi - 1.0  # periodic trapezoid on [-1, 1)
    # The rule follows the radial piece, not the node's own visibility: the
    # outer piece can begin before ζ = cot θ (where that lies beyond the
    # split cap), and its nodes' arcs must shrink continuously from π as θ
    # grows, so they always use Gauss-Legendre.
    outer = (np.arange(2 * n_zeta) >= n_zeta)[:, None]
    unit = np.where(outer, x, trap)
    w_unit = np.where(outer, w_x, 2.0 / n_phi)
    phi = half[..., None] * unit
    w_phi = half[..., None] * w_unit / (2.0 * np.pi)
    zeta_ = zeta[..., None]
    proj = np.clip(cos_t[..., None] + zeta_ * sin_t[..., None] * np.cos(phi), 0.0, None)
    w = (w_zeta[..., None] * w_phi * proj).reshape(theta.shape + (-1,))
    total = w.sum(axis=-1, keepdims=True)
    w = np.where(total > 0.0, w / np.where(total > 0.0, total, 1.0), 0.0)
    norm = np.sqrt(1.0 + zeta_ * zeta_)
    zeta_b = np.broadcast_to(zeta_, phi.shape)
    h = np.stack(
        (zeta_b * np.cos(phi) / norm, zeta_b * np.sin(phi) / norm, np.broadcast_to(1.0 / norm, phi.shape)),
        axis=-1,
    ).reshape(theta.shape + (-1, 3))
    return h, w


@dataclasses.dataclass(frozen=True)
class FacetState:
    """The rays that cross the interface through the facets visible from one
    external direction, for each polar angle θ of a batch (shape S) and each
    of the M nodes of the visible-normal rule: what ``facet_states`` returns.

    Vectors are unit vectors in the mean-surface frame (z along the mean
    normal, out of the binder; x towards azimuth 0); every quantity is
    dimensionless.  An entering ray comes from the source (azimuth π) and
    refracts into the binder; an exiting one leaves the binder towards the
    viewer at azimuth 0 (turn it about z for other azimuths)."""

    #: (S, M, 3) facet unit normal, z component > 0 (mirrored to the source's
    #: side on entry).
    h: np.ndarray
    #: (S, M) quadrature weight of the facet: its share of the area projected
    #: along the ray, P(ζ) max(cos ι, 0) sec θn (Eq. 36), normalized to sum 1
    #: over M; all 0 for θ >= π/2.
    w: np.ndarray
    #: (S, M, 3) external propagation direction: k_i (towards the surface) on
    #: entry, k_s (away from it) on exit; the same for every facet.
    k: np.ndarray
    #: (S, M, 3) internal propagation direction from Snell's law at the facet
    #: (Eq. 30): into the binder on entry; on exit the internal ray that
    #: leaves through the facet along k.
    k_in: np.ndarray
    #: (S, M) Fresnel amplitude transmission coefficients for s and p light
    #: from air at the facet's local angle ι (Eqs. 10, 11; on exit the
    #: air-side ones, by reciprocity, Eq. 25); 0 where the facet is not met.
    t_s: np.ndarray
    t_p: np.ndarray
    #: (S, M) beam factor n cos ι'/cos ι of the crossing (Eqs. 24, 42): the
    #: Mueller transmittance is beam · M(diag(t_s, t_p)); 0 under total
    #: internal reflection or where the facet is not met.
    beam: np.ndarray


def facet_states(theta, n, slope, distribution, nodes, entering) -> FacetState:
    """Rays crossing the interface through the facets visible from a
    direction at polar angle θ: entering the binder from the source
    (k_i, azimuth π) or, with ``entering=False``, leaving it towards the
    viewer (k_s at azimuth 0; rotate for other azimuths).

    The facets and their weights are the visible-normal rule (Eq. 36,
    ``visible_normals``); the internal ray is Snell's law at each facet
    (Eq. 30).  By reciprocity the exit is the entry of the reversed ray: the
    internal ray is minus the refraction of -k_s, and the coefficients are
    the air-side ones (paper Eqs. 11, 25).  See ``FacetState`` for the
    arrays returned."""
    h, w = visible_normals(theta, slope, distribution, nodes)
    u = geometry.scattered(theta, 0.0)[..., None, :]  # towards the viewer or the source
    if entering:
        mirror = np.array([-1.0, 1.0, 1.0])  # the source sits at azimuth π
        h, u = h * mirror, u * mirror
    cos_i = np.clip(dot(u, h), 0.0, 1.0)
    k_down, cos_t, ok = geometry.refract(-u, h, n, cos_i)
    t_s, t_p, _ = fresnel.transmission_coefficients(cos_i, n)
    beam = np.where(ok & (cos_i > 0.0), n * cos_t / np.where(cos_i > 0, cos_i, 1.0), 0.0)
    k = np.broadcast_to(-u if entering else u, h.shape)
    return FacetState(h=h, w=w, k=k, k_in=k_down if entering else -k_down, t_s=t_s, t_p=t_p, beam=beam)


# --------------------------------------------------------------------------- diffuse


def _transmittance_rows(theta, n, slope, distribution, nodes):
    """Facet-averaged first row of the entry transmittance Mueller matrix
    (= first column of the exit one), shape (..., 4): Σ w · beam · M(J)[0, :]
    over the facets, J the facet's transmission Jones matrix between the
    global s/p bases of the external and the internal ray (Eq. 40), beam the
    factor of Eq. 42 (the rough counterpart of Eq. 24)."""
    facets = facet_states(theta, n, slope, distribution, nodes, entering=True)
    basis_a = geometry.sp_basis(facets.k)
    basis_b = geometry.sp_basis(facets.k_in)
    jones = geometry.interface_jones(facets.k, facets.k_in, facets.h, facets.t_s, facets.t_p, basis_a, basis_b)
    m = jones_to_mueller(jones)[..., 0, :]
    return np.sum((facets.w * facets.beam)[..., None] * m, axis=-2)


@functools.lru_cache(maxsize=64)
def rough_internal_reflectance(n: float, slope: float, distribution: str, nodes=DIFFUSE_NODES, theta_nodes=96):
    """Internal hemispherical reflectance r̄ of the rough interface for
    diffuse light inside the binder (the rough counterpart of Eq. 22):
    r̄ = 1 - (2/n²) ∫₀^{π/2} τ(θ) cos θ sin θ dθ, τ the facet-averaged
    transmittance from air, by reciprocity and the n² radiance law."""
    x, w = np.polynomial.legendre.leggauss(theta_nodes)
    theta = 0.25 * np.pi * (x + 1.0)
    tau = _transmittance_rows(theta, n, slope, distribution, nodes)[..., 0]
    integral = np.sum(0.25 * np.pi * w * tau * np.cos(theta) * np.sin(theta))
    return float(1.0 - 2.0 * integral / (n * n))


#: Held while a transmittance row table is made: threads evaluating one
#: paint type at once (a LUT bake's chunks) wait for the first one's table
#: instead of each making it again.
_ROW_TABLE_LOCK = threading.Lock()


def _row_table(n, slope, distribution, nodes, size):
    """The transmittance rows on a uniform grid of ``size`` polar angles over
    [0, π/2], cached per interface (read-only arrays), made once whichever
    thread asks first."""
    with _ROW_TABLE_LOCK:
        return _row_table_cached(n, slope, distribution, nodes, size)


@functools.lru_cache(maxsize=16)
def _row_table_cached(n, slope, distribution, nodes, size):
    grid = np.linspace(0.0, np.pi / 2, size)
    # The angles are independent (numpy releases the interpreter lock in
    # the facet arithmetic): split over the cores, at most four.
    parts = np.array_split(grid, max(1, min(4, os.cpu_count() or 1, size)))
    with concurrent.futures.ThreadPoolExecutor(max_workers=len(parts), thread_name_prefix="paint-lut-rows") as pool:
        rows = list(pool.map(lambda part: _transmittance_rows(part, n, slope, distribution, nodes), parts))
    table = np.concatenate(rows, axis=0)
    grid.setflags(write=False)
    table.setflags(write=False)
    return grid, table


def _rows_at(theta, n, slope, distribution, nodes):
    """Transmittance rows at arbitrary polar angles: computed at the distinct
    values, or interpolated from a fine cached table when there are many."""
    flat = theta.ravel()
    uniq, inverse = np.unique(flat, return_inverse=True)
    if uniq.size <= DIRECT_LIMIT:
        rows = _transmittance_rows(uniq, n, slope, distribution, nodes)[inverse]
    else:
        grid, table = _row_table(n, slope, distribution, nodes, TABLE_SIZE)
        rows = np.stack([np.interp(flat, grid, table[:, c]) for c in range(4)], axis=-1)
    rows = np.where((flat < np.pi / 2)[:, None], rows, 0.0)
    return rows.reshape(theta.shape + (4,))


def _interface(n, slope, distribution, nodes):
    """Validated parameters of the rough interface and its quadrature."""
    return (
        _validate.index(n),
        _validate.rms_slope(slope),
        _validate.distribution(distribution),
        _validate.nodes(nodes),
    )


def rough_diffuse(
    theta_i, theta_s, phi_s, *, n, rho, slope, distribution="gaussian", mueller=True, nodes=DIFFUSE_NODES
):
    """Mueller BRDF [sr⁻¹] of a totally diffuse substrate (reflectance rho)
    under a rough interface (paper Sec. 2.5 with Eq. 21; see the module
    docstring for the factorization and its derivation).

    Parameters: angles in radians; n (> 0); rho in [0, 1]; slope the total
    RMS slope (>= 0; 0 gives ``smooth_diffuse``); distribution 'gaussian' |
    'exponential'; nodes the (radial, azimuthal) sizes of the visible-normal
    rule.  Returns broadcast(angles) + (4, 4), or M00 with ``mueller=False``.
    The result does not depend on phi_s."""
    n, slope, distribution, nodes = _interface(n, slope, distribution, nodes)
    rho = _validate.reflectance(rho)
    ti, ts, ps = _validate.angles(theta_i, theta_s, phi_s)
    if slope == 0.0:
        return smooth.smooth_diffuse(ti, ts, ps, n=n, rho=rho, mueller=mueller)
    rbar = rough_internal_reflectance(n, slope, distribution, nodes)
    k = rho / (np.pi * n * n * (1.0 - rho * rbar))
    row = _rows_at(ti, n, slope, distribution, nodes)
    col = _rows_at(ts, n, slope, distribution, nodes)
    if not mueller:
        return k * col[..., 0] * row[..., 0]
    # The exit column is the reciprocal of the entry row: equal I and Q parts;
    # U and V vanish by the mirror symmetry of the visible facets.
    return k * col[..., :, None] * row[..., None, :]


# --------------------------------------------------------------------------- single


def local_basis(k_ext, k_int, h):
    """Local s vector of the facet and the p vectors of the external and the
    internal ray (paper Eq. 40): s' = k×h/|k×h|, p' = k×s'.  The s vector
    falls back to the global one at normal incidence on the facet, where the
    choice does not matter."""
    s_glob, _ = geometry.sp_basis(k_ext)
    s_loc, _ = geometry.unit_or(cross(k_ext, h), s_glob)
    return s_loc, cross(k_ext, s_loc), cross(k_int, s_loc)


def _rotate_z(v, cos_p, sin_p):
    """Vectors v (..., 3) turned about z by the angle with cosine ``cos_p``
    and sine ``sin_p``."""
    x, y = v[..., 0], v[..., 1]
    return np.stack((x * cos_p - y * sin_p, x * sin_p + y * cos_p, v[..., 2]), axis=-1)


@dataclasses.dataclass(frozen=True)
class ScatterLeg:
    """One leg of the single-scatter sum, entry or exit: per facet of the
    visible-normal rule, what the pair sum needs.  Built by ``_scatter_leg``
    from a ``FacetState``; shapes (S, M) for S polar angles and M facets,
    with a trailing (3,) for vectors (mean-surface frame, unit, as in
    ``FacetState``) and (2, 2) for the Jones matrix.  Dimensionless."""

    #: Facet weight times beam factor, w · n cos ι'/cos ι (Eqs. 36, 42); 0 for
    #: rays whose internal direction does not head into (entry) or out of
    #: (exit) the bulk.
    weight: np.ndarray
    #: |cos θ'| of the internal ray to the mean normal: depth is measured
    #: along it, as cos θ'i and cos θ'r in Eqs. 18-19.
    depth: np.ndarray
    #: Internal propagation direction (``FacetState.k_in``).
    k_in: np.ndarray
    #: The facet's local s vector, k×h/|k×h| (Eq. 40).
    s: np.ndarray
    #: The internal ray's local p vector, k_in×s (Eq. 40).
    p: np.ndarray
    #: Air-side Fresnel amplitude transmission coefficients (``FacetState``).
    t_s: np.ndarray
    t_p: np.ndarray
    #: Jones matrix of the crossing between the external ray's global s/p
    #: basis and the facet's internal local one (s, p): Eq. 40 without its
    #: rotation out of the local basis, A = diag(t_s, t_p)·R on entry; on
    #: exit its transpose B = Rᵀ·diag(t_s, t_p).
    jones: np.ndarray

    def take(self, index) -> ScatterLeg:
        """The legs at the angle indices ``index`` (C,): shapes (C, M, ...)."""
        return ScatterLeg(**{f.name: getattr(self, f.name)[index] for f in dataclasses.fields(self)})

    def rotated(self, cos_p, sin_p) -> ScatterLeg:
        """The leg turned about the mean normal by φ (cosine and sine of
        shape (C, 1)).  The Jones matrix is unchanged: the exit ray's global
        basis turns rigidly with the facets, at θs = 0 as well (the limit
        along φs, as for every model; docs/models.md, Conventions)."""
        return dataclasses.replace(
            self,
            k_in=_rotate_z(self.k_in, cos_p, sin_p),
            s=_rotate_z(self.s, cos_p, sin_p),
            p=_rotate_z(self.p, cos_p, sin_p),
        )


def rough_single(theta_i, theta_s, phi_s, *, n, g, slope, distribution="gaussian", mueller=True, nodes=SINGLE_NODES):
    """Mueller BRDF [sr⁻¹] of single volume scattering with the polarimetric
    Henyey-Greenstein phase function (Eq. 7) under a rough interface (paper
    Sec. 2.5; see the module docstring).

    Parameters: angles in radians; n (> 0); g in (-1, 1); slope (>= 0; 0
    gives ``smooth_single``); distribution; nodes the (radial, azimuthal)
    sizes of the visible-normal rule used for both the entry and the exit
    facets (all pairs are summed).  Returns broadcast(angles) + (4, 4), or M00
    with ``mueller=False``."""
    n, slope, distribution, nodes = _interface(n, slope, distribution, nodes)
    g = _validate.asymmetry(g)
    ti, ts, ps = _validate.angles(theta_i, theta_s, phi_s)
    if slope == 0.0:
        return smooth.smooth_single(ti, ts, ps, n=n, g=g, mueller=mueller)
    return _single_sum(ti, ts, ps, n, g, slope, distribution, nodes, nodes, mueller)


def _single_sum(ti, ts, ps, n, g, slope, distribution, nodes_in, nodes_out, mueller):
    """The single-scatter sum of the module docstring over all entry × exit
    facet pairs, for flat or broadcast angle arrays (validated, same shape).
    Evaluated in chunks of direction pairs (``CHUNK_PAIRS`` facet pairs)."""
    shape = ti.shape
    ti, ts, ps = ti.ravel(), ts.ravel(), ps.ravel()

    # Computing the entry facets at the distinct incident angles and the exit
    # facets at the distinct scattering angles (at φs = 0).
    ui, inv_i = np.unique(ti, return_inverse=True)
    us, inv_s = np.unique(ts, return_inverse=True)
    entry = _scatter_leg(ui, n, slope, distribution, nodes_in, entering=True)
    exit_ = _scatter_leg(us, n, slope, distribution, nodes_out, entering=False)

    out = np.zeros(ti.shape + ((4, 4) if mueller else ()))
    chunk = max(1, CHUNK_PAIRS // (entry.weight.shape[-1] * exit_.weight.shape[-1]))
    for start in range(0, ti.size, chunk):
        sl = slice(start, start + chunk)
        # Gathering the legs of each direction pair, the exit turned to φs.
        a = entry.take(inv_i[sl])
        b = exit_.take(inv_s[sl]).rotated(np.cos(ps[sl])[:, None], np.sin(ps[sl])[:, None])

        # Computing the scattering angle and the projection dyadic of every
        # facet pair.
        cos_sc, v = _pair_geometry(a, b)

        # Computing the scalar weight of every facet pair.
        weight = _pair_weights(a, b, cos_sc, g, n)

        # Computing the Mueller matrix (or its M00) of every facet pair and
        # summing over the pairs.
        if mueller:
            out[sl] = np.sum(weight[..., None, None] * _pair_mueller(a, b, v), axis=(1, 2))
        else:
            out[sl] = np.sum(weight * _pair_m00(a, b, v), axis=(1, 2))

    # No light reaches or leaves the binder at or below the horizon.
    lit = (ti < np.pi / 2) & (ts < np.pi / 2)
    out[~lit] = 0.0
    return out.reshape(shape + ((4, 4) if mueller else ()))


def _scatter_leg(theta, n, slope, distribution, nodes, entering) -> ScatterLeg:
    """The entry (or, with ``entering=False``, exit) leg at polar angles θ:
    the facets of ``facet_states``, their local s/p vectors (Eq. 40), the
    depth cosines of Eq. 19, and the Jones matrix of each crossing between
    the ray's global s/p basis and the facet's internal one (Eq. 40 with the
    Fresnel coefficients of Eq. 10, or Eq. 11 by reciprocity on exit)."""
    facets = facet_states(theta, n, slope, distribution, nodes, entering)
    s_loc, _, p_int = local_basis(facets.k, facets.k_in, facets.h)
    heading = facets.k_in[..., 2] < 0.0 if entering else facets.k_in[..., 2] > 0.0
    # The crossing seen from the global s/p basis of k into the facet's own
    # internal basis (R_out = identity): diag(t_s, t_p)·R.
    jones = geometry.interface_jones(
        facets.k, facets.k_in, facets.h, facets.t_s, facets.t_p, geometry.sp_basis(facets.k), (s_loc, p_int)
    )
    return ScatterLeg(
        weight=np.where(heading, facets.w * facets.beam, 0.0),
        depth=np.abs(facets.k_in[..., 2]),
        k_in=facets.k_in,
        s=s_loc,
        p=p_int,
        t_s=facets.t_s,
        t_p=facets.t_p,
        # Computed at φs = 0; the exit's global basis turns rigidly with the
        # azimuth (``ScatterLeg.rotated``).
        jones=jones if entering else np.swapaxes(jones, -1, -2),
    )


def _pair_geometry(a: ScatterLeg, b: ScatterLeg):
    """Every entry facet a against every exit facet b, from their internal
    vectors: cos θ_ab = k'_a·k'_b, the cosine of the scattering angle of the
    phase function (Eqs. 2, 7), and V_ab, the projection dyadic of Eq. 4
    between the facets' internal local s/p vectors (as in Eq. 13): V_jk =
    e_b,j · (σ₂σ₂ + π₂π₂) · e_a,k = e_b,j · e_a,k, since e_b,j ⊥ k'_b lies in
    the span of σ₂ and π₂.  Returns cos θ (C, M, N) and ((V_ss, V_sp),
    (V_ps, V_pp)), rows (s_b, p_b), columns (s_a, p_a)."""
    m_in, m_out = a.weight.shape[-1], b.weight.shape[-1]
    # All pairwise dot products in one batched matrix product.
    left = np.concatenate((a.k_in, a.s, a.p), axis=1)  # (C, 3M, 3)
    right = np.concatenate((b.k_in, b.s, b.p), axis=1)  # (C, 3N, 3)
    d = np.matmul(left, right.transpose(0, 2, 1)).reshape(-1, 3, m_in, 3, m_out)
    cos_sc = np.clip(d[:, 0, :, 0, :], -1.0, 1.0)
    v_ss, v_sp = d[:, 1, :, 1, :], d[:, 2, :, 1, :]
    v_ps, v_pp = d[:, 1, :, 2, :], d[:, 2, :, 2, :]
    return cos_sc, ((v_ss, v_sp), (v_ps, v_pp))


def _pair_weights(a: ScatterLeg, b: ScatterLeg, cos_sc, g, n):
    """The scalar factor of every pair (C, M, N), Eq. 20 written with the
    beam factors T = n cos θ'/cos θ of Eqs. 24-25 (T_a T_b / n² =
    cos θ'i cos θ'r / (cos θi cos θr)) and taken facet by facet:

        w_a w_b · (T_a T_b / n²) · 2p(θ_ab) / (1 + cos²θ_ab) / (|cos θ'_a| + |cos θ'_b|),

    the phase factor 2p/(1 + cos²θ) of Eq. 7 and the depth integral
    1/(cos θ'i + cos θ'r) of Eq. 19."""
    depth = a.depth[:, :, None] + b.depth[:, None, :]
    # Eq. 19: 1/(cos θ'1 + cos θ'2); both cosines vanish only for grazing
    # internal rays, whose weights are already zero.
    inv_depth = np.divide(1.0, depth, out=np.zeros_like(depth), where=depth > 0.0)
    return a.weight[:, :, None] * b.weight[:, None, :] * phase.rayleigh_factor(cos_sc, g) * inv_depth / (n * n)


def _pair_m00(a: ScatterLeg, b: ScatterLeg, v):
    """M00 of M(J_b V_ab J_a) for every pair (C, M, N) (Eqs. 13-14): the
    rotations of J_a and J_b into the global bases leave M00 unchanged, so
    only the facets' Fresnel coefficients enter (``jones_product_m00``)."""
    return jones_product_m00(
        (b.t_s[:, None, :], b.t_p[:, None, :]),
        v,
        (a.t_s[:, :, None], a.t_p[:, :, None]),
    )


def _pair_mueller(a: ScatterLeg, b: ScatterLeg, v):
    """M(J_b V_ab J_a) for every pair (C, M, N, 4, 4): the Mueller matrix of
    the net Jones matrix in the global s/p bases of the incident and the
    scattered ray (Eqs. 12-14, with the facet crossings of Eq. 40)."""
    (v_ss, v_sp), (v_ps, v_pp) = v
    v_matrix = np.stack((np.stack((v_ss, v_sp), -1), np.stack((v_ps, v_pp), -1)), -2)
    jones = np.matmul(np.matmul(b.jones[:, None, :, :, :], v_matrix), a.jones[:, :, None, :, :])
    return jones_to_mueller(jones)
