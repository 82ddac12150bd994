"""``germer_paint``: the paints as a polarized BSDF plugin of Mitsuba 3.

``lut.polarized.register()`` registers it for Mitsuba's active variant (a
polarized one: ``scalar_spectral_polarized``, ``llvm_ad_mono_polarized``,
``llvm_ad_spectral_polarized``, ...).  mitsuba and drjit are imported only
here, when it is called.  Its properties are the paint's fields:

    n             float   binder refractive index (default 1.5)
    rho           texture pigment colour ρ: a float, RGB or spectrum (default 0.8)
    single        texture weight of single scattering (default 0)
    g             float   Henyey-Greenstein asymmetry (default 0)
    slope         float   total RMS slope of the interface (0: smooth, default)
    distribution  string  "gaussian" or "exponential" (default "gaussian")
    facet         float   weight of the interface reflection (default 1)
    cache         string  directory of the Mueller LUTs (default: the user's
                          cache directory, ``default_cache``)

**Evaluation.**  The paint's type (n, g, slope, distribution) picks a Mueller
LUT (``lut.polarized.mueller_lut``: each colour-free component's Mueller
matrix in the transported bases of the half frame), baked once and cached by
content.  ``eval`` looks single scattering and the diffuse term up with
Dr.Jit operations only (a 3-D texture of 32 channels: M00 and Mij/M00 of
each, then Mitsuba's ``mueller.rotate_mueller_basis`` from the half frame's
transported bases to Mitsuba's ``mueller.stokes_basis`` of the incident and
exit rays in the shading frame, which is the same transported basis built
in that frame), and evaluates the facet term in closed form (paper Sec. 2.4,
Eqs. 35-38, as ``lut.models.facet_reflection``: its peak is sharper than the
table's cells), so the JIT variants evaluate whole wavefronts and the
scalar variant needs no numpy per sample.  The components are
weighted per wavelength as ``lut.Paint`` weights them per RGB channel
(T. A. Germer, "Polarized light diffusely scattered under smooth and rough
interfaces", Proc. SPIE 5158, 2003): the facet term by ``facet``, single
scattering by ``single(λ)``, the diffuse term by
k(ρ(λ)) = ρ(1 − r̄)/(1 − ρ r̄) (Eq. 27, r̄ the LUT's internal reflectance).
Colours are Mitsuba textures, so spectral variants take RGB through
Mitsuba's own spectral upsampling, spectra as given, and textures vary
over the surface; mono variants take Mitsuba's luminance of them.

A smooth paint (slope 0) adds the interface's mirror, a delta: Fresnel's
reflection Mueller matrix (``mueller.specular_reflection``) times
``facet``, referred to the Stokes bases as Mitsuba's ``pplastic`` refers
its own.  Everything else is ``lut.Paint.mueller``'s.

**Sampling.**  A mixture: cosine-weighted directions, a Beckmann lobe of
α = slope about the normal for a rough paint (the facet term's shape; a
proposal only, so its likeness to the exponential distribution affects
noise, not the mean), and the mirror of a smooth paint, chosen with its
Fresnel reflectance times ``facet`` (within [0.05, 0.95]).  ``pdf`` is the
mixture's density of the non-delta part.

**Conventions.**  As Mitsuba's polarized BSDFs (and ``pplastic``): light
arrives along −ω̂_o and leaves along ω̂_i (ω̂ swapped in importance
transport), the matrix maps the Stokes vector in ``stokes_basis(−ω̂_o)`` to
the one in ``stokes_basis(ω̂_i)``, and ``eval`` includes cos θ of ``wo``.
Linear polarization follows SCATMECH's Q = I_s − I_p, U about s + p with
p = k × s, which Mitsuba's Stokes bases share (x = s, y = k × x); the sign
of V is SCATMECH's (the elements coupling V with I, Q and U vanish for a
real refractive index).  Dispersive paints (n as Cauchy coefficients) are
not offered here: their LUT has one tile per RGB channel.
"""

from __future__ import annotations

import functools
import math
import os
import pathlib
import subprocess
import sys

import numpy as np

from ..models._validate import REFLECTANCE, check_range
from ..paint.core import Paint
from ..paint.schema import PAINT_FIELDS
from . import mueller_lut

PLUGIN = "germer_paint"
#: Proposal weights of the sampling mixture, and the mirror's bounds.
FACET_LOBE_WEIGHT = 0.5
MIRROR_CHOICE = (0.05, 0.95)
#: D of the mirror fold (U and V change sign): the sign of element 4i + j.
_MIRROR_SIGNS = tuple(
    (1.0 if i < 2 else -1.0) * (1.0 if j < 2 else -1.0) for i in range(4) for j in range(4)
)  # fmt: skip

_CLASSES: dict = {}


def _not(mask):
    """Logical not of a Dr.Jit mask or of the scalar variants' bool."""
    return not mask if isinstance(mask, bool) else ~mask


def default_cache() -> pathlib.Path:
    """Where the plugin keeps its Mueller LUTs unless told: $PAINT_LUT_CACHE,
    else ``paint-lut/mueller`` in the user's cache directory
    ($XDG_CACHE_HOME, or ~/.cache)."""
    if os.environ.get("PAINT_LUT_CACHE"):
        return pathlib.Path(os.environ["PAINT_LUT_CACHE"])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return pathlib.Path(base) / "paint-lut" / "mueller"


#: The polarized variants, best first: the JIT ones evaluate whole wavefronts
#: but need a libLLVM newer than many systems carry (Dr.Jit aborts the process
#: with LLVM 15 or 16), so each is tried in a child process first.
VARIANTS = ("llvm_ad_spectral_polarized", "scalar_spectral_polarized")


#: A tiny polarized render: loading a JIT variant can succeed where compiling
#: its kernels aborts.
_PROBE_RENDER = (
    "mi.render(mi.load_dict({'type': 'scene', 'integrator': {'type': 'stokes', 'integrator': {'type': 'direct'}}, "
    "'sensor': {'type': 'orthographic', 'film': {'type': 'hdrfilm', 'width': 2, 'height': 2}}, "
    "'plane': {'type': 'rectangle', 'to_world': mi.ScalarTransform4f().translate([0, 0, 2])}, "
    "'sun': {'type': 'directional', 'direction': [0, 0, 1]}}), spp=1)"
)


@functools.lru_cache(maxsize=8)
def choose_variant(candidates=VARIANTS) -> tuple[str, str]:
    """(variant, why): ``$PAINT_LUT_MITSUBA_VARIANT`` if set, else the first
    polarized variant that renders a tiny scene in a child process
    (``DRJIT_LIBLLVM_PATH`` is honoured there: Dr.Jit reads it when first
    imported, so set it before importing mitsuba), and a sentence that says
    which was taken and why the ones before it were not.  Probed once per
    process."""
    chosen = os.environ.get("PAINT_LUT_MITSUBA_VARIANT")
    if chosen:
        return chosen, f"Mitsuba variant {chosen} (PAINT_LUT_MITSUBA_VARIANT)"
    skipped = []
    for variant in candidates:
        probe = f"import mitsuba as mi; mi.set_variant({variant!r}); {_PROBE_RENDER}"
        try:
            run = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120)
        except subprocess.TimeoutExpired:
            skipped.append(f"{variant} (timed out loading)")
            continue
        if run.returncode == 0:
            why = f"Mitsuba variant {variant}"
            if skipped:
                why += " (" + "; ".join(skipped) + ")"
            return variant, why
        last = (run.stderr.strip().splitlines() or [""])[-1][:120]
        hint = "; Dr.Jit's JIT needs libLLVM 17 or later (DRJIT_LIBLLVM_PATH)" if variant.startswith("llvm") else ""
        skipped.append(f"{variant} fails to render here (exit status {run.returncode}: {last}){hint}")
    raise RuntimeError("no polarized Mitsuba variant loads here: " + "; ".join(skipped))


def register() -> None:
    """Register ``germer_paint`` for Mitsuba's active variant, which must be
    polarized (ValueError otherwise, naming the variants to choose)."""
    import mitsuba as mi

    variant = mi.variant()
    if variant is None or "polarized" not in variant:
        choices = ", ".join(v for v in mi.variants() if "polarized" in v) or "none in this build"
        raise ValueError(
            f"germer_paint needs a polarized Mitsuba variant (mitsuba.set_variant), got {variant!r}; "
            f"polarized variants: {choices}"
        )
    if variant not in _CLASSES:
        _CLASSES[variant] = _bsdf_class()
    cls = _CLASSES[variant]
    mi.register_bsdf(PLUGIN, lambda props: cls(props))


def type_paint(n=None, g=None, slope=None, distribution=None, facet=None) -> Paint:
    """The ``lut.Paint`` of the plugin's scalar properties (the defaults of
    ``lut.Paint`` where not given): validates them, naming a property out
    of its range, and gives the paint type whose Mueller LUT it reads."""
    fields = {"n": n, "g": g, "slope": slope, "distribution": distribution, "facet": facet}
    fields = {k: v for k, v in fields.items() if v is not None}
    for name, value in fields.items():
        spec = PAINT_FIELDS[name]
        if spec.choices:
            if value not in spec.choices:
                choices = ", ".join(repr(c) for c in spec.choices)
                raise ValueError(f"germer_paint property {name} must be one of {choices}, got {value!r}")
            continue
        allowed = spec.bake or spec.allowed  # what a LUT can hold, as the command line's bakes
        if not (name == "slope" and value == 0):
            check_range(value, f"germer_paint property {name}", allowed)
    paint = Paint(**fields)
    if paint.dispersive:
        raise ValueError("germer_paint takes n as one number (dispersive paints have a Mueller LUT per channel)")
    return paint


def _bsdf_class():
    """The plugin class for the active variant (Mitsuba's types are the
    variant's, so the class is made after ``set_variant``)."""
    import drjit as dr
    import mitsuba as mi

    half_pi = 0.5 * math.pi

    def half_frame_basis(k, phi_h):
        """The half frame's transported basis vector s of rays k: built in the
        frame turned by φh about the normal, turned back."""
        c, s = dr.cos(phi_h), dr.sin(phi_h)
        local = mi.Vector3f(c * k.x + s * k.y, -s * k.x + c * k.y, k.z)
        b = mi.mueller.stokes_basis(local)
        return mi.Vector3f(c * b.x - s * b.y, s * b.x + c * b.y, b.z)

    def fresnel_reflection(light, view, normal, eta):
        """Fresnel's reflection Mueller matrix of a dielectric surface of unit
        ``normal`` (a mirror's, or a facet's), at cos ι = |ω·normal|, referred
        from its s/p bases (s ∝ normal × ray, as Mitsuba's ``conductor`` and
        ``pplastic`` refer theirs) to Mitsuba's Stokes bases.  Light that
        returns along itself, or meets the mirror along its normal, has no
        plane of incidence: any s across the ray is the surface's."""
        f = mi.mueller.specular_reflection(dr.clip(dr.abs(dr.dot(light, normal)), 0.0, 1.0), eta)
        s_in, s_out = dr.cross(normal, -light), dr.cross(normal, view)
        collinear = dr.squared_norm(s_in) < 1e-12
        across = mi.mueller.stokes_basis(-light)
        s_in = dr.select(collinear, across, dr.normalize(s_in))
        s_out = dr.select(collinear, across, dr.normalize(s_out))
        return mi.mueller.rotate_mueller_basis(
            f, -light, s_in, mi.mueller.stokes_basis(-light), view, s_out, mi.mueller.stokes_basis(view)
        )

    def colour_texture(props, name):
        """A colour property as a texture, its values within [0, 1] (a float
        is checked exactly, a texture by its largest value)."""
        if name not in props:
            return mi.load_dict({"type": "uniform", "value": float(np.mean(PAINT_FIELDS[name].default))})
        if props.type(name) == mi.Properties.Type.Float:
            check_range(props.get(name), f"germer_paint property {name}", REFLECTANCE)
        texture = props.get_texture(name)
        if float(texture.max()) > 1.0 + 1e-6:
            raise ValueError(
                f"germer_paint property {name} must be a colour with values in [0, 1], its largest is {texture.max():g}"
            )
        return texture

    class GermerPaint(mi.BSDF):
        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            get = props.get
            fields = {key: get(key) for key in ("n", "g", "slope", "distribution", "facet") if key in props}
            self.paint = type_paint(**fields)
            self.rho = colour_texture(props, "rho")
            self.single = colour_texture(props, "single")
            if "cache" in props and props.type("cache") != mi.Properties.Type.String:
                raise ValueError(
                    f"germer_paint property cache must be a directory path (a string), got {get('cache')!r}"
                )
            cache = pathlib.Path(get("cache")) if "cache" in props else default_cache()
            path = mueller_lut.bake_mueller(self.paint, cache)
            table = mueller_lut.load_mueller_lut(path)
            self.lut_path = str(path)
            self.rbar = table.internal_reflectance
            self.cos_power = int(table.meta["cos_power"][1])
            n_p, n_d, n_u = table.data.shape[2:5]
            self.shape = (n_u, n_d, n_p)
            # Single scattering and the diffuse term (the facet term is a closed form, ``_facet``).
            self.texture = mi.Texture3f(
                mi.TensorXf(np.ascontiguousarray(table._flat[..., 16:], dtype=np.float32)),
                use_accel=False,
                filter_mode=dr.FilterMode.Linear,
                wrap_mode=dr.WrapMode.Clamp,
            )
            self.smooth = self.paint.slope == 0.0
            self.facet = float(self.paint.facet)
            self.eta = float(self.paint.n)
            self.slope = float(self.paint.slope)
            self.gaussian = self.paint.distribution == "gaussian"
            self.alpha = min(max(float(self.paint.slope), 0.02), 2.0)
            lobe = mi.BSDFFlags.GlossyReflection if not self.smooth else mi.BSDFFlags.DiffuseReflection
            self.lobe = lobe
            components = [lobe | mi.BSDFFlags.FrontSide]
            if self.smooth:
                components.append(mi.BSDFFlags.DeltaReflection | mi.BSDFFlags.FrontSide)
            self.m_components = components
            flags = components[0]
            for c in components[1:]:
                flags = flags | c
            self.m_flags = flags

        # -- the Mueller LUT ------------------------------------------------
        def _amplitudes(self, si, active):
            rho = self.rho.eval(si, active)
            single = self.single.eval(si, active)
            k = rho * (1.0 - self.rbar) / (1.0 - rho * self.rbar)  # Eq. 27
            return self.facet, single, k

        def _brdf(self, si, light, view, active):
            """Σ_c a_c M_c [sr⁻¹] of light arriving from ``light`` and leaving
            towards ``view`` (unit, shading frame), in Mitsuba's Stokes bases."""
            h = dr.normalize(light + view)
            theta_h = dr.safe_acos(h.z)
            phi_h = dr.atan2(h.y, h.x)
            # d = R_y(-θh) R_z(-φh) ω_light (lut.lutfiles.angles.half_diff_signed)
            c, s = dr.cos(phi_h), dr.sin(phi_h)
            x = c * light.x + s * light.y
            y = -s * light.x + c * light.y
            ct, st = dr.cos(theta_h), dr.sin(theta_h)
            dx, dz = ct * x - st * light.z, st * x + ct * light.z
            theta_d = dr.safe_acos(dz)
            phi_d = dr.atan2(y, dx)
            n_u, n_d, n_p = self.shape
            pos = mi.Point3f(
                (dr.sqrt(dr.clip(theta_h / half_pi, 0.0, 1.0)) * (n_u - 1) + 0.5) / n_u,
                (dr.clip(theta_d / half_pi, 0.0, 1.0) * (n_d - 1) + 0.5) / n_d,
                (dr.clip(dr.abs(phi_d) / math.pi, 0.0, 1.0) * (n_p - 1) + 0.5) / n_p,
            )
            # Single scattering and the diffuse term: M00 and the normalised
            # elements Mij/M00 of each (mueller_lut's layout).
            g = self.texture.eval(pos, active)
            mirrored = phi_d < 0.0
            facet, single, k = self._amplitudes(si, active)
            a_single, a_diffuse = single * g[0], k * g[16]
            if self.cos_power == -1:  # stored M00 / (cos θi cos θs) (mueller_lut.cos_power)
                a_single, a_diffuse = a_single * (light.z * view.z), a_diffuse * (light.z * view.z)
            m = mi.Spectrum(0.0)
            for e in range(16):
                value = a_single + a_diffuse if e == 0 else a_single * g[e] + a_diffuse * g[16 + e]
                if _MIRROR_SIGNS[e] < 0.0:
                    value = dr.select(mirrored, -value, value)
                m[e // 4][e % 4] = value
            k_in, k_out = -light, view
            m = mi.mueller.rotate_mueller_basis(
                m,
                k_in,
                half_frame_basis(k_in, phi_h),
                mi.mueller.stokes_basis(k_in),
                k_out,
                half_frame_basis(k_out, phi_h),
                mi.mueller.stokes_basis(k_out),
            )
            if self.smooth or self.facet == 0.0:
                return m
            return m + self._facet(light, view, h) * facet

        def _facet(self, light, view, h):
            """The facet term in closed form (paper Sec. 2.4, Eqs. 35-38;
            ``lut.models.facet_reflection``, P(ζ) as
            ``lut.models.distributions.pdf``): P(ζ) sec⁴θn / (4 cos θi cos θs)
            times Fresnel's reflection matrix of the facet (normal h).  Its
            peak is sharper than a table resolves, and it costs a few
            operations."""
            hz = dr.maximum(h.z, 1e-6)
            zeta2 = dr.minimum((h.x * h.x + h.y * h.y) / (hz * hz), 1e8)  # tan²θn (Eq. 35)
            s2 = self.slope * self.slope
            if self.gaussian:
                density = dr.exp(-zeta2 / s2) / (math.pi * s2)  # Eq. 29, Beckmann with α = s
            else:
                density = 3.0 / (math.pi * s2) * dr.exp(-math.sqrt(6.0) * dr.sqrt(zeta2) / self.slope)
            scale = density * dr.square(1.0 + zeta2) / (4.0 * dr.maximum(light.z * view.z, 1e-12))
            return fresnel_reflection(light, view, h, self.eta) * scale

        def _mirror(self, si, light, view):
            """The smooth interface's delta: facet x Fresnel's reflection matrix,
            in Mitsuba's Stokes bases (as ``pplastic`` refers its own)."""
            return fresnel_reflection(light, view, mi.Vector3f(0.0, 0.0, 1.0), self.eta) * self.facet

        def _rays(self, ctx, si, wo):
            """(towards the light, towards the viewer) of a query."""
            if ctx.mode == mi.TransportMode.Radiance:
                return wo, si.wi
            return si.wi, wo

        # -- sampling ---------------------------------------------------------
        def _distribution(self):
            return mi.MicrofacetDistribution(mi.MicrofacetType.Beckmann, self.alpha, False)

        def _mirror_choice(self, cos_i):
            r = mi.fresnel(cos_i, self.eta)[0] * self.facet
            return dr.clip(r, *MIRROR_CHOICE)

        def _pdf(self, ctx, si, wo, active):
            if not ctx.is_enabled(self.lobe, 0):
                return mi.Float(0.0)  # only the mirror (a delta) is asked for
            cos_i, cos_o = mi.Frame3f.cos_theta(si.wi), mi.Frame3f.cos_theta(wo)
            pdf = mi.warp.square_to_cosine_hemisphere_pdf(wo)
            if not self.smooth:
                h = dr.normalize(si.wi + wo)
                lobe = self._distribution().pdf(si.wi, h) / (4.0 * dr.abs(dr.dot(wo, h)))
                pdf = (1.0 - FACET_LOBE_WEIGHT) * pdf + FACET_LOBE_WEIGHT * lobe
            elif ctx.is_enabled(mi.BSDFFlags.DeltaReflection, 1):
                pdf = pdf * (1.0 - self._mirror_choice(cos_i))
            return dr.select(active & (cos_i > 0.0) & (cos_o > 0.0), pdf, 0.0)

        def sample(self, ctx, si, sample1, sample2, active=True):
            cos_i = mi.Frame3f.cos_theta(si.wi)
            active = active & (cos_i > 0.0)
            bs = dr.zeros(mi.BSDFSample3f)
            wo = mi.warp.square_to_cosine_hemisphere(sample2)
            if not self.smooth:
                m = self._distribution().sample(si.wi, sample2)[0]
                lobe_wo = mi.reflect(si.wi, m)
                wo = dr.select(sample1 < FACET_LOBE_WEIGHT, lobe_wo, wo)
            has_mirror = self.smooth and ctx.is_enabled(mi.BSDFFlags.DeltaReflection, 1)
            has_lobe = ctx.is_enabled(self.lobe, 0)
            mirror = active & False
            if has_mirror:
                choice = self._mirror_choice(cos_i) if has_lobe else 1.0
                mirror = active & (sample1 < choice)
                wo = dr.select(mirror, mi.reflect(si.wi), wo)
            bs.wo = wo
            bs.eta = 1.0
            bs.pdf = self._pdf(ctx, si, wo, active)
            bs.sampled_component = dr.select(mirror, mi.UInt32(1), mi.UInt32(0))
            lobe_type = +self.lobe
            bs.sampled_type = dr.select(mirror, mi.UInt32(+mi.BSDFFlags.DeltaReflection), mi.UInt32(lobe_type))
            value = self.eval(ctx, si, wo, active & _not(mirror))
            weight = value / dr.select(bs.pdf > 0.0, bs.pdf, 1.0)
            if has_mirror:
                light, view = self._rays(ctx, si, wo)
                weight = dr.select(mirror, self._mirror(si, light, view) / choice, weight)
                bs.pdf = dr.select(mirror, choice, bs.pdf)
            ok = active & (bs.pdf > 0.0) & (mi.Frame3f.cos_theta(wo) > 0.0)
            return bs, dr.select(ok, weight, 0.0)

        def eval(self, ctx, si, wo, active=True):
            cos_i, cos_o = mi.Frame3f.cos_theta(si.wi), mi.Frame3f.cos_theta(wo)
            active = active & (cos_i > 0.0) & (cos_o > 0.0)
            if not ctx.is_enabled(self.lobe, 0):
                return mi.Spectrum(0.0)
            light, view = self._rays(ctx, si, wo)
            value = self._brdf(si, light, view, active) * cos_o
            return dr.select(active, value, 0.0)

        def pdf(self, ctx, si, wo, active=True):
            return self._pdf(ctx, si, wo, active)

        def eval_pdf(self, ctx, si, wo, active=True):
            return self.eval(ctx, si, wo, active), self._pdf(ctx, si, wo, active)

        def to_string(self):
            return f"GermerPaint[{self.paint.type_dict()}, facet={self.facet}, lut={self.lut_path!r}]"

    return GermerPaint
