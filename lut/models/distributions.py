"""Isotropic slope distribution functions P(ζ) (paper Eq. 29), normalized so
that ∫ P(ζ) dζx dζy = 1 and <ζ²> = s² (s the total RMS slope), exactly as in
SCATMECH's ``Gaussian_Slope_Distribution_Function`` and
``Exponential_Slope_Distribution_Function``:

* gaussian:    P(ζ) = exp(-ζ²/s²) / (π s²)   (Beckmann with α = s)
* exponential: P(ζ) = 3/(π s²) · exp(-√6 ζ / s)
"""

from __future__ import annotations

import functools

import numpy as np

SQRT6 = np.sqrt(6.0)


def pdf(zeta, slope: float, distribution: str):
    """P(ζ) per unit dζx dζy."""
    z = np.asarray(zeta, dtype=float)
    s2 = slope * slope
    if distribution == "gaussian":
        return np.exp(-(z * z) / s2) / (np.pi * s2)
    return 3.0 / (np.pi * s2) * np.exp(-SQRT6 * z / slope)


@functools.lru_cache(maxsize=32)
def _laguerre_rule(nodes: int, alpha: float):
    """Gauss rule for the weight x^alpha e^-x on [0, ∞) by the Golub-Welsch
    eigenvalue method (recurrence a_k = 2k + alpha + 1, b_k = k (k + alpha)).
    Returns (x, w) with the weights normalized to sum to 1."""
    k = np.arange(nodes, dtype=float)
    diag = 2.0 * k + alpha + 1.0
    off = np.sqrt(k[1:] * (k[1:] + alpha))
    jacobi = np.diag(diag) + np.diag(off, 1) + np.diag(off, -1)
    x, vec = np.linalg.eigh(jacobi)
    w = vec[0] ** 2
    x.setflags(write=False)
    w.setflags(write=False)
    return x, w


#: Split cap in the radial variable t (see ``split_radial_rule``): beyond it
#: the tail holds ~1e-4 of the facets and gets a Laguerre rule of its own.
_T_CAP = {"gaussian": 9.0, "exponential": 12.0}


def radial_variable(zeta, slope: float, distribution: str):
    """The radial variable t in which the facet measure 2πζP(ζ)dζ is simple:
    t = ζ²/s² with measure e^-t dt (gaussian), t = √6 ζ/s with measure
    t e^-t dt (exponential)."""
    if distribution == "gaussian":
        return (zeta / slope) ** 2
    return SQRT6 * zeta / slope


def split_radial_rule(t_split, slope: float, distribution: str, nodes: int):
    """Quadrature over the radial slope for the probability measure
    2πζP(ζ)dζ, split at t_split (broadcast array, in the variable of
    ``radial_variable``; capped at a fixed value where the tail is small):
    Gauss-Legendre with ``nodes`` nodes on [0, t_split] and a shifted
    (Gauss-)Laguerre rule with ``nodes`` nodes on [t_split, ∞).

    Splitting where the integrand has a kink (the onset of facets turning
    away from the ray) keeps both pieces smooth, so both rules converge fast.
    Returns (zeta, weight), shapes t_split.shape + (2 * nodes,); the weights
    sum to 1 up to the rules' error."""
    t_split = np.minimum(np.asarray(t_split, dtype=float), _T_CAP[distribution])[..., None]
    x, wx = np.polynomial.legendre.leggauss(nodes)
    u, wu = _laguerre_rule(nodes, 0.0)
    t_a = 0.5 * t_split * (x + 1.0)
    t_b = t_split + u
    w_a = 0.5 * t_split * wx * np.exp(-t_a)
    w_b = wu * np.exp(-t_split) * np.ones_like(t_b)
    if distribution == "exponential":
        w_a = w_a * t_a
        w_b = w_b * t_b
        zeta = slope * np.concatenate((t_a, t_b), axis=-1) / SQRT6
    else:
        zeta = slope * np.sqrt(np.concatenate((t_a, t_b), axis=-1))
    return zeta, np.concatenate((w_a, w_b), axis=-1)
