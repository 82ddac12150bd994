"""Checks that a paint can be stored on a material exactly.

A material stores an RGB paint in its panel fields (``properties``), whose
limits are narrower than ``lut.Paint``'s (n in [1, 4], g within ±0.99, slope
up to 3, surface reflection up to 1) and whose colours are in the scene's
working space: Blender would clamp a value beyond them, and the material
would bake a different paint.  ``check_paint_fits`` refuses such a paint with
an error naming the field and its range instead.  Presets and spectral
paints are stored whole, so they always fit."""

from __future__ import annotations

import numpy as np

from . import properties
from ._lut import lut

#: Panel fields checked against their property's hard limits.
_SCALARS = ("n", "g", "slope", "facet")
_COLOURS = ("rho", "single")
#: Colour conversion between working spaces is rounded at this level.
_TOLERANCE = 1e-6


def _limits(field):
    prop = properties.PaintLUTSettings.bl_rna.properties[field]
    return prop.hard_min, prop.hard_max


def _stored_whole(paint: lut.Paint) -> bool:
    """Whether set_paint stores the paint as a preset or spectral paint."""
    return paint.spectral or any(paint == lut.preset(name, paint.space) for name in lut.PRESETS)


def check_paint_fits(paint: lut.Paint, space: str | None = None) -> None:
    """Raise ValueError unless ``paint`` can be stored on a material without
    Blender clamping it (``addon.api.set_paint``): each RGB paint field within
    the panel's limits, its colours within [0, 1] once converted to the
    working space ``space`` (default: the open file's)."""
    if not isinstance(paint, lut.Paint):
        raise ValueError(f"paint must be a lut.Paint, got {type(paint).__name__}")
    if _stored_whole(paint):
        return
    space = space or properties.working_space()
    for field in _SCALARS:
        low, high = _limits(field)
        value = getattr(paint, field)
        if not low - _TOLERANCE <= value <= high + _TOLERANCE:
            raise ValueError(
                f"{field} must be in [{low:g}, {high:g}] on a material (the Paint LUT panel's limits), got {value:g}"
            )
    matrix = lut.colour_management.rgb_to_rgb(paint.space, space) if space != paint.space else np.eye(3)
    for field in _COLOURS:
        low, high = _limits(field)
        rgb = matrix @ np.asarray(getattr(paint, field), dtype=float)
        if np.any(rgb < low - _TOLERANCE) or np.any(rgb > high + _TOLERANCE):
            shown = ", ".join(f"{v:.4g}" for v in rgb)
            where = f" in the scene's working space {space}" if space != paint.space else ""
            raise ValueError(f"{field} must be in [{low:g}, {high:g}] per channel{where} on a material, got ({shown})")
