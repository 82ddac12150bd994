"""The Paint LUT panel, in Material Properties and in the shader editor's sidebar."""

from __future__ import annotations

import bpy

from . import api
from .properties import MATERIAL_FIELDS, seen_limit


def draw_settings(layout, material, scene=None):
    settings = material.paint_lut
    layout.prop(settings, "enabled")
    layout.prop(settings, "preset")
    col = layout.column(align=False)
    col.use_property_split = True
    col.use_property_decorate = False
    col.label(text="Colours (live: no bake)")
    col.prop(settings, "seen")
    limit = seen_limit(settings)
    if limit is not None:
        col.label(text=seen_limit_text(limit), icon="INFO")
    for spec in MATERIAL_FIELDS:  # the colours and weights (lut.paint.schema)
        if not spec.shapes_type:
            col.prop(settings, spec.name)
    col.label(text="Paint type (bake)")
    for spec in MATERIAL_FIELDS:
        if spec.shapes_type:
            col.prop(settings, spec.name)
    row = layout.row()
    row.operator("paint_lut.bake", icon="RENDER_STILL")
    if settings.stale:
        layout.label(text="Paint type changed since the last bake", icon="ERROR")
    elif settings.lut_path:
        layout.label(text=bpy.path.basename(settings.lut_path), icon="CHECKMARK")
        errors = api.fit_errors(material, variants=True)
        has_variant = api.OSL_VARIANT in errors  # a bake stores the variant only where its ramps carry weight
        offer = errors.pop(api.OSL_VARIANT, None) if not settings.osl else None
        if settings.osl_problem:  # asked for but not built here: the SVM closures render
            errors.pop(api.OSL_VARIANT, None)
        for target, fit in errors.items():
            layout.label(text=fit_error_text(target, fit), icon="ERROR" if fit.missed else "CHECKMARK")
            if target == "EEVEE" and fit.eevee_mode:
                layout.label(text=eevee_text(fit, api.eevee_mode(scene)), icon="INFO")
            if target == "EEVEE" and fit.missed:
                layout.label(text=EEVEE_LIMIT, icon="INFO")
        # Cycles' OSL variant: offered where the SVM fit misses its goals.
        if settings.osl or (offer is not None and errors.get("CYCLES") is not None and errors["CYCLES"].missed):
            layout.prop(settings, "osl")
            if offer is not None:
                layout.label(text=offer_text(offer), icon="INFO")
            if settings.osl_problem:
                layout.label(text=settings.osl_problem, icon="ERROR")
            elif scene is not None:
                drawn = api.cycles_variant(material, scene)
                layout.label(text=variant_text(settings.osl, drawn, has_variant), icon="INFO")
    if scene is not None and getattr(scene, "paint_lut", None) is not None:
        layout.prop(scene.paint_lut, "eevee_mode", text="EEVEE (scene)")


def eevee_text(fit, scene_mode: str) -> str:
    """The panel's EEVEE line for an ``api.FitError``: how EEVEE draws the
    material (exactly at one sample, or converged over N samples), and a
    note when the scene asks for the other mode (it applies at the next bake)."""
    if fit.exact:
        text = "EEVEE: exact at 1 sample"
    else:
        text = f"EEVEE: converged, about {fit.samples} samples (Render Samples in the scene)"
    if scene_mode != fit.eevee_mode:
        text += f"; the scene asks {scene_mode.title()}: bake to apply"
    return text


#: The panel's line where EEVEE misses its goal: why, and where to look instead.
EEVEE_LIMIT = "EEVEE draws every lobe as GGX and diffuse light as Lambert: Cycles shows this paint as fitted"


def offer_text(fit) -> str:
    """The panel's line offering Cycles' OSL variant (an ``api.FitError`` of it)."""
    return (
        f"With OSL, Cycles would render {100 * fit.error:.1f}% (target {100 * fit.target:.0f}%), "
        f"grazing light {100 * fit.grazing:.1f}% (target {100 * fit.grazing_target:.0f}%)"
    )


def variant_text(asked: bool, drawn: str, has_variant: bool = True) -> str:
    """The panel's line on what Cycles draws of the material in this scene
    (``api.cycles_variant``); ``has_variant``: whether the type's OSL
    variant has ramps at all (where they do not bring it nearer its goals
    it is the SVM fit, and Cycles renders that with OSL on or off)."""
    if drawn == "OSL":
        return "Cycles renders the OSL variant here"
    if not has_variant:
        return "The OSL ramps do not improve this paint type: Cycles renders its SVM closures"
    if asked:
        return "Cycles renders the SVM closures here: turn Open Shading Language on (CPU or OptiX) for the OSL variant"
    return "Cycles renders the SVM closures; the OSL variant needs Open Shading Language (CPU or OptiX)"


#: How the panel names each fit's engine.
ENGINE_LABELS = {"CYCLES": "Cycles", "EEVEE": "EEVEE", "OSL": "Cycles OSL"}


def seen_limit_text(limit: float) -> str:
    """The panel's note when "Color as Seen" is at its most (``seen_limit``)."""
    return f"Seen colour capped at {limit:.2f}: a white pigment shows no more through the binder"


def fit_error_text(target, fit) -> str:
    """The panel's line for an engine's ``api.FitError``: the fidelity
    measure over its whole grid and over the grazing band, with their goals."""
    label = ENGINE_LABELS.get(target, target.title())
    return (
        f"{label} fit error {100 * fit.error:.1f}% (target {100 * fit.target:.0f}%), "
        f"grazing light {100 * fit.grazing:.1f}% (target {100 * fit.grazing_target:.0f}%)"
    )


class _PaintLUTPanel:
    bl_label = "Paint LUT"

    def draw(self, context):
        draw_settings(self.layout, context.material, context.scene)


class MATERIAL_PT_paint_lut(_PaintLUTPanel, bpy.types.Panel):
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "material"

    @classmethod
    def poll(cls, context):
        return getattr(context, "material", None) is not None


class NODE_PT_paint_lut(_PaintLUTPanel, bpy.types.Panel):
    bl_space_type = "NODE_EDITOR"
    bl_region_type = "UI"
    bl_category = "Paint LUT"

    @classmethod
    def poll(cls, context):
        space = context.space_data
        return getattr(space, "tree_type", None) == "ShaderNodeTree" and getattr(context, "material", None) is not None


CLASSES = (MATERIAL_PT_paint_lut, NODE_PT_paint_lut)


register, unregister = bpy.utils.register_classes_factory(CLASSES)
