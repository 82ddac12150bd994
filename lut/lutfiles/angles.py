"""Rusinkiewicz's half/difference angles (S. Rusinkiewicz, "A New Change of
Variables for Efficient BRDF Representation", EGWR 1998), in the model
core's conventions (lut.models): the source at azimuth π, the viewer at φs.

An isotropic BRDF depends on (θh, θd, φd) alone; reciprocity adds
f(φd) = f(φd + π) and mirror symmetry about the plane of incidence
f(φd) = f(-φd), so φd ∈ [0, π/2] holds every value (tests check both on the
models)."""

from __future__ import annotations

import numpy as np


def _normalize(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def to_half_diff(theta_i, theta_s, phi_s):
    """(θh, θd, φd) of the light direction ω_i = (-sin θi, 0, cos θi) and the
    view direction ω_o = (sin θs cos φs, sin θs sin φs, cos θs), with φd
    folded into [0, π/2]."""
    theta_h, theta_d, phi_d, _ = half_diff_signed(theta_i, theta_s, phi_s)
    phi_d = np.abs(phi_d)  # mirror symmetry: φd -> -φd
    phi_d = np.where(phi_d > np.pi / 2, np.pi - phi_d, phi_d)  # reciprocity and mirror: φd -> π - φd
    return theta_h, theta_d, phi_d


def half_diff_signed(theta_i, theta_s, phi_s):
    """(θh, θd, φd, φh) of model angles with φd in (-π, π], unfolded, and
    φh the half vector's azimuth in the models' frame (where the source
    lies at azimuth π): ω_i = R_z(φh) R_y(θh) d."""
    theta_i, theta_s, phi_s = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (theta_i, theta_s, phi_s)))
    wi = np.stack((-np.sin(theta_i), np.zeros_like(theta_i), np.cos(theta_i)), -1)
    st = np.sin(theta_s)
    wo = np.stack((st * np.cos(phi_s), st * np.sin(phi_s), np.cos(theta_s)), -1)
    h = wi + wo
    norm = np.linalg.norm(h, axis=-1, keepdims=True)
    h = np.where(norm > 1e-12, h / np.where(norm > 1e-12, norm, 1.0), np.array([0.0, 0.0, 1.0]))
    theta_h = np.arccos(np.clip(h[..., 2], -1.0, 1.0))
    phi_h = np.arctan2(h[..., 1], h[..., 0])
    # d = R_y(-θh) R_z(-φh) ω_i
    c, s = np.cos(-phi_h), np.sin(-phi_h)
    x = c * wi[..., 0] - s * wi[..., 1]
    y = s * wi[..., 0] + c * wi[..., 1]
    z = wi[..., 2]
    c, s = np.cos(-theta_h), np.sin(-theta_h)
    dx, dz = c * x + s * z, -s * x + c * z
    theta_d = np.arccos(np.clip(dz, -1.0, 1.0))
    return theta_h, theta_d, np.arctan2(y, dx), phi_h


def half_frame_rays(theta_h, theta_d, phi_d):
    """Unit vectors towards the light and the viewer in the half frame (the
    half vector at azimuth 0): ω_i = R_y(θh) d and ω_o = R_y(θh) d', d' the
    mirror of d about the half vector, each broadcast(angles) + (3,)."""
    theta_h, theta_d, phi_d = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (theta_h, theta_d, phi_d)))
    d = np.stack((np.sin(theta_d) * np.cos(phi_d), np.sin(theta_d) * np.sin(phi_d), np.cos(theta_d)), -1)
    c, s = np.cos(theta_h), np.sin(theta_h)

    def rot(v):
        return np.stack((c * v[..., 0] + s * v[..., 2], v[..., 1], -s * v[..., 0] + c * v[..., 2]), -1)

    return rot(d), rot(d * np.array([-1.0, -1.0, 1.0]))


def from_half_diff(theta_h, theta_d, phi_d):
    """(θi, θs, φs) of half/difference angles (any φh: the BRDF is isotropic,
    so φh = 0 is used).  θi or θs >= π/2 lie below the horizon."""
    wi, wo = half_frame_rays(theta_h, theta_d, phi_d)
    theta_i = np.arccos(np.clip(wi[..., 2], -1.0, 1.0))
    theta_s = np.arccos(np.clip(wo[..., 2], -1.0, 1.0))
    phi_light = np.arctan2(wi[..., 1], wi[..., 0])
    phi_view = np.arctan2(wo[..., 1], wo[..., 0])
    # The source sits at azimuth π in the model convention.
    return theta_i, theta_s, np.mod(phi_view - phi_light + np.pi + np.pi, 2 * np.pi) - np.pi
