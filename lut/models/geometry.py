"""Directions and polarization bases (SCATMECH's conventions, paper Eqs. 3, 8).

Vectors are numpy arrays whose last axis holds (x, y, z).

* Incident propagation: k_i = (sin θi, 0, -cos θi): the source sits at azimuth π.
* Reflected (scattered) propagation: k_s = (sin θs cos φs, sin θs sin φs, cos θs);
  φs = 0 with θs = θi is the specular direction.
* Transmitted propagation: k_t = (sin θt cos φt, sin θt sin φt, -cos θt), θt from
  the inward normal, φt = 0 the regular refraction side.
* s/p basis of a ray k: s = ẑ×k / |ẑ×k|, p = k×s.  This is SCATMECH's
  ``GetBasisVectorsSP``; the paper's Eq. 8 uses s = k×n̂, which differs only
  by the sign of both s and p and leaves every Mueller matrix unchanged.
  Along the normal (k ∥ ẑ) s is the limit along the ray's azimuth φ,
  s = (-sin φ, cos φ, 0), as SCATMECH's models take it: the caller's φs (or
  φt) defines the exit basis at θs = 0, and the incident ray, whose azimuth
  is fixed at π, has s = ŷ at θi = 0.  ``sp_basis`` sees only k and returns
  this limit for φ = 0 (s = ŷ); the models build their exit rays at φ = 0 and
  rotate them, or use the azimuth directly.
"""

from __future__ import annotations

import numpy as np

#: Below this transverse length a direction counts as parallel to ẑ.
PARALLEL_EPS = 1e-12


def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Dot product over the last axis."""
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product over the last axis (cheaper than np.cross on small axes)."""
    return np.stack(
        (
            a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
            a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
            a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0],
        ),
        axis=-1,
    )


def vec(x, y, z) -> np.ndarray:
    """Stack broadcast components into vectors."""
    x, y, z = np.broadcast_arrays(x, y, z)
    return np.stack((x, y, z), axis=-1).astype(float)


def incident(theta_i) -> np.ndarray:
    """Incident propagation direction k_i (source at azimuth π)."""
    return vec(np.sin(theta_i), 0.0, -np.cos(theta_i))


def scattered(theta_s, phi_s) -> np.ndarray:
    """Reflected propagation direction k_s."""
    st = np.sin(theta_s)
    return vec(st * np.cos(phi_s), st * np.sin(phi_s), np.cos(theta_s))


def transmitted(theta_t, phi_t) -> np.ndarray:
    """Transmitted propagation direction k_t (θt from the inward normal)."""
    st = np.sin(theta_t)
    return vec(st * np.cos(phi_t), st * np.sin(phi_t), -np.cos(theta_t))


def unit_or(v: np.ndarray, fallback: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Normalize v; where |v| is below PARALLEL_EPS use ``fallback`` instead.

    Returns (unit vectors, norms)."""
    norm = np.sqrt(dot(v, v))
    ok = norm > PARALLEL_EPS
    if ok.all():  # the usual case: no fallback to merge in (the same values, half the array work)
        return v / norm[..., None], norm
    safe = np.where(ok, norm, 1.0)
    out = np.where(ok[..., None], v / safe[..., None], fallback)
    return out, norm


def sp_basis(k: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """SCATMECH's s/p basis of propagation direction k: s = ẑ×k/|ẑ×k|
    (ŷ when k ∥ ẑ: the limit along the azimuth 0 or π), p = k×s."""
    zxk = np.stack((-k[..., 1], k[..., 0], np.zeros_like(k[..., 0])), axis=-1)
    s, _ = unit_or(zxk, np.array([0.0, 1.0, 0.0]))
    return s, cross(k, s)


def refract(k: np.ndarray, h: np.ndarray, eta, cos_i: np.ndarray):
    """Refract propagation direction k at a facet of unit normal h (pointing
    back towards the source side, i.e. cos_i = -k·h >= 0) with relative index
    eta = n_2 / n_1 (Snell's law, paper Eq. 30: k×h = eta k'×h).

    Returns (k', cos_t, ok) where ok is False under total internal reflection.
    """
    sin2_t = (1.0 - cos_i * cos_i) / (eta * eta)
    ok = sin2_t <= 1.0
    cos_t = np.sqrt(np.clip(1.0 - sin2_t, 0.0, None))
    kt = k / eta + ((cos_i / eta) - cos_t)[..., None] * h
    return kt, cos_t, ok


def interface_jones(k_a, k_b, h, c_s, c_p, basis_a, basis_b):
    """Jones matrix (s/p bases of the two rays) of one planar interface with
    unit normal h that takes ray k_a to ray k_b with local Fresnel amplitude
    coefficients c_s, c_p (paper Eqs. 10, 11, 40).

    The local s vector is k_a×h (any vector ⊥ k_a at normal incidence, where
    the result does not depend on the choice); the local p vectors are k×s.
    Returns an array (..., 2, 2): rows (s_b, p_b), columns (s_a, p_a)."""
    s_a, p_a = basis_a
    s_b, p_b = basis_b
    s_loc, _ = unit_or(cross(k_a, h), s_a)
    pa_loc = cross(k_a, s_loc)
    pb_loc = cross(k_b, s_loc)
    # J = R_out · diag(c_s, c_p) · R_in
    in_ss, in_sp = dot(s_loc, s_a), dot(s_loc, p_a)
    in_ps, in_pp = dot(pa_loc, s_a), dot(pa_loc, p_a)
    out_ss, out_sp = dot(s_b, s_loc), dot(s_b, pb_loc)
    out_ps, out_pp = dot(p_b, s_loc), dot(p_b, pb_loc)
    j00 = out_ss * c_s * in_ss + out_sp * c_p * in_ps
    j01 = out_ss * c_s * in_sp + out_sp * c_p * in_pp
    j10 = out_ps * c_s * in_ss + out_pp * c_p * in_ps
    j11 = out_ps * c_s * in_sp + out_pp * c_p * in_pp
    return np.stack((np.stack((j00, j01), -1), np.stack((j10, j11), -1)), -2)
