"""The paint: a paint type and its colours (``core.Paint``), the fields a
user sets and their ranges (``schema``), the named paints (``presets``) and
their gloss (``gloss``, after the gloss standards).

Owns what a paint *is*: its BRDF and Mueller matrix come from the paper's
models.  May import ``lut.models`` and ``lut.colour``; nothing above it
(LUT files, the render fit and the add-on build on it)."""

from . import core, gloss, presets, schema
from .core import (
    COMPONENTS,
    DISPERSION_BANDS,
    REFERENCE_WAVELENGTH,
    Paint,
    diffuse_amplitude,
    pigment_of_amplitude,
    reference_index,
)

__all__ = [
    "COMPONENTS",
    "DISPERSION_BANDS",
    "REFERENCE_WAVELENGTH",
    "Paint",
    "core",
    "diffuse_amplitude",
    "gloss",
    "pigment_of_amplitude",
    "presets",
    "reference_index",
    "schema",
]
