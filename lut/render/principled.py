"""A Principled BSDF fallback for export: Cycles' Principled BSDF as a
function of the light and view directions (numpy only), and the Principled
parameters that best match a paint on the fidelity measure.

glTF and USD exporters read only the Principled BSDF, so every paint
material carries one (``addon.export``) whose parameters are fitted here.

The model (Blender 5.0's Cycles, ``intern/cycles/kernel/svm/closure.h``,
Principled branch, with the node's distribution set to single-scatter
"GGX", metallic, transmission, sheen, subsurface and emission at 0) is a
stack of layers, each attenuating the ones below by its estimated albedo
(``closure_layering_weight``: weight · (1 - albedo)):

* coat (weight w_c, roughness r_c, IOR n_c): GGX reflection of α = r_c² with
  exact dielectric Fresnel, F·D·G/(4 cos θv) per unit irradiance (Walter et
  al., "Microfacet models for refraction through rough surfaces", EGSR 2007,
  Eqs. 33-34; ``lut.render.closures``' "ggx" kind), times w_c;
* specular (roughness r, IOR n): the same lobe at α = r², under the coat;
* diffuse: Lambert, base colour · cos θl/π, under both.

A dielectric layer's albedo at the view cosine μ is
F0 + (1 - F0)·s(r, μ, z) (``bsdf_microfacet_estimate_albedo``), F0 =
((n - 1)/(n + 1))², z = sqrt((n - 1)/(n + 1)), where Cycles reads s from a
16³ table (``ggx_gen_schlick_ior_s``, trilinear over r, μ, z in [0, 1]) whose
entries are the mean, over microfacet normals h drawn from the distribution
of visible normals, of the Fresnel interpolation factor
(F(μ_h) - F0)/(1 - F0), counting a normal whose reflection goes below the
horizon as 0 (``intern/cycles/app/cycles_precompute.cpp``,
``precompute_ggx_gen_schlick_s``).  Here the table is computed the same way
by quadrature (the visible normals' density D_v = G1(v)·max(0, v·h)·D(h)/μ,
Heitz, "Sampling the GGX distribution of visible normals", JCGT 7(4), 2018,
Eq. 1) and read with the same interpolation.

The fit (``fit_principled``) minimizes the fidelity measure
(``lut.render.measure``: relative RMS of the radiance f·cos θl) on a coarser
grid of the measure's range, ``GRID``, off the mirror (a Principled BSDF
draws no delta): the base colour is linear in the radiance and
solved in closed form per channel (clipped to [0, 1]); roughness, IOR and
the coat's parameters by Nelder-Mead from the best point of a coarse grid.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np

from ..models import _validate
from . import measure
from .closures import Closure, _ggx

#: The fit's grid: the fidelity measure's range (θl 0-75°, θv 5-75°, φ
#: 0-180°) in 15°, 10° and 30° steps, less the geometries within
#: ``measure.MIRROR_EXCLUSION`` of the mirror.
GRID = (
    np.radians(np.arange(0.0, 75.1, 15.0)),
    np.radians(np.arange(5.0, 75.1, 10.0)),
    np.radians(np.arange(0, 181, 30)),
)

#: Bounds of the fitted parameters (the Principled node's own ranges where it
#: has them; IOR within what paints' binders and coats span, widened).
BOUNDS = {"roughness": (0.0, 1.0), "ior": (1.01, 2.5), "coat_weight": (0.0, 1.0), "coat_roughness": (0.0, 1.0)}

#: Resolution of Cycles' ggx_gen_schlick_ior_s table per axis.
TABLE_SIZE = 16
#: The ranges of the roughnesses and weights, and of the IORs, that a fit gives.
_UNIT = _validate.Range(0.0, 1.0)
_IOR = _validate.Range(1.0, 4.0, low_open=True)


@dataclasses.dataclass(frozen=True)
class PrincipledParams:
    """Inputs of a Principled BSDF (distribution "GGX", everything not listed
    at the node's default): base colour (scene-linear RGB), roughness, IOR,
    coat weight, roughness and IOR."""

    base_color: tuple = (0.8, 0.8, 0.8)
    roughness: float = 0.5
    ior: float = 1.5
    coat_weight: float = 0.0
    coat_roughness: float = 0.03
    coat_ior: float = 1.5

    def __post_init__(self):
        colour = tuple(float(c) for c in np.broadcast_to(np.asarray(self.base_color, dtype=float), (3,)))
        if not all(0.0 <= c <= 1.0 for c in colour):
            raise ValueError(f"base_color must be an RGB triple in [0, 1], got {self.base_color!r}")
        object.__setattr__(self, "base_color", colour)
        for name in ("roughness", "coat_weight", "coat_roughness"):
            object.__setattr__(self, name, _validate.check_range(getattr(self, name), name, _UNIT))
        for name in ("ior", "coat_ior"):
            object.__setattr__(self, name, _validate.check_range(getattr(self, name), name, _IOR))

    def node_inputs(self) -> dict:
        """{Principled BSDF input name: value} (Blender 4.0+ names)."""
        return {
            "Base Color": (*self.base_color, 1.0),
            "Roughness": self.roughness,
            "IOR": self.ior,
            "Coat Weight": self.coat_weight,
            "Coat Roughness": self.coat_roughness,
            "Coat IOR": self.coat_ior,
        }

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)


# ------------------------------------------------------------ Cycles' model


def _fresnel(cos_d, n):
    """Unpolarized dielectric Fresnel reflectance (Cycles' fresnel_dielectric_cos)."""
    c = np.clip(cos_d, 0.0, 1.0)
    g2 = n * n - 1.0 + c * c
    g = np.sqrt(np.maximum(g2, 0.0))
    a = (g - c) / (g + c)
    b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0)
    return 0.5 * a * a * (1.0 + b * b)


def _f0(n):
    return ((n - 1.0) / (n + 1.0)) ** 2


def _ior_of_z(z):
    """Cycles' ior_parametrization: ior_from_F0(z⁴)."""
    root = np.sqrt(np.minimum(z**4, 1.0 - 1e-7))
    return (1.0 + root) / (1.0 - root)


def _s_exact(rough, mu, n, nodes=48):
    """The table's entry: mean over visible normals h (GGX, α = rough²) of the
    Fresnel factor (F(v·h) - F0)/(1 - F0), 0 where the reflection leaves the
    upper hemisphere.  Broadcasts rough, mu, n; quadrature over the GGX
    normal distribution D·cos θh (tan²θh = α² u/(1 - u), Gauss-Legendre in u,
    uniform in φ)."""
    rough, mu, n = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (rough, mu, n)))
    x, w = np.polynomial.legendre.leggauss(nodes)
    u, wu = 0.5 * (x + 1.0), 0.5 * w
    phi = (np.arange(2 * nodes) + 0.5) * (2 * np.pi / (2 * nodes))
    a2 = (rough**2)[..., None, None] ** 2
    tan2 = a2 * (u / (1.0 - u))[:, None]
    cos_h = 1.0 / np.sqrt(1.0 + tan2)
    sin_h = np.sqrt(1.0 - cos_h * cos_h)
    m = mu[..., None, None]
    sv = np.sqrt(1.0 - m * m)
    vh = sv * sin_h * np.cos(phi) + m * cos_h  # v = (sin, 0, μ)
    out_z = 2.0 * vh * cos_h - m  # reflection's z
    lam_v = 0.5 * (np.sqrt(1.0 + a2 * (1.0 - m * m) / (m * m)) - 1.0)
    # ∫ D_v g dω_h = ∫ G1(v) max(0, v·h)/(μ cos θh) g · (D cos θh dω_h), the
    # latter du dφ/(2π).
    density = np.maximum(vh, 0.0) / (m * cos_h) / (1.0 + lam_v)
    nn = n[..., None, None]
    f0 = _f0(nn)
    s = np.clip((_fresnel(vh, nn) - f0) / (1.0 - f0), 0.0, 1.0)
    value = np.where(out_z > 0.0, s, 0.0) * density
    return np.clip(np.einsum("...ij,i->...", value, wu) / (2 * nodes), 0.0, 1.0)


@functools.cache
def _table() -> np.ndarray:
    """ggx_gen_schlick_ior_s as Cycles tabulates it: [z, μ, rough] at
    i/15 each, clamped as cycles_precompute does (rough, μ ≥ 1e-4, z in
    [1e-4, 0.99])."""
    axis = np.arange(TABLE_SIZE) / (TABLE_SIZE - 1)
    z = np.clip(axis, 1e-4, 0.99)[:, None, None]
    mu = np.clip(axis, 1e-4, 1.0)[None, :, None]
    rough = np.clip(axis, 1e-4, 1.0)[None, None, :]
    # One z slice at a time keeps the quadrature's arrays small.
    return np.stack([_s_exact(rough[0], mu[0], _ior_of_z(zk)) for zk in z[:, 0, 0]])


def _lerp_axis(x):
    x = np.clip(x, 0.0, 1.0) * (TABLE_SIZE - 1)
    i = np.minimum(x.astype(int), TABLE_SIZE - 1)
    return i, np.minimum(i + 1, TABLE_SIZE - 1), x - i


def table_s(rough, mu, n):
    """Cycles' lookup_table_read_3D of ggx_gen_schlick_ior_s at (rough, μ,
    z(n)): trilinear interpolation."""
    rough, mu, n = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (rough, mu, n)))
    t = _table()
    (x0, x1, fx), (y0, y1, fy), (z0, z1, fz) = (
        _lerp_axis(rough),
        _lerp_axis(mu),
        _lerp_axis(np.sqrt(np.abs((n - 1.0) / (n + 1.0)))),
    )

    def plane(z):
        return (1 - fy) * ((1 - fx) * t[z, y0, x0] + fx * t[z, y0, x1]) + fy * (
            (1 - fx) * t[z, y1, x0] + fx * t[z, y1, x1]
        )

    return (1 - fz) * plane(z0) + fz * plane(z1)


def layer_albedo(roughness, ior, cos_view):
    """A dielectric GGX layer's albedo estimate at the view cosine:
    F0 + (1 - F0)·s (``bsdf_microfacet_estimate_albedo``)."""
    f0 = _f0(ior)
    return f0 + (1.0 - f0) * table_s(roughness, cos_view, ior)


def _lobe(roughness, ior, theta_l, theta_v, phi):
    # Cycles evaluates no lobe below α·α = 1e-7 (a mirror, off the measure).
    if roughness**4 <= 1e-7:
        return np.zeros(np.broadcast_shapes(np.shape(theta_l), np.shape(theta_v), np.shape(phi)))
    return _ggx(Closure("ggx", ior=ior, roughness=roughness), theta_l, theta_v, phi)


def _parts(params: PrincipledParams, theta_l, theta_v, phi):
    """(grey specular + coat radiance, diffuse radiance per unit base colour),
    per unit irradiance, cos θl included."""
    cos_v = np.cos(theta_v)
    spec = _lobe(params.roughness, params.ior, theta_l, theta_v, phi)
    under = 1.0 - layer_albedo(params.roughness, params.ior, cos_v)
    if params.coat_weight > 0.0:
        coat_albedo = params.coat_weight * layer_albedo(params.coat_roughness, params.coat_ior, cos_v)
        coat = params.coat_weight * _lobe(params.coat_roughness, params.coat_ior, theta_l, theta_v, phi)
        spec = coat + np.clip(1.0 - coat_albedo, 0.0, 1.0) * spec
        under = under * np.clip(1.0 - coat_albedo, 0.0, 1.0)
    up = (np.asarray(theta_l) < np.pi / 2) & (np.asarray(theta_v) < np.pi / 2)
    diffuse = np.where(up, np.clip(under, 0.0, 1.0) * np.cos(theta_l) / np.pi, 0.0)
    return spec, diffuse


def radiance(params: PrincipledParams, theta_l, theta_v, phi) -> np.ndarray:
    """The Principled BSDF's RGB radiance per unit irradiance, f·cos θl,
    shape broadcast(angles) + (3,).  Angles as in ``lut.models`` (light at
    azimuth π, φ = 0 the mirror)."""
    spec, diffuse = _parts(params, theta_l, theta_v, phi)
    return spec[..., None] + diffuse[..., None] * np.asarray(params.base_color)


# ------------------------------------------------------------------ the fit


def _grid():
    return measure.grid_points(GRID, measure.MIRROR_EXCLUSION)


def reference(source, amplitudes=None) -> np.ndarray:
    """f·cos θl of the paint on the fit's grid ``GRID``, (N, 3): ``source`` a
    ``lut.Paint``, or a loaded LUT (``lut.lutfiles.baking.LUT``) with ``amplitudes``
    (3 channels × 3 components, ``Paint.amplitudes`` or
    ``lut.render.bake.amplitudes_of_inputs``)."""
    tl, tv, ph = _grid()
    if hasattr(source, "brdf"):
        if amplitudes is not None:
            raise ValueError("amplitudes must be None for a Paint (they come from the paint)")
        return source.brdf(tl, tv, ph) * np.cos(tl)[:, None]
    if not hasattr(source, "components"):
        raise TypeError(f"source must be a lut.Paint or a loaded LUT, got {type(source).__name__}")
    if amplitudes is None:
        raise ValueError("amplitudes (3 channels × 3 components) are needed with a LUT")
    amps = np.asarray(amplitudes, dtype=float)
    if amps.shape != (3, 3):
        raise ValueError(f"amplitudes must have shape (3, 3), got {amps.shape}")
    comps = source.components(tl, tv, ph)  # (N, tiles, 3 components)
    tiles = comps.shape[1]
    per_channel = comps[:, [c if tiles == 3 else 0 for c in range(3)], :]  # (N, 3 channels, 3)
    return np.einsum("nkc,kc->nk", per_channel, amps) * np.cos(tl)[:, None]


def error(params: PrincipledParams, ref: np.ndarray) -> float:
    """The fidelity measure of ``params`` against ``reference(...)`` on ``GRID``."""
    tl, tv, ph = _grid()
    return measure.relative_rms(radiance(params, tl, tv, ph), ref)


def _solve_colour(spec, diffuse, ref, w2):
    """The base colour minimizing the weighted squared error, per channel
    (one unknown each, so clipping to [0, 1] keeps it optimal), and the
    error's numerator."""
    num = np.sum(w2[:, None] * diffuse[:, None] * (ref - spec[:, None]), axis=0)
    den = max(float(np.sum(w2 * diffuse * diffuse)), 1e-300)
    colour = np.clip(num / den, 0.0, 1.0)
    resid = spec[:, None] + diffuse[:, None] * colour - ref
    return colour, float(np.sum(w2[:, None] * resid * resid))


def _nelder_mead(f, x0, step, iterations=200, tol=1e-7):
    """A plain Nelder-Mead (Nelder & Mead, Computer Journal 7, 1965; the
    standard coefficients 1, 2, 1/2, 1/2)."""
    n = len(x0)
    simplex = [np.asarray(x0, dtype=float)]
    for i in range(n):
        x = simplex[0].copy()
        x[i] += step[i]
        simplex.append(x)
    values = [f(x) for x in simplex]
    for _ in range(iterations):
        order = np.argsort(values)
        simplex = [simplex[i] for i in order]
        values = [values[i] for i in order]
        if values[-1] - values[0] <= tol * max(abs(values[0]), 1e-12):
            break
        centre = np.mean(simplex[:-1], axis=0)
        reflected = centre + (centre - simplex[-1])
        fr = f(reflected)
        if fr < values[0]:
            expanded = centre + 2.0 * (centre - simplex[-1])
            fe = f(expanded)
            simplex[-1], values[-1] = (expanded, fe) if fe < fr else (reflected, fr)
        elif fr < values[-2]:
            simplex[-1], values[-1] = reflected, fr
        else:
            contracted = centre + 0.5 * (simplex[-1] - centre)
            fc = f(contracted)
            if fc < values[-1]:
                simplex[-1], values[-1] = contracted, fc
            else:
                for i in range(1, n + 1):
                    simplex[i] = simplex[0] + 0.5 * (simplex[i] - simplex[0])
                    values[i] = f(simplex[i])
    best = int(np.argmin(values))
    return simplex[best], values[best]


_NAMES = {False: ("roughness", "ior"), True: ("roughness", "ior", "coat_weight", "coat_roughness", "ior")}


def _params_of(x, coat: bool):
    def clip(v, name):
        lo, hi = BOUNDS[name]
        return float(np.clip(v, lo, hi))

    kwargs = {"roughness": clip(x[0], "roughness"), "ior": clip(x[1], "ior")}
    if coat:
        kwargs.update(
            coat_weight=clip(x[2], "coat_weight"),
            coat_roughness=clip(x[3], "coat_roughness"),
            coat_ior=clip(x[4], "ior"),
        )
    return kwargs


def fit_principled(source, amplitudes=None, *, coat: bool = True):
    """The Principled parameters that best match a paint on the fidelity
    measure: ``source`` a ``lut.Paint`` or a loaded LUT with ``amplitudes``
    (see ``reference``).  ``coat``: also try a coat layer (kept only where it
    lowers the error).  Returns (PrincipledParams, its fidelity measure)."""
    ref = reference(source, amplitudes)
    if not np.all(np.isfinite(ref)) or np.sum(ref * ref) <= 0.0:
        raise ValueError("the paint reflects nothing on the fit grid: nothing to fit")
    tl, tv, ph = _grid()
    w2 = np.ones_like(tl)  # every geometry counted once (the measure)
    norm = float(np.sum(w2[:, None] * ref * ref))

    def objective(x, with_coat):
        p = PrincipledParams(**_params_of(x, with_coat))
        spec, diffuse = _parts(p, tl, tv, ph)
        _, sse = _solve_colour(spec, diffuse, ref, w2)
        # Leaving the bounds costs a little, so the simplex comes back.
        lo = np.array([BOUNDS[k][0] for k in _NAMES[with_coat]])
        hi = np.array([BOUNDS[k][1] for k in _NAMES[with_coat]])
        outside = np.sum(np.maximum(lo - x, 0.0) + np.maximum(x - hi, 0.0))
        return sse / norm + outside

    starts = [(r, n) for r in (0.0, 0.15, 0.3, 0.45, 0.6, 0.8, 1.0) for n in (1.3, 1.5, 1.8)]
    best = min(starts, key=lambda x: objective(np.array(x), False))
    x, value = _nelder_mead(lambda x: objective(x, False), np.array(best), np.array([0.1, 0.1]))
    results = [(value, x, False)]
    if coat:
        coat_starts = [(*x, cw, cr, 1.5) for cw in (0.3, 1.0) for cr in (0.0, 0.1, 0.3)]
        start = min(coat_starts, key=lambda c: objective(np.array(c), True))
        xc, vc = _nelder_mead(lambda c: objective(c, True), np.array(start), np.array([0.1, 0.1, 0.2, 0.1, 0.1]))
        results.append((vc, xc, True))
    _, x, with_coat = min(results, key=lambda r: r[0])
    params = PrincipledParams(**_params_of(x, with_coat))
    spec, diffuse = _parts(params, tl, tv, ph)
    colour, _ = _solve_colour(spec, diffuse, ref, w2)
    params = dataclasses.replace(params, base_color=tuple(colour))
    return params, error(params, ref)


def recolour(params: PrincipledParams, source, amplitudes=None):
    """The same fallback for another colour of the paint type: roughness,
    IOR and coat kept, the base colour solved again (exact per channel, one
    evaluation of the Principled model on the fit grid), so a colour
    edit refreshes the export fallback at interactive cost.  Returns
    (PrincipledParams, its fidelity measure)."""
    ref = reference(source, amplitudes)
    tl, tv, ph = _grid()
    spec, diffuse = _parts(params, tl, tv, ph)
    colour, _ = _solve_colour(spec, diffuse, ref, np.ones_like(tl))
    params = dataclasses.replace(params, base_color=tuple(float(c) for c in colour))
    return params, error(params, ref)
