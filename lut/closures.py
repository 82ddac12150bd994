"""Blender closures as functions of the light and view directions, and the
fit of a paint's BRDF onto them (numpy only).

Blender's shader nodes see the view direction, never the light's; only
closures depend on the light.  So a paint is rendered as Σ_k w_k(θv)·b_k(l, v):
closures b_k whose light dependence Cycles evaluates exactly, with weights
that depend on the view alone (read from a texture by Incoming·Normal).

Each basis function returns the closure's contribution per unit irradiance,
cos θl included (what Cycles' eval returns), for a white closure:

* ``lambert``:      Diffuse BSDF, cos θl / π.
* ``diffuse_toon``: Diffuse Toon BSDF (size a, smooth s), I(θl)/(2π(1 - cos θm)),
  I = 1 below a·π/2 falling linearly to 0 over s·π/2, θm = min((a + s)·π/2, π/2)
  (Cycles' bsdf_toon.h; checked against renders in tests).
* ``glossy_toon``:  Glossy Toon BSDF, the same in the angle between l and the
  mirror of v.

Angles follow ``lut.models``: the light at polar angle θl and azimuth π, the
viewer at (θv, φ), φ = 0 the mirror direction."""

from __future__ import annotations

import dataclasses
import pathlib

import numpy as np

from .models import _validate


@dataclasses.dataclass(frozen=True)
class Closure:
    """One basis closure: kind 'lambert', 'diffuse_toon' or 'glossy_toon',
    with the Toon size and smooth."""

    kind: str
    size: float = 0.0
    smooth: float = 0.0

    def evaluate(self, theta_l, theta_v, phi):
        if self.kind == "lambert":
            return np.cos(theta_l) / np.pi * np.ones(np.broadcast(theta_l, theta_v, phi).shape)
        if self.kind == "diffuse_toon":
            return _toon(np.broadcast_to(theta_l, np.broadcast(theta_l, theta_v, phi).shape), self.size, self.smooth)
        if self.kind == "glossy_toon":
            # Mirror of the view direction: (-sin θv cos φ, -sin θv sin φ, cos θv)
            # against the light (-sin θl, 0, cos θl).
            cos_rl = np.sin(theta_v) * np.cos(phi) * np.sin(theta_l) + np.cos(theta_v) * np.cos(theta_l)
            angle = np.arccos(np.clip(cos_rl, 0.0, 1.0))
            return _toon(angle, self.size, self.smooth)
        raise ValueError(f"unknown closure kind {self.kind!r}")


def _toon(angle, size, smooth):
    a = np.clip(size, 1e-5, 1.0) * np.pi / 2
    s = np.clip(smooth, 0.0, 1.0) * np.pi / 2
    ramp = np.clip(1.0 - (angle - a) / s, 0.0, 1.0) if s > 0 else np.zeros_like(angle)
    intensity = np.where(angle < a, 1.0, ramp)
    theta_max = min(a + s, np.pi / 2)
    return intensity / (2.0 * np.pi * (1.0 - np.cos(theta_max)))


def smooth_basis():
    """The closures used for smooth paints: Lambert, Diffuse Toon ramps for
    the light-side fall-off of the subsurface terms, Glossy Toon ramps for the
    view-dependent single scattering."""
    basis = [Closure("lambert"), Closure("diffuse_toon", 1e-5, 1.0)]
    basis += [Closure("diffuse_toon", a, s) for a in (0.3, 0.5, 0.6, 0.7, 0.8, 0.9) for s in (0.1, 0.3)]
    basis += [Closure("glossy_toon", a, 0.3) for a in (0.2, 0.4, 0.6, 0.8)]
    return basis


def nnls(a, b, tol=None, max_iter=None):
    """Non-negative least squares min ‖a x - b‖, x >= 0 (Lawson and Hanson,
    *Solving Least Squares Problems*, 1974, ch. 23)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    m, n = a.shape
    tol = tol if tol is not None else 10 * max(m, n) * np.finfo(float).eps * np.abs(a).max()
    max_iter = max_iter or 3 * n
    x = np.zeros(n)
    passive = np.zeros(n, dtype=bool)
    w = a.T @ (b - a @ x)
    for _ in range(max_iter):
        if passive.all() or w[~passive].max() <= tol:
            break
        j = np.argmax(np.where(passive, -np.inf, w))
        passive[j] = True
        while True:
            z = np.zeros(n)
            z[passive] = np.linalg.lstsq(a[:, passive], b, rcond=None)[0]
            if z[passive].min() > 0:
                x = z
                break
            neg = passive & (z <= 0)
            alpha = np.min(x[neg] / (x[neg] - z[neg]))
            x = x + alpha * (z - x)
            passive &= x > tol
            x[~passive] = 0.0
        w = a.T @ (b - a @ x)
    return x


@dataclasses.dataclass
class Fit:
    """Per-view closure weights: ``weights`` (K, M, 3) for the basis at view
    cosines ``cos_view`` (M,), the mirror reflectance weight, and the fit's
    cos-weighted relative RMS error on its own samples."""

    basis: list
    cos_view: np.ndarray
    weights: np.ndarray
    mirror: float
    error: float


def fit(paint, views=32, light_polar=24, azimuths=24, basis=None) -> Fit:
    """Fit a smooth paint's non-delta BRDF · cos θl, per view cosine, as a
    non-negative combination of ``basis`` closures (NNLS per channel, rows
    weighted by cos θl as the fidelity measure is).  The smooth interface's
    mirror reflection is a delta: it is carried by a mirror closure of weight
    ``paint.facet`` with the exact Fresnel reflectance."""
    if paint.slope > 0:
        raise ValueError("closure fits of rough paints are not implemented yet (slope must be 0)")
    basis = basis or smooth_basis()
    views = _validate.positive_int(views, "views", 2)
    cos_view = np.linspace(0.0, 1.0, views)
    cos_light = np.linspace(np.cos(np.radians(88.0)), 1.0, light_polar)
    theta_l = np.arccos(cos_light)[:, None]
    phi = np.linspace(0.0, np.pi, azimuths)[None, :]
    weights = np.zeros((len(basis), views, 3))
    num = den = 0.0
    for j, cv in enumerate(cos_view):
        theta_v = float(np.arccos(np.clip(cv, np.cos(np.radians(89.5)), 1.0)))
        target = paint.brdf(theta_l, theta_v, phi) * np.cos(theta_l)[..., None]  # (L, P, 3)
        a = np.stack([c.evaluate(theta_l, theta_v, phi).ravel() for c in basis], axis=1)
        row_w = np.broadcast_to(np.cos(theta_l), target.shape[:2]).ravel()
        for ch in range(3):
            b = target[..., ch].ravel()
            weights[:, j, ch] = nnls(a * row_w[:, None], b * row_w)
            resid = (a @ weights[:, j, ch] - b) * row_w
            num += np.sum(resid**2)
            den += np.sum((b * row_w) ** 2)
    return Fit(basis, cos_view, weights, paint.facet, float(np.sqrt(num / den)))


def save_weights(fitted: Fit, path) -> pathlib.Path:
    """Write the weights as a Non-Color float EXR of K rows (closures) by M
    columns (view cosines 0..1), RGB: row k counted from the bottom (where a
    Blender image texture has v = 0), column j holds w_k(cos θv_j)."""
    from . import lutfile

    return lutfile.write_exr(path, fitted.weights[::-1], {"paintlut:closures": repr(fitted.basis)})


def fit_for_lut(paint, lut_path):
    """The closure fit of a baked paint and its weights file beside the LUT
    (``paintfit-<key>.exr`` next to ``paintlut-<key>.exr``); (None, None) for
    rough paints, whose fit is not implemented yet."""
    if paint.slope > 0:
        return None, None
    fitted = fit(paint)
    lut_path = pathlib.Path(lut_path)
    return fitted, save_weights(fitted, lut_path.with_name(lut_path.name.replace("paintlut-", "paintfit-")))
