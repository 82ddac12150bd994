"""The paper's three samples as paints, with plausible spectral colours.

What the paper gives and what is our choice:

* glossy_white (Fig. 2 left): n 1.5 and ρ 0.93 at 632.8 nm under a smooth
  interface (paper).  Our choice: ρ(λ) flat at 0.93 above 430 nm, falling to
  0.10 at 380 nm like a rutile TiO2 white (absorption edge near 410 nm); facet
  weight 1 (the mirror reflection of the smooth binder).
* glossy_red (Fig. 2 right): the combination of facet reflection and single
  volume scattering (paper; its parameters were hand-fitted and not given).
  Our choice: n 1.5, a glossy interface of Gaussian RMS slope 0.05, g 0
  (Rayleigh-Gans pigment), single(λ) = 0.5 · the ColorChecker (N. Ohta) "red"
  reflectance, and ρ(λ) = that reflectance for the multiply scattered light
  (0.05 at 441.6 nm, where the paper notes the reflectance is low).
* green_carc (Fig. 3): n 1.5, exponential slopes with RMS 2, g 0.3, ρ 0.05 at
  632.8 nm (paper).  Our choice: ρ(λ) = the ColorChecker (N. Ohta) "green"
  pigment reflectance scaled to 0.05 at 632.8 nm (not "foliage", whose
  chlorophyll edge above 700 nm no paint has); single = 1, the paper's Eq. 20
  unweighted (no absorption): at that weight the Sec. 2.5 model's η at
  n = 1.5 comes close to the facet model's at n = 1.2, which is the paper's
  point about this sample, and the hue comes from ρ.  Facet weight 1.
"""

from __future__ import annotations

from .colour_management import Spectrum
from .paint import Paint


def glossy_white(space: str = "Linear Rec.709") -> Paint:
    rho = Spectrum([380, 400, 410, 420, 430, 780], [0.10, 0.25, 0.55, 0.85, 0.93, 0.93], name="TiO2 white 0.93")
    return Paint(n=1.5, rho=rho, single=0.0, slope=0.0, facet=1.0, space=space, name="glossy_white")


def glossy_red(space: str = "Linear Rec.709") -> Paint:
    red = Spectrum("ColorChecker N Ohta/red")
    return Paint(
        n=1.5,
        rho=red,
        single=Spectrum("ColorChecker N Ohta/red", scale=0.5, name="0.5 x ColorChecker red"),
        g=0.0,
        slope=0.05,
        distribution="gaussian",
        facet=1.0,
        space=space,
        name="glossy_red",
    )


def green_carc(space: str = "Linear Rec.709") -> Paint:
    pigment = Spectrum("ColorChecker N Ohta/green")
    green = Spectrum(
        "ColorChecker N Ohta/green", scale=0.05 / float(pigment.at(632.8)), name="CARC green, 0.05 at 632.8 nm"
    )
    return Paint(
        n=1.5,
        rho=green,
        single=Spectrum.flat(1.0),
        g=0.3,
        slope=2.0,
        distribution="exponential",
        facet=1.0,
        space=space,
        name="green_carc",
    )


PRESETS = {"glossy_white": glossy_white, "glossy_red": glossy_red, "green_carc": green_carc}


def preset(name: str, space: str = "Linear Rec.709") -> Paint:
    """A preset paint by name."""
    if name not in PRESETS:
        raise ValueError(f"preset must be one of {', '.join(PRESETS)}, got {name!r}")
    return PRESETS[name](space)
