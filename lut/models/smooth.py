"""Volume scattering under a smooth interface (paper Secs. 2.2 and 2.3)."""

from __future__ import annotations

import numpy as np

from . import _validate, fresnel, geometry, phase
from .geometry import dot
from .mueller import jones_to_mueller


def _refracted_cosines(ti, ts, n):
    """cos θ' inside the binder for the incident and scattered directions
    (Snell, Eq. 9), and the mask of directions that cross the interface
    (above the horizon and, for n < 1, below the critical angle)."""
    cos_i, cos_s = np.cos(ti), np.cos(ts)
    ts_i, tp_i, cos_ip = fresnel.transmission_coefficients(cos_i, n)
    ts_s, tp_s, cos_sp = fresnel.transmission_coefficients(cos_s, n)
    # Light crosses only where the refracted ray exists and leaves the plane:
    # above the horizon, below the critical angle (n < 1), and cos θ' > 0
    # (which fails in floating point for n -> 1 within ~1e-12 of grazing).
    ok = (ti < np.pi / 2) & (ts < np.pi / 2) & (cos_ip > 0.0) & (cos_sp > 0.0)
    if n < 1.0:
        ok &= (np.sin(ti) < n) & (np.sin(ts) < n)
    return cos_i, cos_s, cos_ip, cos_sp, (ts_i, tp_i), (ts_s, tp_s), ok


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
    ti, ts, _ = _validate.angles(theta_i, theta_s, phi_s)
    cos_i, cos_s, cos_ip, cos_sp, (tis, tip), (trs, trp), ok = _refracted_cosines(ti, ts, n)
    rbar = fresnel.internal_reflectance(n)
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = np.where(ok, rho / np.pi / (1.0 - rho * rbar) * cos_sp * cos_ip / (cos_s * cos_i), 0.0)
    a_i, b_i = tis * tis + tip * tip, tis * tis - tip * tip
    a_s, b_s = trs * trs + trp * trp, trs * trs - trp * trp
    if not mueller:
        return scale * 0.25 * a_s * a_i
    m = np.zeros(scale.shape + (4, 4))
    m[..., 0, 0] = a_s * a_i
    m[..., 0, 1] = a_s * b_i
    m[..., 1, 0] = b_s * a_i
    m[..., 1, 1] = b_s * b_i
    return (0.25 * scale)[..., None, None] * m


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
    and backward directions (k1×k2 = 0) are regular.  No absorption: the
    single-scattering albedo weight is applied by the caller.

    Parameters: angles in radians; n binder index (> 0); g in (-1, 1).
    Returns broadcast(angles) + (4, 4), or M00 alone with ``mueller=False``."""
    n = _validate.index(n)
    g = _validate.asymmetry(g)
    ti, ts, ps = _validate.angles(theta_i, theta_s, phi_s)
    cos_i, cos_s, cos_ip, cos_sp, (tis, tip), (trs, trp), ok = _refracted_cosines(ti, ts, n)
    # Internal propagation directions (Eq. 9) and their s/p bases.
    si, ss = np.sin(ti) / n, np.sin(ts) / n
    k1 = geometry.vec(si, 0.0, -cos_ip)
    k2 = geometry.vec(ss * np.cos(ps), ss * np.sin(ps), cos_sp)
    s1, p1 = geometry.sp_basis(k1)
    s2, p2 = geometry.sp_basis(k2)
    cos_sc = np.clip(dot(k1, k2), -1.0, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = np.where(
            ok,
            phase.rayleigh_factor(cos_sc, g) * cos_ip * cos_sp / (cos_i * cos_s * (cos_ip + cos_sp)),
            0.0,
        )
    v_ss, v_sp = dot(s2, s1), dot(s2, p1)
    v_ps, v_pp = dot(p2, s1), dot(p2, p1)
    if not mueller:
        m00 = 0.5 * (
            trs * trs * (v_ss * v_ss * tis * tis + v_sp * v_sp * tip * tip)
            + trp * trp * (v_ps * v_ps * tis * tis + v_pp * v_pp * tip * tip)
        )
        return scale * m00
    jones = np.stack(
        (
            np.stack((trs * v_ss * tis, trs * v_sp * tip), -1),
            np.stack((trp * v_ps * tis, trp * v_pp * tip), -1),
        ),
        -2,
    )
    return scale[..., None, None] * jones_to_mueller(jones)
