"""The paper's random-pairs method for single scattering under a rough
interface (Sec. 2.5), kept as a reference: a check, not on the bake path.

The paper averages the smooth-interface result over ~5000 random pairs of
facet normals per direction pair, one met by the incident ray and one by the
scattered ray.  ``rough.rough_single`` computes the same average by
deterministic quadrature and is what the models, the fit and the bake use.
This module exists so the quadrature can be checked against the paper's own
method (tests/test_physics.py) and timed against it (``lut.bench``,
scripts/benchmark_models.py); nothing in production imports it.
"""

from __future__ import annotations

import numpy as np

from . import _validate, distributions, fresnel, geometry, phase
from .geometry import dot
from .mueller import jones_product_m00
from .rough import CHUNK_PAIRS, local_basis


def _area_normals(rng, shape, slope, distribution):
    """Random facet normals distributed as P(ζ) dζx dζy (uniform on the mean
    plane), the paper's first random surface-normal generator."""
    if distribution == "gaussian":
        zeta = slope * np.sqrt(rng.standard_exponential(shape))
    else:
        zeta = slope * rng.standard_gamma(2.0, shape) / distributions.SQRT6
    phi = rng.uniform(-np.pi, np.pi, shape)
    norm = np.sqrt(1.0 + zeta * zeta)
    return np.stack((zeta * np.cos(phi) / norm, zeta * np.sin(phi) / norm, 1.0 / norm), axis=-1)


def rough_single_random(theta_i, theta_s, phi_s, *, n, g, slope, distribution="gaussian", pairs=5000, seed=0):
    """M00 of ``rough_single`` by the paper's Monte Carlo method (Sec. 2.5):
    for every direction pair, ``pairs`` independent pairs of random facet
    normals, one met by the incident and one by the scattered ray, averaged.
    The baseline of the benchmark (``lut.bench``,
    scripts/benchmark_models.py) and a check that the quadrature of
    ``rough_single``, the production path, converges to the paper's average.

    The normals seen by a ray are drawn from the area distribution and
    weighted by their projected area max(cos ι, 0) sec θn (Eq. 36) with a
    self-normalized average, rather than by the paper's rejection step;
    both sample the same distribution."""
    n = _validate.index(n)
    g = _validate.asymmetry(g)
    slope = _validate.rms_slope(slope)
    distribution = _validate.distribution(distribution)
    pairs = _validate.positive_int(pairs, "pairs")
    ti, ts, ps = (a.ravel() for a in _validate.angles(theta_i, theta_s, phi_s))
    shape = np.broadcast(theta_i, theta_s, phi_s).shape
    rng = np.random.default_rng(seed)
    out = np.zeros(ti.shape)
    chunk = max(1, CHUNK_PAIRS // pairs)
    for start in range(0, ti.size, chunk):
        sl = slice(start, start + chunk)
        k_i = geometry.incident(ti[sl])[:, None, :]
        k_s = geometry.scattered(ts[sl], ps[sl])[:, None, :]
        h1 = _area_normals(rng, (k_i.shape[0], pairs), slope, distribution)
        h2 = _area_normals(rng, (k_i.shape[0], pairs), slope, distribution)
        # Projected-area weights max(cos ι, 0) sec θn of the ray's facets (Eq. 36).
        w1 = np.clip(-dot(k_i, h1), 0.0, None) / h1[..., 2]
        w2 = np.clip(dot(k_s, h2), 0.0, None) / h2[..., 2]
        cos1, cos2 = np.clip(-dot(k_i, h1), 0.0, 1.0), np.clip(dot(k_s, h2), 0.0, 1.0)
        # Snell's law at each facet (Eq. 30); the exit is the reversed entry
        # of -k_s, with the air-side coefficients (reciprocity, Eq. 25).
        k1, c1t, ok1 = geometry.refract(k_i, h1, n, cos1)
        k2r, c2t, ok2 = geometry.refract(-k_s, h2, n, cos2)
        k2 = -k2r
        t1s, t1p, _ = fresnel.transmission_coefficients(cos1, n)
        t2s, t2p, _ = fresnel.transmission_coefficients(cos2, n)
        s1, _, p1 = local_basis(np.broadcast_to(k_i, k1.shape), k1, h1)
        s2, _, p2 = local_basis(np.broadcast_to(k_s, k2.shape), k2, h2)
        # Beam factors n cos ι'/cos ι of the two crossings (Eqs. 24, 25, 42),
        # for pairs whose internal rays head into, then out of, the bulk.
        good = ok1 & ok2 & (k1[..., 2] < 0.0) & (k2[..., 2] > 0.0) & (cos1 > 0.0) & (cos2 > 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            beam = np.where(good, n * c1t / cos1 * n * c2t / cos2, 0.0)
        cos_sc = np.clip(dot(k1, k2), -1.0, 1.0)
        # M00 of the facets' Jones product (Eq. 13 in the local s/p bases).
        m00 = jones_product_m00((t2s, t2p), ((dot(s2, s1), dot(s2, p1)), (dot(p2, s1), dot(p2, p1))), (t1s, t1p))
        # Eq. 19's 1/(cos θ'i + cos θ's) and Eq. 7's phase factor, as in Eq. 20.
        depth = np.abs(k1[..., 2]) + np.abs(k2[..., 2])
        inv_depth = np.divide(1.0, depth, out=np.zeros_like(depth), where=depth > 0.0)
        value = beam * phase.rayleigh_factor(cos_sc, g) * m00 * inv_depth / (n * n)
        # Self-normalized average over the pairs (each ray meets one facet).
        norm = np.sum(w1, axis=1) * np.sum(w2, axis=1) / pairs
        with np.errstate(divide="ignore", invalid="ignore"):
            out[sl] = np.where(norm > 0, np.sum(w1 * w2 * value, axis=1) / np.where(norm > 0, norm, 1.0), 0.0)
    lit = (ti < np.pi / 2) & (ts < np.pi / 2)
    return np.where(lit, out, 0.0).reshape(shape)
