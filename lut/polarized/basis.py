"""A polarization basis continuous over the hemisphere, and the change into
it from SCATMECH's s/p bases.

SCATMECH (and ``lut.models``, docs/models.md) refers a ray of propagation
direction k to s = ẑ×k/|ẑ×k|, p = k×s.  Along the normal that basis has no
value of its own: the models take the limit along the ray's azimuth, so a
Mueller matrix turns by twice the azimuth as the exit direction circles the
pole, and a table interpolating across θs = 0 mixes matrices referred to
different bases.

The *transported* basis has no such point: its s vector is the global x̂
carried from the pole nearest k (+ẑ for rays leaving the surface, -ẑ for
rays arriving at it) to k by the rotation about ẑ×k (parallel transport
along the meridian), p = k×s.  With k = (x, y, z) and σ = sign(z) (+1 at
z = 0):

    s = (1 - σ x²/(σ + z), -σ x y/(σ + z), -σ x),

T. Duff, J. Burgess, P. Christensen, C. Hery, A. Kensler, M. Liani and
R. Villemin, "Building an Orthonormal Basis, Revisited", Journal of
Computer Graphics Techniques 6(1), 2017,
Listing 3 (the first vector); Mitsuba 3 takes the same vector as its Stokes
basis of a direction (``mueller::stokes_basis``).  It is smooth on each
open hemisphere, poles included.

Changing the basis of one ray rotates its Stokes vector: with
s' = cos ψ s + sin ψ p (p' = k×s'), the Jones components turn by
R(ψ) = [[cos ψ, sin ψ], [-sin ψ, cos ψ]] and the Stokes vector by
L(ψ) = M(R(ψ)) (``stokes_rotation``), so a Mueller matrix M referred to the
s/p bases is, in the transported ones, L(ψ_s) · M · L(ψ_i)⁻¹ (the rule of
R. A. Chipman, W. S. T. Lam and G. Young, "Polarized Light and Optical
Systems", CRC Press, 2018,
Sec. 6.4).  M00 is unchanged."""

from __future__ import annotations

import numpy as np

from ..models import _validate, geometry


def transported_basis(k):
    """(s, p) of unit propagation directions k (..., 3) in the transported
    basis (module docstring): each (..., 3)."""
    k = np.asarray(k, dtype=float)
    x, y, z = k[..., 0], k[..., 1], k[..., 2]
    sign = np.where(z >= 0.0, 1.0, -1.0)
    a = -1.0 / (sign + z)
    s = np.stack((1.0 + sign * x * x * a, sign * x * y * a, -sign * x), axis=-1)
    return s, geometry.cross(k, s)


def stokes_rotation(psi):
    """L(ψ) (..., 4, 4): the change of a Stokes vector (I, Q, U, V), Q = I_s - I_p,
    when its basis turns by ψ about the ray (s' = cos ψ s + sin ψ p)."""
    psi = np.asarray(psi, dtype=float)
    c, s = np.cos(2.0 * psi), np.sin(2.0 * psi)
    out = np.zeros(psi.shape + (4, 4))
    out[..., 0, 0] = out[..., 3, 3] = 1.0
    out[..., 1, 1] = out[..., 2, 2] = c
    out[..., 1, 2] = s
    out[..., 2, 1] = -s
    return out


def turn(k, s_from, p_from, s_to):
    """ψ from a basis (s_from, p_from) of rays k to another (s_to, k×s_to):
    s_to = cos ψ s_from + sin ψ p_from."""
    return np.arctan2(geometry.dot(s_to, p_from), geometry.dot(s_to, s_from))


def refer(mueller, psi_i, psi_s):
    """A Mueller matrix (..., 4, 4), or per channel (..., C, 4, 4), referred
    to new bases of its incident and exit rays, turned by ψ_i and ψ_s (each
    of the angles' shape): L(ψ_s) · M · L(-ψ_i)."""
    mueller = np.asarray(mueller, dtype=float)
    psi_i, psi_s = np.broadcast_arrays(np.asarray(psi_i, dtype=float), np.asarray(psi_s, dtype=float))
    shape = psi_i.shape
    if mueller.shape[: len(shape)] != shape or mueller.shape[-2:] != (4, 4) or mueller.ndim > len(shape) + 3:
        raise ValueError(
            f"mueller must have shape angles + (4, 4) or angles + (C, 4, 4) with angles {shape}, got {mueller.shape}"
        )
    extra = (1,) * (mueller.ndim - len(shape) - 2)
    return (
        stokes_rotation(psi_s).reshape(shape + extra + (4, 4))
        @ mueller
        @ stokes_rotation(-psi_i).reshape(shape + extra + (4, 4))
    )


def about_normal(v, angle):
    """Vectors v (..., 3) turned by ``angle`` about ẑ."""
    c, s = np.cos(angle), np.sin(angle)
    return np.stack((c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1], v[..., 2]), axis=-1)


def scatmech_bases(theta_i, theta_s, phi_s):
    """SCATMECH's s/p bases at model angles (the source at azimuth π):
    ((k_i, s_i, p_i), (k_s, s_s, p_s)).  k_i = (sin θi, 0, -cos θi) and
    s_i = ŷ for every θi, the normal included (the source's azimuth is
    fixed); s_s = (-sin φs, cos φs, 0), the models' limit along φs at
    θs = 0 (docs/models.md)."""
    k_i = np.stack((np.sin(theta_i), np.zeros_like(theta_i), -np.cos(theta_i)), axis=-1)
    s_i = np.broadcast_to(np.array([0.0, 1.0, 0.0]), k_i.shape)
    k_s = geometry.scattered(theta_s, phi_s)
    s_s = np.stack((-np.sin(phi_s), np.cos(phi_s), np.zeros_like(phi_s)), axis=-1)
    return (k_i, s_i, geometry.cross(k_i, s_i)), (k_s, s_s, geometry.cross(k_s, s_s))


def mueller_in_transported_basis(mueller, theta_i, theta_s, phi_s, frame=0.0):
    """A Mueller matrix (..., 4, 4), or per channel (..., C, 4, 4), referred
    to SCATMECH's s/p bases of the incident and exit rays at model angles
    (radians; the source at azimuth π), referred instead to their
    transported bases: L(ψ_s) · M · L(ψ_i)⁻¹ (module docstring).  The
    transported bases are those of a frame turned by ``frame`` (radians,
    broadcast with the angles) about the normal from the models' (in which
    the source lies at azimuth π + frame)."""
    ti, ts, ps, frame = np.broadcast_arrays(*_validate.angles(theta_i, theta_s, phi_s), np.asarray(frame, dtype=float))
    psi = []
    for k, s_ray, p_ray in scatmech_bases(ti, ts, ps):
        k, s_ray, p_ray = (about_normal(v, frame) for v in (k, s_ray, p_ray))
        psi.append(turn(k, s_ray, p_ray, transported_basis(k)[0]))
    return refer(mueller, *psi)
