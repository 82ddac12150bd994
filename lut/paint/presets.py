"""The paper's three samples as paints, with plausible spectral colours, and
common finishes (gloss to flat) as data, below them.

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

import functools

from ..colour.management import Spectrum
from .core import Paint


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


# ---------------------------------------------------------------------- finishes
#
# Common finishes, from high gloss to flat, as data: the paint-trade names
# are classified by specular gloss (ASTM D523 at 60°; the Master Painters
# Institute's Gloss and Sheen Standards give each level a range), and in the
# paper's facet model the interface's RMS slope is what sets it.  Each
# finish's slope is chosen so that ``lut.paint.gloss.specular_gloss`` at 60° falls
# inside its MPI range (``GLOSS_RANGE``; tests/test_assets.py checks it).
# What the paper gives and what is our choice:
#
# * n 1.5: the binder index the paper uses for all three of its samples.
# * Slope distribution: Gaussian for the glossy to eggshell finishes, whose
#   interface is binder levelled over the pigment (the paper's Fig. 1 and
#   glossy red use Gaussian slopes); exponential for matte and flat, whose
#   pigment-rich surface is rough like the paper's CARC (exponential, Sec. 4).
# * g 0.3: the only Henyey-Greenstein asymmetry the paper quotes (CARC).
# * ρ(λ): a ColorChecker (N. Ohta) reflectance per finish, so the library
#   shows five hues; our choice.  single(λ): 0.5·ρ(λ) for saturated
#   colours, as our glossy_red preset (the paper finds single scattering
#   visible where a pigment absorbs, Fig. 2 right); 0 for the pale eggshell,
#   as the paper's glossy white (multiply scattered light dominates, Fig. 2
#   left).
# * Facet weight 1: the exposed interface reflects by Fresnel alone.

#: Finish name: (MPI gloss level, its 60° gloss range in GU, ColorChecker
#: patch of ρ, single-scatter factor of ρ, RMS slope, slope distribution).
FINISH_DATA = {
    "gloss": ("Gloss Level 6, gloss", (70.0, 85.0), "blue", 0.5, 0.02, "gaussian"),
    "satin": ("Gloss Level 4, satin", (20.0, 35.0), "orange yellow", 0.5, 0.065, "gaussian"),
    "eggshell": ("Gloss Level 3, eggshell", (10.0, 25.0), "neutral 8 (.23 D)", 0.0, 0.1, "gaussian"),
    "matte": ("Gloss Level 2, velvet/matte", (0.0, 10.0), "blue sky", 0.5, 0.25, "exponential"),
    "flat": ("Gloss Level 1, flat (camouflage)", (0.0, 5.0), "dark skin", 0.5, 0.5, "exponential"),
}

#: The 60° gloss range of each finish (gloss units), from FINISH_DATA.
GLOSS_RANGE = {name: data[1] for name, data in FINISH_DATA.items()}


def finish(name: str, space: str = "Linear Rec.709") -> Paint:
    """A common finish by name (``FINISH_DATA``)."""
    if name not in FINISH_DATA:
        raise ValueError(f"finish must be one of {', '.join(FINISH_DATA)}, got {name!r}")
    _, _, patch, single, slope, distribution = FINISH_DATA[name]
    dataset = f"ColorChecker N Ohta/{patch}"
    return Paint(
        n=1.5,
        rho=Spectrum(dataset),
        single=Spectrum(dataset, scale=single, name=f"{single} x ColorChecker {patch}") if single else 0.0,
        g=0.3,
        slope=slope,
        distribution=distribution,
        facet=1.0,
        space=space,
        name=name,
    )


FINISHES = {name: functools.partial(finish, name) for name in FINISH_DATA}

#: Everything the bundled asset library ships: the paper's presets, then the finishes.
LIBRARY = {**PRESETS, **FINISHES}


def library_paint(name: str, space: str = "Linear Rec.709") -> Paint:
    """A paint of the bundled library (``LIBRARY``) by name."""
    if name not in LIBRARY:
        raise ValueError(f"library paint must be one of {', '.join(LIBRARY)}, got {name!r}")
    return LIBRARY[name](space)
