"""Shared numerical helpers for the tests (hemispherical integrals)."""

import numpy as np


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
