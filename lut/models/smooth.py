"""Volume scattering under a smooth interface (paper Secs. 2.2 and 2.3)."""

from __future__ import annotations

import numpy as np

from . import _validate, _vectorize, fresnel, phase
from .mueller import jones_product_m00, jones_to_mueller


def _refracted_cosines(cos_i, sin_i, up_i, cos_s, sin_s, up_s, n):
    """cos θ' inside the binder for the incident and scattered directions
    (Snell, Eq. 9), the air-side transmission coefficients, and the mask of
    directions that cross the interface."""
    ts_i, tp_i, cos_ip = fresnel.transmission_coefficients(cos_i, n)
    ts_s, tp_s, cos_sp = fresnel.transmission_coefficients(cos_s, n)
    # Light crosses only where the refracted ray exists and leaves the plane:
    # above the horizon, below the critical angle (n < 1), and cos θ' > 0
    # (which fails in floating point for n -> 1 within ~1e-12 of grazing).
    ok = up_i & up_s & (cos_ip > 0.0) & (cos_sp > 0.0)
    if n < 1.0:
        ok &= (sin_i < n) & (sin_s < n)
    return cos_ip, cos_sp, (ts_i, tp_i), (ts_s, tp_s), ok


def smooth_diffuse(theta_i, theta_s, phi_s, *, n, rho, mueller=True):
    """Mueller BRDF [sr⁻¹] of a totally diffuse (Lambertian, depolarizing)
    substrate of reflectance rho under a smooth interface, paper Eqs. 27-28:

        f = M_diff · (ρ/π) / (1 - ρ r̄) · cos θ's cos θ'i / (cos θs cos θi),

    M_diff built from the air-side transmission coefficients at θi and θs, and
    r̄ the internal hemispherical reflectance of Eq. 22 (``internal_reflectance``,
    computed exactly; SCATMECH's ``Diffuse_Subsurface_BRDF_Model`` sums it in
    0.2° steps, up to 5e-4 relative away).  The result does not depend on
    phi_s (it is accepted for a uniform signature).

    Parameters: angles in radians; n binder index (> 0); rho in [0, 1].
    Returns broadcast(angles) + (4, 4), or M00 alone with ``mueller=False``."""
    n = _validate.index(n)
    rho = _validate.reflectance(rho)
    ti, ts, ps = _validate.angles(theta_i, theta_s, phi_s, broadcast=False)
    factor = rho / np.pi / (1.0 - rho * fresnel.internal_reflectance(n))
    # Eq. 27 is a product of an entry factor of θi and an exit factor of θs:
    # evaluate each on its own array and broadcast the product.
    a_i, b_i = _transmittance_factors(ti, n)
    a_s, b_s = _transmittance_factors(ts, n)
    shape = np.broadcast_shapes(ti.shape, ts.shape, ps.shape)
    if not mueller:
        return np.broadcast_to(factor * a_s * a_i, shape).copy()
    m = np.zeros(shape + (4, 4))
    m[..., 0, 0] = factor * a_s * a_i
    m[..., 0, 1] = factor * a_s * b_i
    m[..., 1, 0] = factor * b_s * a_i
    m[..., 1, 1] = factor * b_s * b_i
    return m


def _transmittance_factors(theta, n):
    """Per-direction factors of Eqs. 27-28: cos θ'/cos θ · (|t_s|² ± |t_p|²)/2,
    zero where no light crosses (at or below the horizon, total reflection)."""
    cos_t, sin_t = _vectorize.cos_sin_polar(theta)
    t_s, t_p, cos_in = fresnel.transmission_coefficients(cos_t, n)
    ok = (theta < np.pi / 2) & (cos_in > 0.0)
    if n < 1.0:
        ok &= sin_t < n
    scale = np.where(ok, cos_in / np.where(ok, cos_t, 1.0), 0.0)
    return 0.5 * scale * (t_s * t_s + t_p * t_p), 0.5 * scale * (t_s * t_s - t_p * t_p)


def smooth_single(theta_i, theta_s, phi_s, *, n, g, mueller=True):
    """Mueller BRDF [sr⁻¹] of single volume scattering under a smooth
    interface with the polarimetric Henyey-Greenstein phase function, paper
    Eq. 20:

        f = 2 p(θ) cos θ'i cos θ's / [cos θi cos θs (cos θ'i + cos θ's)(1 + cos²θ)]
            · M(q_vol),

    where θ is the scattering angle inside the binder and q_vol (Eq. 13) is the
    Jones matrix diag(t_rs, t_rp) · V · diag(t_is, t_ip), V holding the dot
    products of the internal s/p vectors: the projection dyadic of Eq. 4 seen
    in the s/p bases.  This form needs no σ/π basis (Eq. 3), so the forward
    and backward directions (k1×k2 = 0) are regular.  With p = k×s for every
    ray, V_pp = sin θ'i sin θ's - cos θ'i cos θ's cos φ: Eq. 13 prints the
    second term with a + sign, which is the same matrix in a basis whose p
    vector is reversed on one ray; the s/p convention here is SCATMECH's and
    matches it element for element.  No absorption.

    Parameters: angles in radians; n binder index (> 0); g in (-1, 1).
    Returns broadcast(angles) + (4, 4), or M00 alone with ``mueller=False``."""
    n = _validate.index(n)
    g = _validate.asymmetry(g)
    angles = _validate.angles(theta_i, theta_s, phi_s, broadcast=False)

    def kernel(cos_i, sin_i, up_i, cos_s, sin_s, up_s, cp, sp, want_mueller):
        cos_ip, cos_sp, (tis, tip), (trs, trp), ok = _refracted_cosines(cos_i, sin_i, up_i, cos_s, sin_s, up_s, n)
        sin_ip, sin_sp = sin_i / n, sin_s / n
        # Internal rays k1 = (sin θ'i, 0, -cos θ'i), k2 = (sin θ's cos φ, sin θ's sin φ, cos θ's).
        cos_sc = np.clip(sin_ip * sin_sp * cp - cos_ip * cos_sp, -1.0, 1.0)
        denom = np.where(ok, cos_i * cos_s * (cos_ip + cos_sp), 1.0)
        scale = np.where(ok, phase.rayleigh_factor(cos_sc, g) * cos_ip * cos_sp / denom, 0.0)
        # V in the internal s/p bases; the exit basis has the azimuth φs even
        # at θs = 0 (the limit along φs; docs/models.md, Conventions).
        cb, sb = cp, sp
        v_ss, v_sp = cb, -sb * cos_ip
        v_ps, v_pp = -sb * cos_sp, sin_ip * sin_sp - cos_ip * cos_sp * cb
        if not want_mueller:
            return scale * jones_product_m00((trs, trp), ((v_ss, v_sp), (v_ps, v_pp)), (tis, tip))
        jones = np.empty(scale.shape + (2, 2))
        jones[:, 0, 0] = trs * v_ss * tis
        jones[:, 0, 1] = trs * v_sp * tip
        jones[:, 1, 0] = trp * v_ps * tis
        jones[:, 1, 1] = trp * v_pp * tip
        return scale[:, None, None] * jones_to_mueller(jones)

    return _vectorize.evaluate(kernel, angles, mueller)
