"""Mitsuba 3 scenes of the polarized paints: the plugin's properties of a
``lut.Paint``, Mitsuba's ``pplastic`` of the same paint, the plane oracle
(a plane, a directional emitter, an orthographic sensor, the ``stokes``
integrator; a ``polarizer`` sheet in front of the emitter for polarized
light) and a sphere under a sun and a sky; and the Stokes images of a render.

The dictionaries are plain Python (``germer_dict``, ``pplastic_dict``); the
scene builders import mitsuba when called, with a polarized variant set and
``lut.polarized.register()`` done."""

from __future__ import annotations

import numpy as np

from ..colour import management as cm
from ..paint.core import Paint
from . import basis
from .mitsuba_bsdf import PLUGIN


def _colour(value, space):
    """A paint colour as a Mitsuba texture: a spectrum as given (nm, value),
    a grey as a float, RGB as Mitsuba's linear-sRGB texture."""
    if isinstance(value, cm.Spectrum):
        pairs = zip(cm.WAVELENGTHS, value.values, strict=True)
        return {"type": "spectrum", "value": [(float(w), float(v)) for w, v in pairs]}
    rgb = [float(v) for v in np.broadcast_to(np.asarray(value, float), (3,))]
    if rgb[0] == rgb[1] == rgb[2]:
        return rgb[0]
    if space != cm.DEFAULT_SPACE:
        raise ValueError(
            f"paint space must be {cm.DEFAULT_SPACE!r} for RGB colours in Mitsuba (its RGB is linear sRGB), "
            f"got {space!r}"
        )
    return {"type": "rgb", "value": rgb}


def germer_dict(paint: Paint, cache=None) -> dict:
    """The ``germer_paint`` BSDF of a paint, for ``mitsuba.load_dict``."""
    if not isinstance(paint, Paint):
        raise ValueError(f"paint must be a lut.Paint, got {type(paint).__name__}")
    out = {
        "type": PLUGIN,
        "n": float(paint.n),
        "g": float(paint.g),
        "slope": float(paint.slope),
        "distribution": paint.distribution,
        "facet": float(paint.facet),
        "rho": _colour(paint.rho, paint.space),
        "single": _colour(paint.single, paint.space),
    }
    if cache is not None:
        out["cache"] = str(cache)
    return out


#: pplastic needs a positive roughness; a smooth paint's is this.
PPLASTIC_SMOOTH_ALPHA = 0.01


def pplastic_dict(paint: Paint) -> dict:
    """Mitsuba's ``pplastic`` given the same paint: the same index, its
    pigment colour as ``diffuse_reflectance``, a Beckmann facet lobe of α =
    the total RMS slope (``PPLASTIC_SMOOTH_ALPHA`` for a smooth paint).  It
    has neither the paper's 1/n² and 1/(1 − ρ r̄) nor single scattering; that
    is the comparison."""
    return {
        "type": "pplastic",
        "diffuse_reflectance": _colour(paint.rho, paint.space),
        "eta": float(paint.n),
        "alpha": float(paint.slope) if paint.slope > 0 else PPLASTIC_SMOOTH_ALPHA,
        "distribution": "beckmann",
    }


def direction(theta, phi) -> np.ndarray:
    """A unit vector at polar angle θ and azimuth φ (radians)."""
    return np.array([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])


def polarizer_frame(light):
    """The sheet of a plane oracle's polarizer: one unit towards the light,
    facing it (``mitsuba.ScalarTransform4f``)."""
    import mitsuba as mi

    return mi.ScalarTransform4f().look_at(origin=np.asarray(light, float).tolist(), target=[0, 0, 0], up=[0, 0, 1])


def plane_oracle(bsdf, light, view, polarizer=None, spp=36, size=4) -> np.ndarray:
    """(S0, S1, S2, S3), green channel (of a grey paint, every channel is the
    same light), of a plane under a directional
    emitter of unit irradiance from ``light`` (unit, towards it), seen by an
    orthographic sensor from ``view``, through a ``polarizer`` sheet (its
    angle, degrees) in front of the emitter if given; the Stokes basis is the
    sensor's (x = its left).  Every pixel sees one geometry.  The stratified
    sampler gives two renders of one set-up the same wavelengths, so a ratio
    of two of them is free of the spectral estimate's noise."""
    import mitsuba as mi

    light, view = np.asarray(light, float), np.asarray(view, float)
    scene = {
        "type": "scene",
        # volpath carries the emitter's light through the polarizer (a null BSDF).
        "integrator": {"type": "stokes", "integrator": {"type": "volpath", "max_depth": 2}},
        "sensor": {
            "type": "orthographic",
            "to_world": mi.ScalarTransform4f().look_at(origin=(5 * view).tolist(), target=[0, 0, 0], up=[0, 0, 1])
            @ mi.ScalarTransform4f().scale([0.1, 0.1, 1.0]),
            "film": {"type": "hdrfilm", "width": size, "height": size, "rfilter": {"type": "box"}},
            "sampler": {"type": "stratified", "sample_count": spp},
        },
        "plane": {"type": "rectangle", "bsdf": bsdf},
        "sun": {"type": "directional", "direction": (-light).tolist(), "irradiance": {"type": "rgb", "value": 1.0}},
    }
    if polarizer is not None:
        scene["polarizer"] = {
            "type": "rectangle",
            "to_world": polarizer_frame(light) @ mi.ScalarTransform4f().scale([0.3, 0.3, 1.0]),
            "bsdf": {"type": "polarizer", "theta": {"type": "spectrum", "value": float(polarizer)}},
        }
    image = np.array(mi.render(mi.load_dict(scene)))
    return image.reshape(-1, image.shape[-1]).mean(axis=0)[3:].reshape(4, 3)[:, 1]


def model_mueller(paint: Paint, theta_l, phi_l, theta_v, phi_v, channel=1) -> np.ndarray:
    """The models' Mueller matrix × cos θl (one RGB ``channel``) of light from
    (θl, φl) seen from (θv, φv) in a shading frame (radians, broadcast), in
    Mitsuba's Stokes bases there: the transported bases of that frame, the
    models' frame turned by φl − π (``basis.mueller_in_transported_basis``)."""
    theta_l, theta_v = np.asarray(theta_l, float), np.asarray(theta_v, float)
    phi_s = phi_v - phi_l + np.pi
    m = paint.mueller(theta_l, theta_v, phi_s)[..., channel, :, :]
    return (
        basis.mueller_in_transported_basis(m, theta_l, theta_v, phi_s, phi_l - np.pi) * np.cos(theta_l)[..., None, None]
    )


def model_stokes(paint: Paint, theta_l, phi_l, theta_v, phi_v, polarizer=None, channel=1) -> np.ndarray:
    """What ``plane_oracle`` renders, from the models: the Stokes vector at the
    sensor, in its basis (x = its left), of unit irradiance, unpolarized or
    through the ``polarizer`` sheet (degrees: linearly polarized along the
    sheet's local x turned by −θ about the light's direction of travel)."""
    light, view = direction(theta_l, phi_l), direction(theta_v, phi_v)
    m = model_mueller(paint, theta_l, phi_l, theta_v, phi_v, channel)
    s_in = np.array([1.0, 0.0, 0.0, 0.0])
    if polarizer is not None:
        import mitsuba as mi

        s, p = basis.transported_basis(-light)
        axis = np.array(polarizer_frame(light) @ mi.ScalarVector3f(1.0, 0.0, 0.0))
        chi = np.arctan2(axis @ p, axis @ s) - np.radians(polarizer)
        s_in = 0.5 * np.array([1.0, np.cos(2 * chi), np.sin(2 * chi), 0.0])
    left = np.cross([0.0, 0.0, 1.0], -view)
    s_out, p_out = basis.transported_basis(view)
    to_sensor = basis.stokes_rotation(basis.turn(view, s_out, p_out, left / np.linalg.norm(left)))
    return to_sensor @ m @ s_in


def sphere_scene(bsdf, size=128, spp=16, sun=(40.0, 30.0), sky=0.15, max_depth=3) -> dict:
    """A unit sphere of ``bsdf`` seen by a perspective camera from +y, under a
    directional sun (elevation and azimuth, degrees; irradiance 3) and a
    uniform sky (``constant`` radiance ``sky``), rendered through the
    ``stokes`` integrator over ``path``."""
    import mitsuba as mi

    elevation, azimuth = np.radians(sun)
    towards_sun = [np.cos(elevation) * np.sin(azimuth), np.cos(elevation) * np.cos(azimuth), np.sin(elevation)]
    return {
        "type": "scene",
        "integrator": {"type": "stokes", "integrator": {"type": "path", "max_depth": max_depth}},
        "sensor": {
            "type": "perspective",
            "fov": 28.0,
            "to_world": mi.ScalarTransform4f().look_at(origin=[0, 4.5, 0.6], target=[0, 0, 0], up=[0, 0, 1]),
            "film": {"type": "hdrfilm", "width": size, "height": size, "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "ball": {"type": "sphere", "bsdf": bsdf},
        "sun": {
            "type": "directional",
            "direction": [-c for c in towards_sun],
            "irradiance": {"type": "rgb", "value": 3.0},
        },
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": float(sky)}},
    }


def stokes_images(image) -> np.ndarray:
    """(4, H, W, 3): S0..S3 (RGB) of a ``stokes`` render in a spectral variant
    (its channels R, G, B, then S0..S3 as RGB each)."""
    image = np.asarray(image)
    if image.ndim != 3 or image.shape[-1] < 15:
        raise ValueError(
            f"a stokes render of a spectral variant has 15 or more channels (RGB, then S0..S3 as RGB), got shape "
            f"{image.shape}"
        )
    return np.moveaxis(image[..., 3:15].reshape(image.shape[:2] + (4, 3)), 2, 0)


#: Rec. 709 luminance of linear sRGB: CIE ȳ, which weighs every wavelength
#: positively, so the Stokes vectors of Y are those of real light (an sRGB
#: channel's weights go negative and its "degree of polarization" can pass 1).
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])


def luminance(stokes) -> np.ndarray:
    """(4, ...) Stokes images of luminance Y from RGB ones (4, ..., 3)."""
    return np.asarray(stokes) @ LUMINANCE


def degree_and_angle(stokes) -> tuple[np.ndarray, np.ndarray]:
    """Degree of linear polarization sqrt(S1² + S2²)/S0 (0 where S0 is 0) and
    its angle ½ atan2(S2, S1) (radians, in (−π/2, π/2]), of Stokes images
    (4, ...)."""
    s0, s1, s2 = stokes[0], stokes[1], stokes[2]
    linear = np.hypot(s1, s2)
    dolp = np.divide(linear, s0, out=np.zeros_like(linear), where=s0 > 0)
    return np.clip(dolp, 0.0, 1.0), 0.5 * np.arctan2(s2, s1)
