"""Germer's polarized light-scattering models of glossy and matte paints
(T. A. Germer, "Polarized light diffusely scattered under smooth and rough
interfaces"), as vectorized numpy functions returning Mueller BSDFs [sr⁻¹].

See docs/models.md for conventions, deviations from the paper and accuracy.
The paper's random-pairs method is kept apart, as a check, in
``lut.models.reference``."""

from .facet import facet_reflection, facet_transmission
from .fresnel import internal_reflectance
from .mueller import STOKES_45, jones_to_mueller, polarization_parameters
from .rough import rough_diffuse, rough_internal_reflectance, rough_single
from .smooth import smooth_diffuse, smooth_single

__all__ = [
    "STOKES_45",
    "facet_reflection",
    "facet_transmission",
    "internal_reflectance",
    "jones_to_mueller",
    "polarization_parameters",
    "rough_diffuse",
    "rough_internal_reflectance",
    "rough_single",
    "smooth_diffuse",
    "smooth_single",
]
