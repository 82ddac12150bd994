"""Blender closures as functions of the light and view directions (numpy
only), and the candidate closures a paint type is fitted with
(``lut.render.fitting``).

Blender's shader nodes see the view direction, never the light's; only
closures depend on the light.  So a paint is rendered as Σ_k w_k(θv)·b_k(l, v):
closures b_k whose light dependence the renderer evaluates, with weights that
depend on the view alone (read from a texture by Incoming·Normal).

Each kind in ``CLOSURE_KINDS`` returns the closure's contribution per unit
irradiance, cos θl included (what Cycles' eval returns), for a white closure:

* ``lambert``:      Diffuse BSDF, cos θl / π.
* ``diffuse_toon``: Diffuse Toon BSDF (size a, smooth s), I(θl)/(2π(1 - cos θm)),
  I = 1 below a·π/2 falling linearly to 0 over s·π/2, θm = min((a + s)·π/2, π/2)
  (Cycles' bsdf_toon.h; checked against renders in tests).
* ``glossy_toon``:  Glossy Toon BSDF, the same in the angle between l and the
  mirror of v.
* ``retro_toon``:   Diffuse Toon BSDF with the view direction as its normal:
  the same ramp in the angle between l and v (a retro-reflection lobe),
  times Cycles' bump shadowing term.
* ``oren_nayar``:   Diffuse BSDF of roughness σ at unit albedo (one closure
  per channel in the node group).
* ``sheen``:        Sheen BSDF, Ashikhmin velvet of roughness σ.
* ``glossy``:       Glossy BSDF, Beckmann, roughness r: D(α = r²)·G/(4 cos θv)
  with no Fresnel factor (Cycles' Glossy BSDF is a white microfacet lobe
  tinted by its colour), G the height-correlated Smith term
  1/(1 + Λ(θl) + Λ(θv)) with Beckmann's rational Λ (Walter et al., "Microfacet
  models for refraction through rough surfaces", EGSR 2007, Eqs. 25-27).
  A coloured lobe.
* ``metallic``:     Metallic BSDF, Beckmann, physical conductor of IOR n and
  no extinction, roughness r: F·D(α = r²)·G/(4 cos θv).  With α = s this is
  the paper's Gaussian facet term (Eq. 31 with Eq. 33) times G.  A *grey*
  closure: it has no colour input, so its weight is one number for all
  channels (a Mix Shader factor in the node group).
* ``retro_glossy``: Glossy BSDF, GGX of roughness r, whose Normal input is
  the view direction (Geometry › Incoming): the white GGX lobe
  D·G/(4 cos θv') in the frame of that normal, where θv' = 0 and the light
  is at the angle γ between l and v: a retro-reflection lobe that EEVEE
  draws as a reflection closure (``lut.render.eevee``; EEVEE draws the retro Toon
  as Lambert about the view, a diffuse closure of a normal of its own).
* ``ggx``:          Principled BSDF with a black base and GGX roughness r: its
  dielectric specular layer alone, F·D_GGX(α = r²)·G/(4 cos θv) with the
  height-correlated Smith G of GGX (Walter et al. 2007, Eqs. 33-34).  Grey.
  Blender 4.2-4.5 have no exact dielectric Metallic, so these are their
  facet lobes.
* ``diffuse_ramp``: one knot j of OSL's ``diffuse_ramp(N, colors[8])``
  (Cycles' bsdf_diffuse_ramp.h, OSL only: CPU and OptiX): the ramp over
  cos θl, linear between 8 knots at cos θl = j/7, divided by π and with no
  further cos θl, so a knot's closure is hat_j(cos θl)/π with
  hat_j(x) = max(0, 1 - |7x - j|).  Its weight is **signed**: OSL passes the
  ramp colours unclamped, and a correction of the other closures may be
  negative (``lut.render.fitting``, "OSL ramps").
* ``phong_ramp``:   one knot j of OSL's ``phong_ramp(N, e, colors[8])``
  (Cycles' bsdf_phong_ramp.h): with p = (R·l)^e, R the mirror of the view,
  hat_j(p)·p·(e + 2)/(2π)·cos θl where R·l > 0, else 0.  Signed.
* ``retro_ramp``:   one knot j of OSL's ``diffuse_ramp(V, colors[8])`` with
  the view direction V as its normal: the ramp over cos γ, γ the angle
  between the light and the viewer, divided by π, times Cycles' bump
  shadowing term for a diffuse closure whose normal is not the surface's
  (as ``retro_toon``), where the light is above the surface and l·v > 0.
  Signed: a lobe about the retro-reflection direction, for back-scattering
  pigments (g < 0), which neither other ramp follows.

Angles follow ``lut.models``: the light at polar angle θl and azimuth π, the
viewer at (θv, φ), φ = 0 the mirror direction."""

from __future__ import annotations

import dataclasses

import numpy as np

from ..models import facet, fresnel
from ..paint.core import reference_index


@dataclasses.dataclass(frozen=True)
class Closure:
    """One basis closure: its kind (a key of ``CLOSURE_KINDS``), the Toon
    size and smooth, the lobes' IOR and roughness, and for an OSL ramp's
    knot its index (0 to ``RAMP_KNOTS`` - 1) and the Phong ramp's exponent."""

    kind: str
    size: float = 0.0
    smooth: float = 0.0
    ior: float = 1.5
    roughness: float = 0.5
    knot: int = 0
    exponent: float = 1.0

    def __post_init__(self):
        validate_kind(self.kind)

    @property
    def grey(self) -> bool:
        """Whether the closure has no colour input (its weight is a Mix Shader factor)."""
        return CLOSURE_KINDS[self.kind].grey

    @property
    def cost(self) -> int:
        """Closures it takes in a material (the render cost budget's unit)."""
        return CLOSURE_KINDS[self.kind].cost

    @property
    def max_weight(self) -> float:
        """The largest weight the node group can give it: 1 where the weight
        is a Mix Shader factor (grey lobes, and Oren-Nayar's per-channel
        closures of unit colour)."""
        return 1.0 if self.grey or self.kind == "oren_nayar" else np.inf

    @property
    def osl(self) -> bool:
        """Whether only Cycles' OSL shading draws it (a ramp knot: the ramps' Script node)."""
        return CLOSURE_KINDS[self.kind].osl

    def evaluate(self, theta_l, theta_v, phi):
        """Contribution per unit irradiance (cos θl included), broadcast shape."""
        theta_l, theta_v, phi = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (theta_l, theta_v, phi)))
        return CLOSURE_KINDS[self.kind].evaluate(self, theta_l, theta_v, phi)

    def to_dict(self) -> dict:
        """Its fields; a ramp's knot and exponent only for the ramps (the
        other kinds' headers stay as they were)."""
        out = dataclasses.asdict(self)
        if not self.osl:
            del out["knot"], out["exponent"]
        return out


def _toon(angle, size, smooth):
    a = np.clip(size, 1e-5, 1.0) * np.pi / 2
    s = np.clip(smooth, 0.0, 1.0) * np.pi / 2
    ramp = np.clip(1.0 - (angle - a) / s, 0.0, 1.0) if s > 0 else np.zeros_like(angle)
    intensity = np.where(angle < a, 1.0, ramp)
    theta_max = min(a + s, np.pi / 2)
    return intensity / (2.0 * np.pi * (1.0 - np.cos(theta_max)))


def _lambert(closure, theta_l, theta_v, phi):
    return np.cos(theta_l) / np.pi


def _diffuse_toon(closure, theta_l, theta_v, phi):
    return _toon(theta_l, closure.size, closure.smooth)


def _glossy_toon(closure, theta_l, theta_v, phi):
    """Cycles' Glossy Toon BSDF: the ramp in the angle between the light and
    the mirror of the view, (-sin θv cos φ, -sin θv sin φ, cos θv) against
    (-sin θl, 0, cos θl), dark outside its sampling cone min(size + smooth,
    90°) (Cycles' bsdf_glossy_toon_eval evaluates only inside that cone: a
    lobe whose size + smooth passes 90° is cut off there, not ramped on)."""
    cos_rl = np.sin(theta_v) * np.cos(phi) * np.sin(theta_l) + np.cos(theta_v) * np.cos(theta_l)
    angle = np.arccos(np.clip(cos_rl, 0.0, 1.0))
    cone = min(np.clip(closure.size, 1e-5, 1.0) + np.clip(closure.smooth, 0.0, 1.0), 1.0) * np.pi / 2
    return np.where(angle < cone, _toon(angle, closure.size, closure.smooth), 0.0)


def _retro_toon(closure, theta_l, theta_v, phi):
    """Diffuse Toon BSDF whose Normal input is the view direction (Geometry ›
    Incoming): the ramp in the angle between the light and the viewer, a lobe
    around the retro-reflection direction that no other closure has (for
    back-scattering pigments, g < 0).  Cycles softens a diffuse closure whose
    normal differs from the surface's by the microfacet shadowing of Conty
    Estevez et al. ("A Microfacet-Based Shadowing Function to Solve the Bump
    Terminator Problem", Ray Tracing Gems, 2019, ch. 12): GGX's G1 at cos θl
    with α² = tan²θv/8 (Cycles' bump_shadowing_term, with the material's
    bump map correction on, its default)."""
    cos_lv = cos_light_view(theta_l, theta_v, phi)
    ramp = _toon(np.arccos(np.clip(cos_lv, 0.0, 1.0)), closure.size, closure.smooth)
    up = (theta_l < np.pi / 2) & (theta_v < np.pi / 2) & (cos_lv > 0)
    return np.where(up, ramp * bump_shadowing(theta_l, theta_v), 0.0)


def _half_vector(theta_l, theta_v, phi):
    """cos θh and cos θd of the light (-sin θl, 0, cos θl) and the view
    (sin θv cos φ, sin θv sin φ, cos θv)."""
    sl, cl = np.sin(theta_l), np.cos(theta_l)
    sv, cv = np.sin(theta_v), np.cos(theta_v)
    hx, hy, hz = sv * np.cos(phi) - sl, sv * np.sin(phi), cv + cl
    norm = np.maximum(np.sqrt(hx * hx + hy * hy + hz * hz), 1e-300)
    return hz / norm, np.clip((-sl * hx + cl * hz) / norm, 0.0, 1.0)


def _beckmann_lambda(theta, alpha):
    """Smith's Λ for Beckmann slopes, the rational approximation of Walter et
    al. 2007 (Eq. 27), in a = 1/(α tan θ)."""
    tan = np.tan(np.minimum(theta, np.pi / 2 - 1e-9))
    a = 1.0 / np.maximum(alpha * tan, 1e-300)
    ac = np.minimum(a, 1.6)  # Λ = 0 from a = 1.6 on
    lam = (1.0 - 1.259 * ac + 0.396 * ac * ac) / (3.535 * ac + 2.181 * ac * ac)
    return np.where(a < 1.6, lam, 0.0)


def _beckmann_lobe(theta_l, theta_v, phi, alpha):
    """D·G/(4 cos θv) of a Beckmann lobe (no Fresnel), cos θl included."""
    cos_h, _ = _half_vector(theta_l, theta_v, phi)
    cos_h = np.maximum(cos_h, 1e-12)
    tan2 = (1.0 - cos_h * cos_h) / (cos_h * cos_h)
    d = np.exp(-tan2 / (alpha * alpha)) / (np.pi * alpha * alpha * cos_h**4)
    g = 1.0 / (1.0 + _beckmann_lambda(theta_l, alpha) + _beckmann_lambda(theta_v, alpha))
    up = (theta_l < np.pi / 2) & (theta_v < np.pi / 2)
    return np.where(up, d * g / (4.0 * np.maximum(np.cos(theta_v), 1e-12)), 0.0)


def _glossy(closure, theta_l, theta_v, phi):
    return _beckmann_lobe(theta_l, theta_v, phi, max(closure.roughness, 1e-3) ** 2)


def _metallic(closure, theta_l, theta_v, phi):
    alpha = max(closure.roughness, 1e-3) ** 2
    f = facet.facet_reflection(theta_l, theta_v, phi, n=closure.ior, slope=alpha, mueller=False)
    g = 1.0 / (1.0 + _beckmann_lambda(theta_l, alpha) + _beckmann_lambda(theta_v, alpha))
    return f * np.cos(theta_l) * g


def ggx_lobe(theta_l, theta_v, phi, roughness):
    """The white GGX lobe D·G/(4 cos θv) of α = r², cos θl included, with
    the height-correlated Smith G (Walter et al. 2007, Eqs. 33-34), and
    cos θd (for a Fresnel factor): (lobe, cos θd)."""
    alpha = max(float(roughness), 1e-3) ** 2
    cos_h, cos_d = _half_vector(theta_l, theta_v, phi)
    cos_h = np.maximum(cos_h, 1e-12)
    a2 = alpha * alpha
    tan2_h = (1.0 - cos_h * cos_h) / (cos_h * cos_h)
    d = a2 / (np.pi * cos_h**4 * (a2 + tan2_h) ** 2)

    def lam(theta):
        t = np.tan(np.minimum(theta, np.pi / 2 - 1e-9))
        return 0.5 * (np.sqrt(1.0 + a2 * t * t) - 1.0)

    g = 1.0 / (1.0 + lam(theta_l) + lam(theta_v))
    up = (theta_l < np.pi / 2) & (theta_v < np.pi / 2)
    return np.where(up, d * g / (4.0 * np.maximum(np.cos(theta_v), 1e-12)), 0.0), cos_d


def _ggx(closure, theta_l, theta_v, phi):
    """GGX microfacet reflection with exact unpolarized dielectric Fresnel,
    per unit irradiance, cos θl included: F·D·G/(4 cos θv) (Walter et al.
    2007, Eqs. 33-34, with the height-correlated Smith G)."""
    lobe, cos_d = ggx_lobe(theta_l, theta_v, phi, closure.roughness)
    rs, rp = fresnel.reflection_coefficients(cos_d, closure.ior)
    return lobe * 0.5 * (np.abs(rs) ** 2 + np.abs(rp) ** 2)


def cos_light_view(theta_l, theta_v, phi):
    """cos γ = l·v of the light (-sin θl, 0, cos θl) and the view
    (sin θv cos φ, sin θv sin φ, cos θv)."""
    return -np.sin(theta_l) * np.sin(theta_v) * np.cos(phi) + np.cos(theta_l) * np.cos(theta_v)


def light_view_angle(theta_l, theta_v, phi):
    """The angle γ between the light and the view (``cos_light_view``)."""
    return np.arccos(np.clip(cos_light_view(theta_l, theta_v, phi), -1.0, 1.0))


def _retro_glossy(closure, theta_l, theta_v, phi):
    """GGX lobe about the view direction: in the frame of that normal the
    viewer is at θv' = 0 and the light at γ (``light_view_angle``); lights
    below the surface stay dark."""
    gamma = light_view_angle(theta_l, theta_v, phi)
    zero = np.zeros_like(gamma)
    lobe, _ = ggx_lobe(gamma, zero, zero, closure.roughness)
    return np.where((theta_l < np.pi / 2) & (theta_v < np.pi / 2), lobe, 0.0)


def _sheen(closure, theta_l, theta_v, phi):
    """Cycles' Sheen BSDF, Ashikhmin velvet of roughness σ: D·G/(4 cos θv)
    with D = exp(-cot²θh/σ²)/(π σ² sin⁴θh) and G = min(1, 2 cos θh cos θ/cos θd)
    over θ = θl, θv (Ashikhmin et al., "A microfacet-based BRDF generator",
    SIGGRAPH 2000; Cycles' bsdf_ashikhmin_velvet.h)."""
    inv = 1.0 / max(closure.roughness, 0.01) ** 2
    cos_h, cos_d = _half_vector(theta_l, theta_v, phi)
    sin2 = 1.0 - cos_h * cos_h
    ok = (np.abs(cos_h) < 1.0 - 1e-5) & (cos_d > 1e-5) & (theta_l < np.pi / 2) & (theta_v < np.pi / 2)
    sin2 = np.where(ok, sin2, 1.0)
    d = np.exp(-cos_h * cos_h / sin2 * inv) * inv / (np.pi * sin2 * sin2)
    ratio = np.maximum(cos_h / np.where(ok, cos_d, 1.0), 1e-5)
    g = np.minimum(1.0, np.minimum(2 * ratio * np.cos(theta_l), 2 * ratio * np.cos(theta_v)))
    return np.where(ok, 0.25 * d * g / np.maximum(np.cos(theta_v), 1e-12), 0.0)


def _oren_nayar_g(cos_t):
    """The directional albedo term of Cycles' energy-compensated Oren-Nayar
    (Fujii's improved model plus OpenPBR's multiple scattering term)."""
    cos_t = np.clip(cos_t, 1e-6, 1.0)
    sin_t = np.sqrt(1.0 - cos_t * cos_t)
    theta = np.arccos(cos_t)
    return sin_t * (theta - 2.0 / 3.0 - sin_t * cos_t) + 2.0 / 3.0 * (sin_t / cos_t) * (1.0 - sin_t**3)


def _oren_nayar(closure, theta_l, theta_v, phi):
    """Cycles' Diffuse BSDF of roughness σ at a unit albedo (the node group
    gives each channel its own closure of unit colour, so the albedo-dependent
    multiple scattering term stays linear): Fujii's improved Oren-Nayar,
    cos θl·(A + B·t) with t = max(0, cos φ'·sin θl sin θv)/max(cos θl, cos θv)
    (Y. Fujii, "A tiny improvement of Oren-Nayar reflectance model", 2013),
    plus the multiple scattering term of the OpenPBR specification,
    E_ms(1 - E(θv))(1 - E(θl))·cos θl."""
    sigma = float(np.clip(closure.roughness, 0.0, 1.0))
    a = 1.0 / (np.pi + sigma * (np.pi / 2 - 2.0 / 3.0))
    b = sigma * a
    cl, cv = np.cos(theta_l), np.cos(theta_v)
    # l·v with l = (-sin θl, 0, cos θl) and v = (sin θv cos φ, sin θv sin φ, cos θv).
    t = -np.sin(theta_l) * np.sin(theta_v) * np.cos(phi) + cl * cv - cl * cv
    t = np.where(t > 0, t / (np.maximum(cl, cv) + 1e-38), t)
    e_avg = a * np.pi + (2 * np.pi - 5.6) / 3.0 * b
    e_ms = (1.0 / np.pi) * e_avg / (1.0 - e_avg) / (1.0 - (1.0 - e_avg))
    e_l = a * np.pi + b * _oren_nayar_g(cl)
    e_v = a * np.pi + b * _oren_nayar_g(cv)
    up = (theta_l < np.pi / 2) & (theta_v < np.pi / 2)
    return np.where(up, cl * (a + b * t + e_ms * (1.0 - e_v) * (1.0 - e_l)), 0.0)


#: Knots of an OSL ramp closure (``diffuse_ramp``, ``phong_ramp``: colors[8]).
RAMP_KNOTS = 8


def ramp_hat(position, knot):
    """The share of knot ``knot`` in a ramp's value at ``position`` in [0, 1]:
    Cycles' bsdf_*_ramp_get_color interpolates linearly between 8 knots
    evenly spaced on [0, 1], hat_j(x) = max(0, 1 - |7x - j|)."""
    x = np.clip(np.asarray(position, dtype=float), 0.0, 1.0) * (RAMP_KNOTS - 1)
    return np.maximum(0.0, 1.0 - np.abs(x - knot))


def _diffuse_ramp_parts(closure, theta_l, theta_v, phi):
    """OSL's diffuse_ramp as (ramp position, factor): cos θl and 1/π (no
    further cos θl: the ramp is the whole light dependence), lights and
    views above the surface."""
    up = (theta_l < np.pi / 2) & (theta_v < np.pi / 2)
    return np.cos(theta_l), np.where(up, 1.0 / np.pi, 0.0)


def _phong_ramp_parts(closure, theta_l, theta_v, phi):
    """OSL's phong_ramp of exponent e as (ramp position, factor): p = (R·l)^e
    with R the mirror of the view, and p·(e + 2)/(2π)·cos θl where R·l > 0."""
    cos_rl = np.sin(theta_v) * np.cos(phi) * np.sin(theta_l) + np.cos(theta_v) * np.cos(theta_l)
    e = max(float(closure.exponent), 0.0)
    p = np.maximum(cos_rl, 0.0) ** e
    up = (theta_l < np.pi / 2) & (theta_v < np.pi / 2) & (cos_rl > 0)
    return p, np.where(up, p * (e + 2.0) / (2.0 * np.pi) * np.cos(theta_l), 0.0)


def bump_shadowing(theta_l, theta_v):
    """Cycles' bump shadowing term for a diffuse closure whose normal is the
    view direction (Conty Estevez et al., "A Microfacet-Based Shadowing
    Function to Solve the Bump Terminator Problem", Ray Tracing Gems, 2019,
    ch. 12; Cycles' bump_shadowing_term): GGX's G1 at cos θl with
    α² = tan²θv/8."""
    cos_v = np.clip(np.cos(theta_v), 1e-6, 1.0)
    cos_l = np.clip(np.cos(theta_l), 1e-6, 1.0)
    alpha2 = np.clip(0.125 * (1.0 / cos_v**2 - 1.0), 0.0, 1.0)
    return 2.0 / (1.0 + np.sqrt(1.0 + alpha2 * (1.0 / cos_l**2 - 1.0)))


def _retro_ramp_parts(closure, theta_l, theta_v, phi):
    """OSL's diffuse_ramp about the view direction as (ramp position,
    factor): cos γ = l·v and the bump shadowing term over π, lights above
    the surface with l·v > 0."""
    cos_lv = cos_light_view(theta_l, theta_v, phi)
    up = (theta_l < np.pi / 2) & (theta_v < np.pi / 2) & (cos_lv > 0)
    return np.clip(cos_lv, 0.0, 1.0), np.where(up, bump_shadowing(theta_l, theta_v) / np.pi, 0.0)


_RAMP_PARTS = {"diffuse_ramp": _diffuse_ramp_parts, "phong_ramp": _phong_ramp_parts, "retro_ramp": _retro_ramp_parts}


def _ramp_knot(closure, theta_l, theta_v, phi):
    """One knot j of a ramp: hat_j(position)·factor (``_RAMP_PARTS``)."""
    position, factor = _RAMP_PARTS[closure.kind](closure, theta_l, theta_v, phi)
    return ramp_hat(position, closure.knot) * factor


def evaluate_all(closures, theta_l, theta_v, phi) -> np.ndarray:
    """Every closure's ``evaluate`` stacked on a last axis, (..., K): a
    ramp's position and factor are computed once for all its knots."""
    theta_l, theta_v, phi = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (theta_l, theta_v, phi)))
    out = np.empty((*theta_l.shape, len(closures)))
    parts = {}
    for k, closure in enumerate(closures):
        if closure.osl:
            family = (closure.kind, closure.exponent)
            if family not in parts:
                parts[family] = _RAMP_PARTS[closure.kind](closure, theta_l, theta_v, phi)
            position, factor = parts[family]
            out[..., k] = ramp_hat(position, closure.knot) * factor
        else:
            out[..., k] = CLOSURE_KINDS[closure.kind].evaluate(closure, theta_l, theta_v, phi)
    return out


def ramp_closures(exponents=(1.0,), retro=False) -> list:
    """The knots of one diffuse ramp, of a Phong ramp per exponent and
    (``retro``) of a diffuse ramp about the view: the signed corrections an
    OSL fit adds (``lut.render.fitting``)."""
    knots = [Closure("diffuse_ramp", knot=j) for j in range(RAMP_KNOTS)]
    knots += [Closure("phong_ramp", knot=j, exponent=float(e)) for e in exponents for j in range(RAMP_KNOTS)]
    knots += [Closure("retro_ramp", knot=j) for j in range(RAMP_KNOTS)] if retro else []
    return knots


# ---------------------------------------------------------------------- EEVEE's rendering

#: The roughnesses (glossy, metallic) and Metallic BSDF IORs at which EEVEE's
#: rendering of the lobes is calibrated (``lut.render.eevee``); the retro GGX
#: lobes at ``RETRO_ROUGHNESS``.
EEVEE_ROUGHNESS = (0.05, 0.1, 0.2, 0.3, 0.45, 0.6, 0.8, 1.0)
EEVEE_IORS = (1.33, 1.5, 1.7, 2.0)
#: Roughnesses of the retro GGX lobes an EEVEE fit of a smooth type may use.
RETRO_ROUGHNESS = (0.45, 0.6, 0.8, 1.0)


def _eevee_lambert(closure, theta_l, theta_v, phi):
    """cos θl/π: EEVEE draws the Diffuse BSDF of any roughness and the Sheen BSDF as Lambert."""
    return np.where(theta_l < np.pi / 2, np.cos(theta_l), 0.0) / np.pi


def _eevee_retro_toon(closure, theta_l, theta_v, phi):
    """max(0, l·v)/π: EEVEE draws a Toon closure as Lambert about its normal
    (here the view direction), whatever its size and smooth, and does not
    clip the light at the surface's horizon."""
    return np.maximum(np.cos(light_view_angle(theta_l, theta_v, phi)), 0.0) / np.pi


def _eevee_glossy(closure, theta_l, theta_v, phi):
    """The GGX lobe D·G/(4 cos θv) of α = r², height-correlated Smith G
    (Walter et al. 2007, Eqs. 33-34), no Fresnel: EEVEE draws Beckmann lobes as GGX."""
    return ggx_lobe(theta_l, theta_v, phi, closure.roughness)[0]


def _eevee_metallic(closure, theta_l, theta_v, phi):
    """The GGX lobe times the exact unpolarized dielectric Fresnel
    reflectance at the half vector, F(θd, n) (``lut.models.fresnel``)."""
    lobe, cos_d = ggx_lobe(theta_l, theta_v, phi, closure.roughness)
    rs, rp = fresnel.reflection_coefficients(cos_d, closure.ior)
    return lobe * 0.5 * (np.abs(rs) ** 2 + np.abs(rp) ** 2)


def _eevee_retro_glossy(closure, theta_l, theta_v, phi):
    """Its Cycles formula: the GGX lobe in the frame of the view direction."""
    return _retro_glossy(closure, theta_l, theta_v, phi)


@dataclasses.dataclass(frozen=True)
class EeveeResponse:
    """How EEVEE's rendering of a closure kind is calibrated
    (``lut.render.eevee``): the smooth analytic ``reference`` its measured
    ratio tables correct, the closure parameters a table is measured at
    (``params``: they name it, ``table_key``), and for each parameter
    interpolated between tables its calibrated values (``grids``).  A kind
    with parameters but no grids has tables that EEVEE renders alike (its
    diffuse closures): their mean is used for any parameter."""

    reference: object
    params: tuple = ()
    grids: dict = dataclasses.field(default_factory=dict)


@dataclasses.dataclass(frozen=True)
class ClosureKind:
    """A registered closure kind: its evaluation (Cycles' formula), whether
    it is grey, its render cost in closures (an Oren-Nayar closure is one
    per channel), whether EEVEE counts it as a reflection closure (its
    microfacet lobes; ``lut.render.eevee.EXACT_REFLECTION_CLOSURES``), how
    EEVEE's rendering of it is calibrated (``eevee``; None: an EEVEE fit
    never uses it) and whether only OSL draws it, with a signed weight
    (``osl``: the ramps' knots)."""

    evaluate: object
    grey: bool = False
    cost: int = 1
    reflection: bool = False
    eevee: EeveeResponse | None = None
    osl: bool = False


_DIFFUSE_EEVEE = EeveeResponse(_eevee_lambert)

#: The closure kinds the fit and the node groups know (colour-science style
#: registry: ``lut.render.fitting`` evaluates them, ``lut.render.eevee`` reads
#: EEVEE's calibration of them, ``addon.nodes`` builds them): a new kind is
#: added here alone.
CLOSURE_KINDS = {
    "lambert": ClosureKind(_lambert, eevee=_DIFFUSE_EEVEE),
    "diffuse_toon": ClosureKind(_diffuse_toon),
    "glossy_toon": ClosureKind(_glossy_toon),
    "retro_toon": ClosureKind(_retro_toon, eevee=EeveeResponse(_eevee_retro_toon, ("size", "smooth"))),
    "glossy": ClosureKind(
        _glossy, reflection=True, eevee=EeveeResponse(_eevee_glossy, ("roughness",), {"roughness": EEVEE_ROUGHNESS})
    ),
    "sheen": ClosureKind(_sheen, eevee=EeveeResponse(_eevee_lambert, ("roughness",))),
    "oren_nayar": ClosureKind(_oren_nayar, cost=3, eevee=EeveeResponse(_eevee_lambert, ("roughness",))),
    "metallic": ClosureKind(
        _metallic,
        grey=True,
        reflection=True,
        eevee=EeveeResponse(_eevee_metallic, ("ior", "roughness"), {"ior": EEVEE_IORS, "roughness": EEVEE_ROUGHNESS}),
    ),
    "ggx": ClosureKind(_ggx, grey=True, reflection=True),
    "retro_glossy": ClosureKind(
        _retro_glossy,
        reflection=True,
        eevee=EeveeResponse(_eevee_retro_glossy, ("roughness",), {"roughness": RETRO_ROUGHNESS}),
    ),
    "diffuse_ramp": ClosureKind(_ramp_knot, cost=0, osl=True),
    "phong_ramp": ClosureKind(_ramp_knot, cost=0, osl=True),
    "retro_ramp": ClosureKind(_ramp_knot, cost=0, osl=True),
}


def validate_kind(kind: str) -> str:
    if kind not in CLOSURE_KINDS:
        raise ValueError(f"closure kind must be one of {', '.join(CLOSURE_KINDS)}, got {kind!r}")
    return kind


#: Render engines with a fit of their own: Cycles, and EEVEE (which draws
#: Toon closures as Lambert and every microfacet lobe through its own GGX
#: approximation, so its fit uses only Lambert and microfacet lobes).
TARGETS = ("CYCLES", "EEVEE")


def validate_target(target: str) -> str:
    if target not in TARGETS:
        raise ValueError(f"target must be one of {', '.join(TARGETS)}, got {target!r}")
    return target


def _toon_candidates():
    basis = [Closure("diffuse_toon", 1e-5, 1.0)]
    basis += [Closure("diffuse_toon", a, s) for a in (0.3, 0.5, 0.6, 0.7, 0.8, 0.9) for s in (0.1, 0.3)]
    basis += [Closure("glossy_toon", a, 0.3) for a in (0.2, 0.4, 0.6, 0.8)]
    return basis


def lobe_roughnesses(slope: float, distribution: str) -> list[float]:
    """Roughnesses r (α = r²) of the candidate facet lobes of a rough type:
    for Gaussian slopes the paper's facet term itself (α = slope, exact as a
    Beckmann lobe) and neighbours; for exponential slopes, whose sharper peak
    and longer tail no single Beckmann lobe has, a ladder from a fifth to
    three times the slope (a mixture of Beckmann lobes)."""
    factors = (
        (0.5, 0.7, 1.0, 1.4, 2.0) if distribution == "gaussian" else (0.05, 0.1, 0.2, 0.35, 0.6, 1.0, 1.6, 2.5, 3.5)
    )
    rough = np.sqrt(np.clip(slope * np.asarray(factors), 1e-4, 1.0))
    return [float(r) for r in np.unique(np.round(rough, 4))]


def _lobes(type_dict, exact_metallic):
    """Grey facet lobes and coloured Glossy lobes of a rough type's roughnesses."""
    slope = float(type_dict["slope"])
    if slope <= 0:
        return []
    n = reference_index(type_dict["n"])
    rough = lobe_roughnesses(slope, type_dict["distribution"])
    grey = "metallic" if exact_metallic else "ggx"
    return [Closure(grey, ior=n, roughness=r) for r in rough] + [Closure("glossy", roughness=r) for r in rough]


def candidates(type_dict: dict, target: str = "CYCLES", exact_metallic: bool = True, converged: bool = False) -> list:
    """The closures a paint type may be fitted with on a render target:
    Lambert; for Cycles the Toon ramps (the subsurface terms' light-side
    fall-off and the single scattering's view dependence), retro Toon ramps
    and Oren-Nayar (back-scattering pigments, g < 0, brighten toward the
    light: only these peak there); and for rough types coloured Glossy lobes
    and grey facet lobes of the roughnesses ``lobe_roughnesses``: Metallic
    Beckmann where Blender's Metallic BSDF is the exact dielectric lobe
    (``exact_metallic``: Blender 5), Principled GGX otherwise (Blender
    4.2-4.5); for Cycles above a slope of 0.3 also velvet Sheen lobes, which
    rise toward grazing as very rough facet terms do.  EEVEE draws every
    diffuse closure as Lambert (``lut.render.eevee``): Lambert and the lobes; for
    a smooth type, whose mirror leaves one of EEVEE's two exact reflection
    closures free, retro GGX lobes (``retro_glossy``) for back-scattering
    pigments; for a converged EEVEE fit (``converged``: closures beyond the
    exact ones, averaged over samples) retro GGX lobes for every type."""
    target = validate_target(target)
    basis = [Closure("lambert")]
    if target == "CYCLES":
        basis += _toon_candidates()
        basis += [Closure("oren_nayar", roughness=r) for r in (0.5, 1.0)]
        basis += [Closure("retro_toon", a, s) for a in (0.15, 0.3, 0.5) for s in (0.2, 0.6)]
    basis += _lobes(type_dict, exact_metallic)
    if target == "EEVEE" and (converged or float(type_dict["slope"]) == 0):
        basis += [Closure("retro_glossy", roughness=r) for r in RETRO_ROUGHNESS]
    if target == "CYCLES" and float(type_dict["slope"]) > 0.3:
        basis += [Closure("sheen", roughness=r) for r in (0.3, 0.5, 0.8, 1.0)]
    return basis
