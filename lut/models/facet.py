"""Facet (geometric-optics) scattering by the exposed rough interface, in
reflection and in transmission (paper Sec. 2.4, Eqs. 29-43; SCATMECH's
``Facet_BRDF_Model``).  No shadowing or obscuration, as in the paper."""

from __future__ import annotations

import numpy as np

from . import _validate, distributions, fresnel, geometry
from .geometry import dot
from .mueller import jones_to_mueller


def _mirror_normal(k_in, k_out):
    """Facet normal that reflects k_in into k_out: (k_out - k_in)/|k_out - k_in|."""
    h, norm = geometry.unit_or(k_out - k_in, np.array([0.0, 0.0, 1.0]))
    return h, norm


def _slope_density(h, slope, distribution):
    """P(ζ)/h_z⁴ = P(ζ) sec⁴θn for facet normals h with h_z > 0 (paper Eq. 38
    times Eq. 29); zero where h_z <= 0."""
    hz = h[..., 2]
    up = hz > 0.0
    hz_safe = np.where(up, hz, 1.0)
    zeta = np.sqrt(h[..., 0] ** 2 + h[..., 1] ** 2) / hz_safe
    return np.where(up, distributions.pdf(zeta, slope, distribution) / hz_safe**4, 0.0)


def facet_reflection(theta_i, theta_s, phi_s, *, n, slope, distribution="gaussian", mueller=True):
    """Mueller BRDF [sr⁻¹] of specular reflection from facets of an isotropic
    rough surface (paper Sec. 2.4 and refs. 13, 19, 20):

        f = P(ζ) / (4 cos θi cos θs cos⁴θn) · M(J_r),

    with the facet normal n̂ ∝ k_s - k_i, ζ its slope (Eq. 35) and J_r the
    Fresnel reflection Jones matrix at the local angle ι (Eq. 33), rotated
    from the facet's s/p basis into the global ones.  The cos ι normalisation
    of Eq. 37 cancels against the Jacobian 1/(4 cos ι) of the mirror map.

    Parameters: angles in radians (broadcast); n binder index (> 0); slope the
    total RMS slope s (> 0); distribution 'gaussian' | 'exponential'.
    Returns shape broadcast(angles) + (4, 4), or M00 alone (shape of the angles)
    with ``mueller=False``.  Directions at or below the horizon give zero."""
    n = _validate.index(n)
    slope = _validate.rms_slope(slope)
    distribution = _validate.distribution(distribution)
    ti, ts, ps = _validate.angles(theta_i, theta_s, phi_s)
    if slope == 0.0:
        raise ValueError("slope must be > 0 for facet_reflection (slope 0 is a mirror: a delta)")

    k_i = geometry.incident(ti)
    k_s = geometry.scattered(ts, ps)
    h, _ = _mirror_normal(k_i, k_s)
    cos_iota = np.clip(dot(k_s, h), 0.0, 1.0)
    cos_ti, cos_ts = np.cos(ti), np.cos(ts)
    visible = (ti < np.pi / 2) & (ts < np.pi / 2) & (h[..., 2] > 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = np.where(
            visible,
            _slope_density(h, slope, distribution) / (4.0 * cos_ti * cos_ts),
            0.0,
        )
    rs, rp = fresnel.reflection_coefficients(cos_iota, n)
    if not mueller:
        return scale * 0.5 * (np.abs(rs) ** 2 + np.abs(rp) ** 2)
    jones = geometry.interface_jones(k_i, k_s, h, rs, rp, geometry.sp_basis(k_i), geometry.sp_basis(k_s))
    return scale[..., None, None] * jones_to_mueller(jones)


def transmission_normal(k_i, k_t, n):
    """Facet normal refracting k_i into k_t (paper Eqs. 31-32): n̂ ∝ k_i - n k_t,
    signed so that n̂_z >= 0.  Returns (n̂, D) with D = |k_i - n k_t|."""
    v = k_i - n * k_t
    sign = np.where(v[..., 2] < 0.0, -1.0, 1.0)
    h, d = geometry.unit_or(v * sign[..., None], np.array([0.0, 0.0, 1.0]))
    return h, d


def facet_transmission(theta_i, theta_t, phi_t, *, n, slope, distribution="gaussian", mueller=True):
    """Mueller BTDF [sr⁻¹] of refraction into the binder through the facets of
    an isotropic rough surface, paper Eq. 43:

        f = (dΩn/dΩt) · n cos ι_t sec⁴θn / (cos θt cos θi) · P(ζ) · M(J_facet),

    with n̂ from Eq. 31, ι_i and ι_t from Eqs. 33-34 (both must lie in
    [0, π/2], else zero), J_facet the Fresnel transmission Jones matrix at ι_i
    in the global s/p bases (Eqs. 40-41), and the Jacobian of Eq. 39 in the
    equivalent, better conditioned form dΩn/dΩt = n² cos ι_t / D² (D of Eq. 32;
    tests check the two agree).  θt is measured from the inward normal and
    φt = 0 is the regular refraction side.

    Parameters and return as for ``facet_reflection``.  At D = 0 (n = 1 in the
    forward direction, where the BTDF is a delta) the value is 0."""
    n = _validate.index(n)
    slope = _validate.rms_slope(slope)
    distribution = _validate.distribution(distribution)
    ti, tt, pt = _validate.angles(theta_i, theta_t, phi_t, ("theta_i", "theta_t", "phi_t"))
    if slope == 0.0:
        raise ValueError("slope must be > 0 for facet_transmission (slope 0 is a delta)")

    k_i = geometry.incident(ti)
    k_t = geometry.transmitted(tt, pt)
    h, d = transmission_normal(k_i, k_t, n)
    cos_ii = -dot(k_i, h)
    cos_it = -dot(k_t, h)
    ok = (ti < np.pi / 2) & (tt < np.pi / 2) & (cos_ii >= 0.0) & (cos_it >= 0.0)
    ok &= (d > geometry.PARALLEL_EPS) & (h[..., 2] > 0.0)
    cos_ii = np.clip(cos_ii, 0.0, 1.0)
    ts_, tp_, _ = fresnel.transmission_coefficients(cos_ii, n)
    with np.errstate(divide="ignore", invalid="ignore"):
        jac = n * n * cos_it / (d * d)
        scale = np.where(
            ok,
            jac * n * cos_it / (np.cos(tt) * np.cos(ti)) * _slope_density(h, slope, distribution),
            0.0,
        )
    if not mueller:
        return scale * 0.5 * (ts_ * ts_ + tp_ * tp_)
    jones = geometry.interface_jones(k_i, k_t, h, ts_, tp_, geometry.sp_basis(k_i), geometry.sp_basis(k_t))
    return scale[..., None, None] * jones_to_mueller(jones)
