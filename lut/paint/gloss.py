"""Specular gloss of a paint as a glossmeter reads it (ASTM D523 / ISO 2813).

A glossmeter lights the sample with a near-collimated beam at θ from the
normal and collects the flux reflected into a rectangular receptor aperture
centred on the mirror direction; the reading, in gloss units (GU), is that
flux relative to the flux a polished black glass of index 1.567 (sodium D
line) reflects in the same geometry, which reads 100 GU.  The receptor
apertures are ASTM D523's (in the plane of incidence × perpendicular to it):

    20°: 1.8° × 3.6°    60°: 4.4° × 11.7°    85°: 4.0° × 6.0°

Here the flux is the paint's luminance-weighted (CIE Y of its working space)
BRDF integrated over the receptor aperture, plus the mirror reflection of a
smooth interface; the source aperture (0.75° × 2.5° in the standard) is
taken as a point, which only blurs lobes narrower than the receptor.  The
standard's own reflection is its Fresnel reflectance (paper Sec. 2.4's
facet model for a flat surface).  This is what ``lut.paint.presets`` uses to put
each finish's slope in its gloss range (MPI's Gloss and Sheen Standards:
gloss at 60°, sheen at 85°)."""

from __future__ import annotations

import numpy as np

from ..colour import management as cm
from ..models import fresnel

#: The primary standard's index (black glass, sodium D line).
STANDARD_INDEX = 1.567

#: Receptor aperture (in plane, perpendicular) in degrees, per geometry.
RECEPTOR = {20: (1.8, 3.6), 60: (4.4, 11.7), 85: (4.0, 6.0)}


def fresnel_reflectance(theta, n) -> float:
    """½(|r_s|² + |r_p|²) of a flat interface of index n at θ (radians)."""
    rs, rp = fresnel.reflection_coefficients(np.cos(theta), n)
    return float(0.5 * (abs(rs) ** 2 + abs(rp) ** 2))


#: CIE Y of Rec.709 primaries (ITU-R BT.709): Y of scene-linear Rec.709 RGB.
REC709_Y = np.array([0.2126, 0.7152, 0.0722])


def luminance(rgb, space) -> float:
    """CIE Y of scene-linear RGB in working space ``space`` (via Rec.709)."""
    return float(REC709_Y @ (cm.rgb_to_rgb(space, "Linear Rec.709") @ np.asarray(rgb, dtype=float)))


def receptor_directions(theta, geometry, steps=(33, 65)):
    """Directions (θs, φs) and solid-angle weights [sr] covering the receptor
    aperture of ``geometry`` around the mirror direction of incidence θ
    (radians; the source at azimuth π as in ``lut.models``)."""
    along, across = np.radians(RECEPTOR[geometry]) / 2.0
    a = np.linspace(-along, along, steps[0])
    b = np.linspace(-across, across, steps[1])
    aa, bb = np.meshgrid(a, b, indexing="ij")
    tilt = np.clip(theta + aa, 0.0, np.pi / 2 - 1e-6)  # rotated in the plane of incidence
    x, y, z = np.cos(bb) * np.sin(tilt), np.sin(bb), np.cos(bb) * np.cos(tilt)
    theta_s = np.arccos(np.clip(z, -1.0, 1.0))
    phi_s = np.arctan2(y, x)
    # dΩ = cos β dα dβ on this grid (trapezoid weights along each axis).
    wa = np.full(a.size, a[1] - a[0])
    wa[[0, -1]] /= 2
    wb = np.full(b.size, b[1] - b[0])
    wb[[0, -1]] /= 2
    weights = np.outer(wa, wb) * np.cos(bb)
    return theta_s, phi_s, weights


def specular_gloss(paint, geometry: int = 60, steps=(33, 65)) -> float:
    """The paint's specular gloss in gloss units at ``geometry`` (20, 60 or
    85 degrees): the luminance of the flux it reflects into the receptor,
    per unit incident flux, over the black-glass standard's, times 100."""
    if geometry not in RECEPTOR:
        raise ValueError(f"geometry must be one of {', '.join(map(str, RECEPTOR))}, got {geometry!r}")
    theta = np.radians(geometry)
    theta_s, phi_s, weights = receptor_directions(theta, geometry, steps)
    brdf = paint.brdf(np.full(theta_s.shape, theta), theta_s, phi_s)  # (..., 3) sr⁻¹
    flux = np.tensordot(weights * np.cos(theta_s), brdf, axes=([0, 1], [0, 1]))  # RGB, per unit incident flux
    flux = flux + paint.specular_reflectance(np.array(theta))  # a smooth interface's mirror (0 when rough)
    return float(100.0 * luminance(flux, paint.space) / fresnel_reflectance(theta, STANDARD_INDEX))


def main() -> None:
    """Print the specular gloss of every paint of the bundled library."""
    from . import presets

    print("paint            20°     60°     85°   (gloss units)")
    for name in presets.LIBRARY:
        paint = presets.library_paint(name)
        values = "  ".join(f"{specular_gloss(paint, g):6.1f}" for g in sorted(RECEPTOR))
        print(f"{name:14s} {values}")


if __name__ == "__main__":
    main()
