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


def gauss_rules(x, w, nodes: int):
    """Gauss rules for a batch of discrete measures: x, w of shape (B, K),
    K > nodes, give (nodes, weights) of shape (B, nodes), exact for every
    polynomial of degree < 2·nodes under each measure.

    The three-term recurrence comes from the discretized Stieltjes procedure
    and the rule from its Jacobi matrix (Golub-Welsch), as in W. Gautschi,
    *Orthogonal Polynomials: Computation and Approximation* (2004), Secs. 2.2.3
    and 3.1.1.1; with a discretization that integrates the measure's
    polynomials to rounding, the rule is the measure's own Gauss rule."""
    batch = x.shape[0]
    mass = np.sum(w, axis=-1)
    diag = np.empty((batch, nodes))
    off = np.empty((batch, max(nodes - 1, 0)))
    p_prev = np.zeros_like(x)
    p = np.ones_like(x)
    norm_prev = None
    for k in range(nodes):
        wp = w * p
        norm = np.sum(wp * p, axis=-1)
        diag[:, k] = np.sum(wp * p * x, axis=-1) / norm
        if k > 0:
            off[:, k - 1] = np.sqrt(norm / norm_prev)
        # p_{k+1} = (x - a_k) p_k - b_k p_{k-1}, kept at unit norm.
        nxt = (x - diag[:, k, None]) * p - (0.0 if k == 0 else (norm / norm_prev)[:, None]) * p_prev
        scale = 1.0 / np.sqrt(norm)[:, None]
        p_prev, p, norm_prev = p * scale, nxt * scale, np.ones(batch)
    jacobi = np.zeros((batch, nodes, nodes))
    k = np.arange(nodes)
    jacobi[:, k, k] = diag
    jacobi[:, k[1:], k[:-1]] = off
    jacobi[:, k[:-1], k[1:]] = off
    t, vec = np.linalg.eigh(jacobi)
    return t, mass[:, None] * vec[:, 0, :] ** 2


@functools.lru_cache(maxsize=8)
def _legendre_01(count: int):
    """Gauss-Legendre nodes and weights on [0, 1] (read-only)."""
    x, w = np.polynomial.legendre.leggauss(count)
    x, w = 0.5 * (x + 1.0), 0.5 * w
    x.setflags(write=False)
    w.setflags(write=False)
    return x, w


#: Split cap in the radial variable t (see ``split_radial_rule``): where the
#: facets start turning away from a ray beyond it, the split stays there.
#: Near the median of each measure (e^-t: 0.69; t e^-t: 1.68) both pieces
#: keep a fair share of the facets at every angle; a cap far in the tail (the
#: earlier 9 and 12) leaves half the radial nodes with 1e-4 of the weight at
#: normal incidence.
_T_CAP = {"gaussian": 2.0, "exponential": 4.0}
#: Upper end of the discretization of the outer piece's variable v, where
#: e^-v² is below 1e-18.
_V_MAX = 6.5


def _discretization_size(nodes: int) -> int:
    return max(64, 3 * nodes)


def radial_variable(zeta, slope: float, distribution: str):
    """The radial variable t in which the facet measure 2πζP(ζ)dζ is simple:
    t = ζ²/s² with measure e^-t dt (gaussian), t = √6 ζ/s with measure
    t e^-t dt (exponential)."""
    if distribution == "gaussian":
        return (zeta / slope) ** 2
    return SQRT6 * zeta / slope


def split_radial_rule(t_split, slope: float, distribution: str, nodes: int):
    """Quadrature over the radial slope for the probability measure
    2πζP(ζ)dζ (e^-t dt or t e^-t dt in the variable of ``radial_variable``),
    split at t_split (broadcast array, capped at ``_T_CAP``): ``nodes`` nodes
    on each of [0, t_split] and [t_split, ∞).

    The split is where facets begin to turn away from the ray; there the
    facet-averaged integrand has a kink of the form (t - t_split)^(3/2) (the
    hidden arc grows as √(t - t_split)).  So each piece gets the Gauss rule of
    its own measure:

    * inner: the Gauss rule of the truncated measure e^-t (t e^-t) on
      [0, t_split], exact for polynomials of degree 2·nodes - 1 in t (a
      Gauss-Legendre rule in t would have to resolve e^-t as well);
    * outer: with t = t_split + v² the kink becomes the smooth v³, and the
      measure e^-t_split · 2v e^-v² (times t_split + v² for the exponential)
      gets its own Gauss rule in v.

    The rules depend on the split point alone, smoothly; they are tabulated
    once per distribution and node count on ``_SPLIT_TABLE`` + 1 split points
    and interpolated by cubics (which changes integrals by ~1e-9), so they
    move continuously with the split.  Returns (zeta, weight), shapes t_split.shape + (2 · nodes,); the
    weights sum to 1 up to 1e-8."""
    cap = _T_CAP[distribution]
    t_split = np.clip(np.asarray(t_split, dtype=float), 0.0, cap)
    shape = t_split.shape
    ts = t_split.reshape(-1, 1)
    table = _split_table(distribution, nodes)
    # Cubic (4-point Lagrange) interpolation in the table: each piece matches
    # the table at its knots, so the rules stay continuous in t_split.
    pos = np.sqrt(ts[:, 0] / cap) * _SPLIT_TABLE
    k = np.clip(pos.astype(int) - 1, 0, _SPLIT_TABLE - 3)
    u = (pos - k)[:, None]
    lagrange = np.stack(
        (
            -(u - 1.0) * (u - 2.0) * (u - 3.0) / 6.0,
            u * (u - 2.0) * (u - 3.0) / 2.0,
            -u * (u - 1.0) * (u - 3.0) / 2.0,
            u * (u - 1.0) * (u - 2.0) / 6.0,
        ),
        axis=-1,
    )
    stencil = k[:, None] + np.arange(4)
    x_in, w_x_in, v_b, w_b = (np.sum(lagrange * np.swapaxes(col[stencil], 1, 2), axis=-1) for col in table)
    expo = distribution == "exponential"
    # Inner piece in x = t / t_split: e^-t dt = t_split e^(-t_split x) dx,
    # t e^-t dt = t_split² x e^(-t_split x) dx.
    t_a = ts * x_in
    w_a = w_x_in * (ts * ts if expo else ts)
    # Outer piece in v, t = t_split + v².
    t_b = ts + v_b * v_b
    w_b = w_b * np.exp(-ts)
    t = np.concatenate((t_a, t_b), axis=-1)
    w = np.concatenate((w_a, w_b), axis=-1)
    zeta = slope * t / SQRT6 if expo else slope * np.sqrt(t)
    return zeta.reshape(shape + (-1,)), w.reshape(shape + (-1,))


#: Intervals of the table of split rules over [0, _T_CAP].
_SPLIT_TABLE = 256


@functools.lru_cache(maxsize=16)
def _split_table(distribution: str, nodes: int):
    """The pieces of ``split_radial_rule`` on _SPLIT_TABLE + 1 split points
    t_s in [0, _T_CAP]: the inner Gauss rule in x = t/t_s for e^(-t_s x) dx
    (x e^(-t_s x) dx for the exponential) and the outer one in v for
    2v e^-v² dv ((t_s + v²) 2v e^-v² dv), by ``gauss_rules`` on
    Gauss-Legendre discretizations that integrate those measures' polynomials
    to rounding.  Returns four read-only arrays (_SPLIT_TABLE + 1, nodes)."""
    ts = _T_CAP[distribution] * np.linspace(0.0, 1.0, _SPLIT_TABLE + 1)[:, None] ** 2
    expo = distribution == "exponential"
    x, wx = _legendre_01(_discretization_size(nodes))
    w_in = wx * np.exp(-ts * x) * (x if expo else 1.0)
    x_in, w_x_in = gauss_rules(np.broadcast_to(x, w_in.shape), w_in, nodes)
    v = _V_MAX * x
    w_out = _V_MAX * wx * 2.0 * v * np.exp(-v * v) * ((ts + v * v) if expo else 1.0)
    if expo:
        v_b, w_b = gauss_rules(np.broadcast_to(v, w_out.shape), w_out, nodes)
    else:  # the Gaussian's outer rule does not depend on the split
        v_b, w_b = (np.repeat(a, ts.shape[0], axis=0) for a in gauss_rules(v[None, :], w_out[None, :], nodes))
    for a in (x_in, w_x_in, v_b, w_b):
        a.setflags(write=False)
    return x_in, w_x_in, v_b, w_b
