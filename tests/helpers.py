"""Shared numerical helpers for the tests (hemispherical integrals, bases)."""

import numpy as np

from lut.models import jones_to_mueller


def hemispherical(fn, theta_i, n_theta=96, n_phi=96, **kw):
    """Directional-hemispherical reflectance ∫ f(θi, θs, φs) cos θs dΩs of the
    M00 BRDF fn, by Gauss-Legendre in θs and the periodic trapezoid rule in φs."""
    x, w = np.polynomial.legendre.leggauss(n_theta)
    ts = 0.25 * np.pi * (x + 1.0)
    wt = 0.25 * np.pi * w
    ps = (np.arange(n_phi) + 0.5) * 2.0 * np.pi / n_phi - np.pi
    tsg, psg = np.meshgrid(ts, ps, indexing="ij")
    f = fn(theta_i, tsg, psg, mueller=False, **kw)
    return float(np.sum(f * np.cos(tsg) * np.sin(tsg) * wt[:, None]) * 2.0 * np.pi / n_phi)


def relative_rms(a, b):
    return float(np.sqrt(np.mean((np.asarray(a) - np.asarray(b)) ** 2) / np.mean(np.asarray(b) ** 2)))


def normal_basis_rotation(phi, downward=False):
    """Mueller matrix taking the Stokes vector of a ray along the normal from
    the basis s = ŷ to the limit along the azimuth φ, s = (-sin φ, cos φ, 0),
    p = k×s (docs/models.md, Conventions).  For k = ẑ, p = (-cos φ, -sin φ, 0)
    and E_s' = cos φ E_s + sin φ E_p, E_p' = -sin φ E_s + cos φ E_p; for
    k = -ẑ (``downward``: the incident or a transmitted ray) p changes sign and
    so does the rotation."""
    c, s = np.cos(phi), np.sin(phi) * (-1.0 if downward else 1.0)
    jones = np.stack((np.stack((c, s), -1), np.stack((-s, c), -1)), -2)
    return jones_to_mueller(jones)
