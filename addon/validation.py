"""Checks that a paint can be stored on a material exactly.

A material stores an RGB paint in its panel fields (``properties``), whose
limits (``lut.paint.schema``: ``FieldSpec.material``, e.g. n in [1, 4], g within
±0.99) are narrower than ``lut.Paint``'s and whose colours are in the
scene's working space: Blender would clamp a value beyond them, and the
material would bake a different paint.  ``check_paint_fits`` refuses such a
paint with an error naming the field and its range instead.  Presets and
spectral paints are stored whole, so they always fit."""

from __future__ import annotations

import numpy as np

from . import live, properties
from ._lut import lut, schema

#: Colour conversion between working spaces is rounded at this level.
_TOLERANCE = 1e-6
_WHERE = " on a material (the Paint LUT panel's limits)"


def _stored_whole(paint: lut.Paint) -> bool:
    """Whether set_paint stores the paint as a preset or spectral paint."""
    return paint.spectral or any(paint == lut.preset(name, paint.space) for name in lut.PRESETS)


def check_paint_fits(paint: lut.Paint, space: str | None = None) -> None:
    """Raise ValueError unless ``paint`` can be stored on a material without
    Blender clamping it (``addon.api.set_paint``): each RGB paint field within
    the panel's limits, its colours within them once converted to the
    working space ``space`` (default: the open file's)."""
    if not isinstance(paint, lut.Paint):
        raise ValueError(f"paint must be a lut.Paint, got {type(paint).__name__}")
    if _stored_whole(paint):
        return
    space = space or live.working_space()
    matrix = lut.colour.management.rgb_to_rgb(paint.space, space) if space != paint.space else np.eye(3)
    for spec in properties.MATERIAL_FIELDS:
        limits = spec.material_range
        if limits is None:  # a choice
            continue
        value = getattr(paint, spec.name)
        if spec.kind != "colour":
            schema.check_range(value, spec.name, limits, noun="", context=_WHERE, tolerance=_TOLERANCE)
            continue
        rgb = matrix @ np.asarray(value, dtype=float)
        if not all(limits.contains(v, _TOLERANCE) for v in rgb):
            where = f" in the scene's working space {space}" if space != paint.space else ""
            shown = tuple(round(float(v), 4) for v in rgb)
            raise schema.range_error(shown, spec.name, limits, noun="", context=f" per channel{where} on a material")
