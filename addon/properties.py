"""The paint settings stored on every material: ``material.paint_lut``.

A property for every ``lut.Paint`` field a material stores, made from its
description in ``lut.paint.schema.PAINT_FIELDS`` (name, limits, slider, tooltip,
default), plus the preset, the baked LUT's path and a stale flag.
Choosing a preset fills the fields with the preset's values (its spectral
colours shown as RGB in the scene's working space) and bakes use the
preset's exact spectral paint; editing any physical field afterwards makes
the paint "Custom".  Other spectral paints are stored
whole (``spectral_paint``, JSON) under the "Spectral" preset."""

from __future__ import annotations

import dataclasses
import functools
import json
import sys

import bpy

from . import live
from ._lut import fitting, lut, schema
from .live import working_space

#: The paint fields a material stores (in ``lut.Paint``'s order).
MATERIAL_FIELDS = tuple(spec for spec in schema.PAINT_FIELDS.values() if spec.on_material)

#: The preset menu, each item with its stored number (files keep the number:
#: Custom 0, the paper's samples 1-3, Spectral 4; a new sample takes 5 on).
PRESET_ITEMS = [
    ("CUSTOM", "Custom", "Paint given by the fields below", 0),
    *(
        (name, name.replace("_", " ").title(), f"The paper's {name.replace('_', ' ')} sample", n if n < 4 else n + 1)
        for n, name in enumerate(lut.PRESETS, start=1)
    ),
    ("SPECTRAL", "Spectral", "The spectral paint stored from Python (addon.api.set_paint); the fields show its RGB",
     4),
]  # fmt: skip
#: The menu of a material with no spectral paint stored: Spectral would have nothing to show.
_PRESET_ITEMS_RGB = PRESET_ITEMS[:-1]


def _preset_items(self, context):
    """Spectral is offered only where a spectral paint is stored (module-level
    lists: Blender keeps no reference to what a callback returns)."""
    return PRESET_ITEMS if self.spectral_paint else _PRESET_ITEMS_RGB


_applying_preset = False

# Blender 5.0 warns when a "//" path is stored in a FILE_PATH property that
# does not declare this option.  It is checked on 5.0 only, so earlier
# versions are not asked for it.
_RELATIVE_PATH = {"PATH_SUPPORTS_BLEND_RELATIVE"} if bpy.app.version >= (5, 0, 0) else set()


def _leave_preset(self):
    if not _applying_preset and self.preset != "CUSTOM":
        self["preset"] = 0  # set the enum without re-running its update


def _type_changed(self, context):
    """A field that shapes the paint type changed (index, anisotropy, slope,
    distribution): the bake is stale, and the paint no longer a preset."""
    self.stale = True
    _leave_preset(self)


def _colour_changed(self, context):
    """A colour changed (pigment, single scattering, surface reflection):
    the node groups take it as an input at once; no bake, nothing stale."""
    _leave_preset(self)
    if not _applying_preset:
        _send_colours(self)


def _send_colours(settings):
    material = settings.id_data
    if isinstance(material, bpy.types.Material):
        live.update_inputs(material)


#: What a switch of a material's OSL setting calls, with the material
#: (``addon.api.switch_variant`` adds itself: the API imports this module).
OSL_SWITCHED = []


def _osl_changed(self, context):
    """The Cycles OSL variant was switched: a baked material is wired to the
    variant's group (or back to the SVM one) at once (``OSL_SWITCHED``)."""
    material = self.id_data
    if isinstance(material, bpy.types.Material):
        for switch in OSL_SWITCHED:
            switch(material)


def _preset_changed(self, context):
    before = self.type_key()
    if self.preset == "SPECTRAL":
        try:
            set_fields(self, self.to_paint())
        except ValueError as exc:  # a stored paint that is not valid: said once, baked never
            print(f"Paint LUT: {self.id_data.name}: {exc}", file=sys.stderr)
            self.stale = True
    elif self.preset != "CUSTOM":
        set_fields(self, lut.preset(self.preset, working_space()))
    if self.type_key() != before or not self.lut_path:
        self.stale = True
    _send_colours(self)


def set_fields(settings, paint: lut.Paint) -> None:
    """Fill the physical fields from a paint (spectra shown as their RGB in
    the paint's working space) without touching the preset choice."""
    global _applying_preset
    _applying_preset = True
    try:
        values = node_inputs(paint)
        for spec in MATERIAL_FIELDS:
            if spec.kind == "index":  # a dispersive n at the sodium D line
                value = float(paint.index_at(lut.paint.REFERENCE_WAVELENGTH))
            elif spec.label in values:  # colours and the facet weight: the node group's inputs that render them
                value = values[spec.label]
            elif spec.kind == "choice":
                value = getattr(paint, spec.name).upper()
            else:
                value = getattr(paint, spec.name)
            setattr(settings, spec.name, value)
    finally:
        _applying_preset = False


@functools.lru_cache(maxsize=32)
def _spectral_inputs(paint_json: str):
    return lut.render.bake.node_inputs(lut.Paint.from_dict(json.loads(paint_json)))


def node_inputs(paint: lut.Paint) -> dict:
    """The group inputs of a paint (``lut.render.bake.node_inputs``): for an RGB
    paint its own colours; for a spectral one the RGB that renders it
    exactly (computed once per paint)."""
    if paint.spectral or paint.dispersive:
        return dict(_spectral_inputs(json.dumps(paint.to_dict(), sort_keys=True)))
    return lut.render.bake.node_inputs(paint, internal_reflectance=0.0)


def _exact(value):
    """Blender stores float properties in single precision (0.8 reads back as
    0.800000011920929); round to 6 decimals so the paint, and its cache key,
    are those of the number the artist typed."""
    return round(float(value), 6)


def _seen_constants(settings):
    """(a_D, r̄) of the baked type; before a bake those of the smooth
    interface of the same index (exact for smooth paints)."""
    if settings.diffuse_albedo > 0 and settings.internal_reflectance > 0:
        return settings.diffuse_albedo, settings.internal_reflectance
    n = _exact(settings.n)
    rs, rp = lut.models.fresnel.reflection_coefficients(1.0, n)
    return float(1.0 - 0.5 * (rs**2 + rp**2)), lut.models.internal_reflectance(n)


def _get_seen(self):
    albedo, rbar = _seen_constants(self)
    return tuple(float(v) for v in lut.render.bake.seen_of_pigment(tuple(self.rho), albedo, rbar))


def seen_limit(settings):
    """The most a channel of "Color as Seen" can show, a_D (what a white
    pigment shows head-on through the binder's interface: the light is
    transmitted in and out: 1 - R(0) = 0.96 under a smooth binder of n = 1.5,
    less under a rough one), when some channel is at it (its pigment at 1, so a larger
    value asked was capped there); None otherwise."""
    albedo, _ = _seen_constants(settings)
    return albedo if max(settings.rho) >= 1.0 - 1e-6 else None


def _set_seen(self, value):
    albedo, rbar = _seen_constants(self)
    self.rho = tuple(float(v) for v in lut.render.bake.pigment_of_seen(value, albedo, rbar))


class PaintLUTSettings(bpy.types.PropertyGroup):
    enabled: bpy.props.BoolProperty(
        name="Use Paint LUT", default=False, description="Render this material as a Paint LUT paint",
    )  # fmt: skip
    osl: bpy.props.BoolProperty(
        name="Cycles OSL Variant", default=False, update=_osl_changed,
        description="In Cycles with Open Shading Language on (CPU, OptiX), add signed ramp closures that follow "
        "the paint closer at grazing light and on dark rough paints; other scenes render the SVM closures",
    )  # fmt: skip
    preset: bpy.props.EnumProperty(
        name="Preset", items=_preset_items, default=0, update=_preset_changed,
        description="One of the paper's three paints, or Custom",
    )  # fmt: skip
    osl_problem: bpy.props.StringProperty(
        name="OSL Problem", options={"HIDDEN"},
        description="Why the Cycles OSL variant could not be built here (the SVM group renders instead)",
    )  # fmt: skip
    lut_path: bpy.props.StringProperty(
        name="LUT", subtype="FILE_PATH", description="The baked lookup table", options=_RELATIVE_PATH,
    )  # fmt: skip
    stale: bpy.props.BoolProperty(name="Needs Bake", default=True, description="The paint changed since the last bake")
    internal_reflectance: bpy.props.FloatProperty(
        name="Internal Reflectance", default=0.0, options={"HIDDEN"},
        description="r-bar of the baked paint type (turns the pigment colour into the diffuse amplitude)",
    )  # fmt: skip
    diffuse_albedo: bpy.props.FloatProperty(
        name="Diffuse Albedo", default=0.0, options={"HIDDEN"},
        description="a_D of the baked paint type: the head-on diffuse colour of a white pigment",
    )  # fmt: skip
    seen: bpy.props.FloatVectorProperty(
        name="Color as Seen", subtype="COLOR", size=3, min=0.0, max=1.0, get=_get_seen, set=_set_seen,
        description="The diffuse colour the paint shows head-on (k(rho) times the interface's albedo); "
        "setting it sets the Pigment Color that shows it (beyond what a white pigment shows, it is limited)",
    )  # fmt: skip
    fits: bpy.props.StringProperty(
        name="Fit Errors", options={"HIDDEN"},
        description="The baked fits' residual and target matrices per engine (JSON): the error of any colour",
    )  # fmt: skip
    spectral_paint: bpy.props.StringProperty(
        name="Spectral Paint", options={"HIDDEN"},
        description="The spectral paint of the Spectral preset, as lut.Paint.to_dict JSON",
    )  # fmt: skip

    def type_key(self) -> str:
        """The fields that shape the paint type, as text (a change means a bake)."""
        shape = (getattr(self, spec.name) for spec in MATERIAL_FIELDS if spec.shapes_type)
        return "|".join([*(v if isinstance(v, str) else str(_exact(v)) for v in shape), self.spectral_paint])

    def to_paint(self, space: str | None = None) -> lut.Paint:
        """The lut.Paint these settings describe (a preset's exact spectral
        paint while the preset is selected)."""
        space = space or working_space()
        # "" where a file stores Spectral but no spectral paint (the menu no
        # longer offers it): the fields are the paint.
        preset = self.preset or "CUSTOM"
        if preset == "SPECTRAL":
            if not self.spectral_paint:
                raise ValueError("preset 'Spectral' needs a spectral paint stored with addon.api.set_paint")
            try:
                data = json.loads(self.spectral_paint)
            except ValueError:
                raise ValueError("the stored spectral paint is not valid JSON; store it again with set_paint") from None
            return dataclasses.replace(lut.Paint.from_dict(data), space=space)
        if preset != "CUSTOM":
            return lut.preset(preset, space)
        fields = {}
        for spec in MATERIAL_FIELDS:
            value = getattr(self, spec.name)
            if spec.kind == "colour":
                value = tuple(_exact(v) for v in value)
            elif spec.kind == "choice":
                value = value.lower()
            else:
                value = _exact(value)
            fields[spec.name] = value
        return lut.Paint(**fields, space=space)


def paint_property(spec: schema.FieldSpec):
    """The Blender property of a paint field: its label, default, tooltip,
    the material's hard limits (``FieldSpec.material_range``) and the
    slider's (``FieldSpec.soft``).  Fields that shape the paint type make
    the bake stale; colours go to the node groups at once."""
    common = {
        "name": spec.label,
        "description": spec.tooltip or spec.help[:1].upper() + spec.help[1:],
        "update": _type_changed if spec.shapes_type else _colour_changed,
    }
    if spec.kind == "choice":
        items = [(c.upper(), c.title(), f"{c.title()} {spec.help}") for c in spec.choices]
        return bpy.props.EnumProperty(items=items, default=spec.default.upper(), **common)
    limits = {}
    hard = spec.material_range
    for key, value in (("min", hard.low), ("max", hard.high), ("soft_min", spec.soft[0]), ("soft_max", spec.soft[1])):
        if value is not None:
            limits[key] = value
    if spec.precision is not None:
        limits["precision"] = spec.precision
    if spec.kind == "colour":
        return bpy.props.FloatVectorProperty(subtype="COLOR", size=3, default=spec.default, **limits, **common)
    return bpy.props.FloatProperty(default=spec.default, **limits, **common)


def _add_paint_fields(cls):
    """Give ``cls`` a property per paint field a material stores, after its
    ``preset`` (Blender reads the properties from the class annotations)."""
    annotations = {}
    for key, value in cls.__annotations__.items():
        annotations[key] = value
        if key == "preset":
            annotations.update((spec.name, paint_property(spec)) for spec in MATERIAL_FIELDS)
    cls.__annotations__ = annotations
    return cls


_add_paint_fields(PaintLUTSettings)


class PaintLUTSceneSettings(bpy.types.PropertyGroup):
    """A scene's Paint LUT settings: how its EEVEE draws paint materials
    (``lut.render.fitting.EEVEE_MODES``).  A change applies at the next bake
    (the panel says so; a bake computes only the EEVEE fits it lacks)."""

    eevee_mode: bpy.props.EnumProperty(
        name="EEVEE",
        description="How EEVEE draws paint materials; applies at the next bake",
        items=[
            (
                "CONVERGED", "Converged",
                "More closures where three miss the goal: exact once samples average them "
                "(final renders; the viewport converges as it accumulates samples)",
            ),
            ("EXACT", "Exact at 1 sample", "At most the three closures EEVEE sums exactly: no noise at one sample"),
        ],
        default=fitting.DEFAULT_EEVEE_MODE,
    )  # fmt: skip


CLASSES = (PaintLUTSettings, PaintLUTSceneSettings)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Material.paint_lut = bpy.props.PointerProperty(type=PaintLUTSettings)
    bpy.types.Scene.paint_lut = bpy.props.PointerProperty(type=PaintLUTSceneSettings)


def unregister():
    del bpy.types.Scene.paint_lut
    del bpy.types.Material.paint_lut
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
