"""Fresnel coefficients of a planar air/binder interface and the internal
hemispherical reflectance r̄ of paper Eq. 22.

Sign conventions are SCATMECH's (``Thin_Film_Transfer_Matrix`` with no film):
with p = k×s for every ray, r_p = -r_s at normal incidence and t_s, t_p > 0.
"""

from __future__ import annotations

import functools

import numpy as np


def cos_refracted(cos_i, n):
    """cos of the refraction angle for light going from index 1 into index n,
    sqrt(1 - sin²θ/n²), principal complex root beyond the critical angle (n < 1)
    as in SCATMECH's ``cos_internal_angle``.  Real input gives a real result
    clipped to 0 under total internal reflection, complex input a complex one."""
    sin2 = 1.0 - np.asarray(cos_i) ** 2
    arg = 1.0 - sin2 / (n * n)
    if np.iscomplexobj(cos_i):
        return np.sqrt(arg + 0j)
    return np.sqrt(np.clip(arg, 0.0, None))


def reflection_coefficients(cos_i, n):
    """Amplitude reflection coefficients (r_s, r_p) for light incident from
    air (index 1) at a local angle with cosine ``cos_i`` onto index n.

    Complex where n < 1 and the angle exceeds the critical angle (|r| = 1).
    With n = 1 there is no interface and both are 0."""
    cos_i = np.asarray(cos_i, dtype=float)
    if n == 1.0:
        return np.zeros_like(cos_i), np.zeros_like(cos_i)
    if n < 1.0:
        cos_t = cos_refracted(cos_i.astype(complex), n)
    else:
        cos_t = cos_refracted(cos_i, n)
    rs = (cos_i - n * cos_t) / (cos_i + n * cos_t)
    rp = (n * cos_i - cos_t) / (n * cos_i + cos_t)
    return rs, rp


def transmission_coefficients(cos_i, n):
    """Amplitude transmission coefficients (t_s, t_p, cos_t) for light going
    from air into index n at a local angle with cosine ``cos_i``.

    Zero under total internal reflection (n < 1 beyond the critical angle),
    where no power crosses the interface, and for cos_i <= 0 (at or below the
    horizon).  The beam (power) transmittance is n cos_t / cos_i · |t|²
    (paper Eqs. 24, 42)."""
    cos_i = np.asarray(cos_i, dtype=float)
    sin2_t = (1.0 - cos_i * cos_i) / (n * n)
    ok = (sin2_t < 1.0) & (cos_i > 0.0)
    cos_t = np.sqrt(np.clip(1.0 - sin2_t, 0.0, None))
    c = np.where(ok, cos_i, 1.0)
    ts = np.where(ok, 2.0 * c / (c + n * cos_t), 0.0)
    tp = np.where(ok, 2.0 * c / (n * c + cos_t), 0.0)
    return ts, tp, cos_t


def unpolarized_reflectance(c1, c2, n):
    """Reflectance of unpolarized light, ½(|r_s|² + |r_p|²), at a planar
    interface between air and index n: the integrand of paper Eq. 22.

    ``c1`` and ``c2`` are the cosines of the angles to the normal on the air
    and on the binder side, related by Snell's law (paper Eq. 9), so the same
    value serves light arriving from either side (Stokes reciprocity:
    |r| is the same both ways).  r_s and r_p are the Fresnel amplitude
    coefficients written with both cosines, as in
    ``reflection_coefficients`` (SCATMECH's ``Thin_Film_Transfer_Matrix``
    with no film).  Real cosines only, i.e. not beyond the critical angle."""
    rs = (c1 - n * c2) / (c1 + n * c2)
    rp = (n * c1 - c2) / (n * c1 + c2)
    return 0.5 * (rs * rs + rp * rp)


@functools.lru_cache(maxsize=256)
def internal_reflectance(n: float, nodes: int = 256) -> float:
    """Exact internal hemispherical reflectance r̄ of paper Eq. 22,

        r̄ = (1/π) ∫ ½(|r_s(θ')|² + |r_p(θ')|²) cos θ' dΩ' = ∫₀¹ R(u) du,  u = sin²θ',

    for diffuse light inside a medium of index n meeting a smooth interface
    with air.  For n > 1 the part beyond the critical angle is totally
    reflected and contributes 1 - 1/n²; the rest maps onto the external
    reflectance, (1/n²) ∫₀¹ R_ext(w) 2w dw with w = cos θ outside, whose
    integrand is analytic, so Gauss-Legendre converges to machine precision.
    For n < 1 the same is done in w = cos θ' inside.

    SCATMECH's Diffuse_Subsurface_BRDF_Model instead sums this in 0.2° steps
    (0.596353 for n = 1.5 against the exact 0.596346); we deliberately use the
    exact value (see docs/models.md)."""
    n = float(n)
    if n == 1.0:
        return 0.0
    x, w = np.polynomial.legendre.leggauss(nodes)
    w_ = 0.5 * (x + 1.0)  # cosine on [0, 1]
    weights = 0.5 * w
    if n > 1.0:
        c1 = w_
        c2 = np.sqrt(1.0 - (1.0 - c1 * c1) / (n * n))
        integral = np.sum(weights * unpolarized_reflectance(c1, c2, n) * 2.0 * c1)
        return float((1.0 - 1.0 / (n * n)) + integral / (n * n))
    c2 = w_
    c1 = np.sqrt(1.0 - n * n * (1.0 - c2 * c2))
    return float(np.sum(weights * unpolarized_reflectance(c1, c2, n) * 2.0 * c2))
