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
* ``metallic``:     Metallic BSDF, Beckmann, physical conductor of IOR n and
  no extinction, roughness r: F·D(α = r²)·G/(4 cos θv), G the
  height-correlated Smith term 1/(1 + Λ(θl) + Λ(θv)) with Beckmann's rational
  Λ.  With α = s this is the paper's Gaussian facet term times G.  A *grey*
  closure: it has no colour input, so its weight is one number for all
  channels (a Mix Shader factor in the node group).
* ``ggx``:          Principled BSDF with a black base and GGX roughness r: its
  dielectric specular layer alone, F·D_GGX(α = r²)·G/(4 cos θv) with the
  height-correlated Smith G of GGX (Walter et al. 2007, Eqs. 33-34).  Grey.
  EEVEE renders every microfacet lobe as GGX, and Blender 4.2-4.5 have no
  exact dielectric Metallic, so these are their facet lobes.

Angles follow ``lut.models``: the light at polar angle θl and azimuth π, the
viewer at (θv, φ), φ = 0 the mirror direction."""

from __future__ import annotations

import dataclasses
import pathlib

import numpy as np

from .models import _validate


@dataclasses.dataclass(frozen=True)
class Closure:
    """One basis closure: its kind, the Toon size and smooth, the lobes' IOR
    and roughness, and ``fixed``: a weight the fit must not change (None:
    fitted)."""

    kind: str
    size: float = 0.0
    smooth: float = 0.0
    ior: float = 1.5
    roughness: float = 0.5
    fixed: float | None = None

    @property
    def grey(self) -> bool:
        return self.kind in ("metallic", "ggx")

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
        if self.kind == "metallic":
            from . import models

            alpha = self.roughness**2
            f = models.facet_reflection(theta_l, theta_v, phi, n=self.ior, slope=alpha, mueller=False)
            g = 1.0 / (1.0 + _beckmann_lambda(theta_l, alpha) + _beckmann_lambda(theta_v, alpha))
            return f * np.cos(theta_l) * g
        if self.kind == "ggx":
            return _ggx(theta_l, theta_v, phi, self.ior, self.roughness**2)
        raise ValueError(f"unknown closure kind {self.kind!r}")


def _ggx(theta_l, theta_v, phi, n, alpha):
    """GGX microfacet reflection with exact unpolarized dielectric Fresnel,
    per unit irradiance, cos θl included: F·D·G/(4 cos θv) (Walter et al.
    2007, Eqs. 33-34, with the height-correlated Smith G)."""
    from .models import fresnel

    sl, cl = np.sin(theta_l), np.cos(theta_l)
    sv, cv = np.sin(theta_v), np.cos(theta_v)
    # h ∝ l + v with l = (-sin θl, 0, cos θl), v = (sin θv cos φ, sin θv sin φ, cos θv).
    hx, hy, hz = sv * np.cos(phi) - sl, sv * np.sin(phi), cv + cl
    norm = np.sqrt(hx * hx + hy * hy + hz * hz)
    cos_h = hz / norm
    cos_d = np.clip((-sl * hx + cl * hz) / norm, 0.0, 1.0)
    a2 = alpha * alpha
    tan2_h = (1.0 - cos_h * cos_h) / (cos_h * cos_h)
    d = a2 / (np.pi * cos_h**4 * (a2 + tan2_h) ** 2)
    f = fresnel._unpolarized_reflectance(cos_d, fresnel.cos_refracted(cos_d, n), n)

    def lam(s, c):
        return 0.5 * (np.sqrt(1.0 + a2 * (s * s) / (c * c)) - 1.0)

    g = 1.0 / (1.0 + lam(sl, cl) + lam(sv, cv))
    return f * d * g / (4.0 * cv)


def _beckmann_lambda(theta, alpha):
    """Smith's Λ for Beckmann slopes, the usual rational approximation
    (Walter et al. 2007), in a = 1/(α tan θ)."""
    tan = np.tan(np.minimum(theta, np.pi / 2 - 1e-9))
    a = 1.0 / np.maximum(alpha * tan, 1e-300)
    ac = np.minimum(a, 1.6)  # Λ = 0 from a = 1.6 on
    lam = (1.0 - 1.259 * ac + 0.396 * ac * ac) / (3.535 * ac + 2.181 * ac * ac)
    return np.where(a < 1.6, lam, 0.0)


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


#: Gaussian slopes below this make facet lobes too sharp for the fit's light
#: sampling (24 polar x 24 azimuths): a GGX stand-in keeps the facet weight.
SHARP_SLOPE = 0.1

#: Render engines with a fit of their own.  Cycles evaluates every basis
#: closure exactly.  EEVEE renders Toon closures as Lambert (and its
#: microfacet lobes through GGX tables), so its fit uses only the closures it
#: renders as such: Lambert and the Metallic lobes.
TARGETS = ("CYCLES", "EEVEE")


def _target(target):
    if target not in TARGETS:
        raise ValueError(f"target must be one of {', '.join(TARGETS)}, got {target!r}")
    return target


def basis_for(paint, target="CYCLES", exact_metallic=True):
    """The closures a paint is fitted with: the smooth basis, plus for rough
    paints grey facet lobes.  With ``exact_metallic`` (Cycles in Blender 5):
    Metallic Beckmann lobes, for Gaussian slopes the paper's facet term
    exactly (roughness sqrt(slope)), for exponential slopes (which no closure
    reproduces) lobes of several roughnesses.  Otherwise (Blender 4.2-4.5)
    GGX lobes: one of the facet weight for sharp Gaussian slopes (below
    ``SHARP_SLOPE``), fitted ones of several roughnesses otherwise.  For
    EEVEE only the Lambert and facet closures (it draws Toon closures as
    Lambert; it draws the Metallic lobes as GGX, which measured closer than
    fitting GGX lobes: README)."""
    basis = smooth_basis() if _target(target) == "CYCLES" else [Closure("lambert")]
    if paint.slope > 0:
        n = float(paint.index_at(589.3))
        gaussian = paint.distribution == "gaussian" and paint.slope <= 1.0
        if exact_metallic and gaussian:
            basis.append(Closure("metallic", ior=n, roughness=float(np.sqrt(paint.slope))))
        elif exact_metallic:
            basis += [Closure("metallic", ior=n, roughness=r) for r in (0.5, 0.7, 0.85, 1.0)]
        elif gaussian and paint.slope < SHARP_SLOPE:
            # GGX of the same alpha has the Beckmann lobe's peak, D(0) =
            # 1/(pi alpha^2), and heavier tails: keep the facet weight rather
            # than fit a sharp lobe the fit's sampling cannot resolve.
            basis.append(Closure("ggx", ior=n, roughness=float(np.sqrt(paint.slope)), fixed=paint.facet))
        else:
            centre = float(np.sqrt(paint.slope)) if gaussian else 0.7
            roughness = np.unique(np.clip(np.round(centre * np.array([0.7, 0.85, 1.0, 1.2]), 3), 0.05, 1.0))
            basis += [Closure("ggx", ior=n, roughness=float(r)) for r in roughness]
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


#: Closures kept in a fit: render time grows with their number.  6 is the knee
#: measured by scripts/render_cost.py and the fidelity tests (README).
MAX_CLOSURES = 6


def fit(
    paint,
    views=32,
    light_polar=24,
    azimuths=24,
    basis=None,
    max_closures=MAX_CLOSURES,
    target="CYCLES",
    exact_metallic=True,
) -> Fit:
    """As ``fit_all``, keeping at most ``max_closures`` closures: those that
    carry the most of the fitted radiance (summed over views, channels and
    light directions), refitted on their own."""
    full = fit_all(paint, views, light_polar, azimuths, basis or basis_for(paint, target, exact_metallic))
    max_closures = _validate.positive_int(max_closures, "max_closures")
    if len(full.basis) <= max_closures:
        return full
    cos_light = np.linspace(np.cos(np.radians(88.0)), 1.0, light_polar)
    theta_l = np.arccos(cos_light)[:, None]
    phi = np.linspace(0.0, np.pi, azimuths)[None, :]
    energy = np.zeros(len(full.basis))
    for j, cv in enumerate(full.cos_view):
        theta_v = float(np.arccos(np.clip(cv, np.cos(np.radians(89.5)), 1.0)))
        for k, c in enumerate(full.basis):
            energy[k] += np.sum(c.evaluate(theta_l, theta_v, phi) * np.cos(theta_l)) * full.weights[k, j].sum()
    energy[[k for k, c in enumerate(full.basis) if c.fixed is not None]] = np.inf  # always kept
    keep = sorted(np.argsort(energy)[::-1][:max_closures])
    return fit_all(paint, views, light_polar, azimuths, [full.basis[k] for k in keep])


def fit_all(paint, views=32, light_polar=24, azimuths=24, basis=None) -> Fit:
    """Fit a paint's non-delta BRDF · cos θl, per view cosine, as a
    non-negative combination of ``basis`` closures (default ``basis_for``):
    one NNLS per view over the three channels together, coloured closures
    with a weight per channel and grey ones with one weight shared by all,
    rows weighted by cos θl as the fidelity measure is; closures with a
    ``fixed`` weight keep it and the others fit what they leave.  A smooth
    interface's mirror reflection is a delta: it is carried by a mirror
    closure of weight ``paint.facet`` with the exact Fresnel reflectance."""
    basis = basis or basis_for(paint)
    views = _validate.positive_int(views, "views", 2)
    cos_view = np.linspace(0.0, 1.0, views)
    cos_light = np.linspace(np.cos(np.radians(88.0)), 1.0, light_polar)
    theta_l = np.arccos(cos_light)[:, None]
    phi = np.linspace(0.0, np.pi, azimuths)[None, :]
    colour = [k for k, c in enumerate(basis) if not c.grey and c.fixed is None]
    grey = [k for k, c in enumerate(basis) if c.grey and c.fixed is None]
    pinned = [k for k, c in enumerate(basis) if c.fixed is not None]
    weights = np.zeros((len(basis), views, 3))
    for k in pinned:
        weights[k] = basis[k].fixed
    row_w = np.broadcast_to(np.cos(theta_l), (light_polar, azimuths)).ravel()
    num = den = 0.0
    for j, cv in enumerate(cos_view):
        theta_v = float(np.arccos(np.clip(cv, np.cos(np.radians(89.5)), 1.0)))
        target = paint.brdf(theta_l, theta_v, phi) * np.cos(theta_l)[..., None]  # (L, P, 3)
        a = np.stack([c.evaluate(theta_l, theta_v, phi).ravel() for c in basis], axis=1) * row_w[:, None]
        b = np.concatenate([target[..., ch].ravel() * row_w for ch in range(3)])
        full_b = b
        if pinned:
            b = b - np.tile(a[:, pinned] @ weights[pinned, j, 0], 3)
        rows = a.shape[0]
        big = np.zeros((3 * rows, 3 * len(colour) + len(grey)))
        for ch in range(3):
            big[ch * rows : (ch + 1) * rows, ch * len(colour) : (ch + 1) * len(colour)] = a[:, colour]
            big[ch * rows : (ch + 1) * rows, 3 * len(colour) :] = a[:, grey]
        x = nnls(big, b)
        grey_w = x[3 * len(colour) :]
        if np.any(grey_w > 1.0):
            # A grey closure's weight is a Mix Shader factor, which clamps at
            # 1 (weights above 1 only occur near grazing, where Cycles'
            # shadowing darkens the lobe): cap them and refit the rest.
            x[3 * len(colour) :] = np.minimum(grey_w, 1.0)
            fixed = big[:, 3 * len(colour) :] @ x[3 * len(colour) :]
            x[: 3 * len(colour)] = nnls(big[:, : 3 * len(colour)], b - fixed)
        for ch in range(3):
            weights[colour, j, ch] = x[ch * len(colour) : (ch + 1) * len(colour)]
            weights[grey, j, ch] = x[3 * len(colour) :]
        num += np.sum((big @ x - b) ** 2)
        den += np.sum(full_b**2)
    # Closures with zero weight at every view cost render time for nothing.
    used = [k for k in range(len(basis)) if weights[k].max() > 0]
    mirror = paint.facet if paint.slope == 0 else 0.0
    return Fit([basis[k] for k in used], cos_view, weights[used], mirror, float(np.sqrt(num / den)))


def save_weights(fitted: Fit, path) -> pathlib.Path:
    """Write the weights as a Non-Color float EXR of K rows (closures) by M
    columns (view cosines 0..1), RGB: row k counted from the bottom (where a
    Blender image texture has v = 0), column j holds w_k(cos θv_j)."""
    from . import lutfile

    return lutfile.write_exr(path, fitted.weights[::-1], {"paintlut:closures": repr(fitted.basis)})


def weights_path(lut_path, target="CYCLES") -> pathlib.Path:
    """The weights file of a target beside its LUT: ``paintfit-<key>.exr``
    (Cycles) or ``paintfit-eevee-<key>.exr`` next to ``paintlut-<key>.exr``."""
    lut_path = pathlib.Path(lut_path)
    prefix = "paintfit-" if _target(target) == "CYCLES" else f"paintfit-{target.lower()}-"
    return lut_path.with_name(lut_path.name.replace("paintlut-", prefix))


def fit_for_lut(paint, lut_path, exact_metallic=True) -> dict:
    """The closure fits of a baked paint, one per render engine, with their
    weights files beside the LUT: {target: (Fit, weights path)}.
    ``exact_metallic``: whether Blender's Metallic BSDF is the exact
    dielectric lobe (Blender 5); if not, GGX lobes for Cycles too."""
    fits = {}
    for target in TARGETS:
        fitted = fit(paint, target=target, exact_metallic=exact_metallic)
        fits[target] = (fitted, save_weights(fitted, weights_path(lut_path, target)))
    return fits
