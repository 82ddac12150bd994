"""Headless API of the add-on (for scripts and farms): no UI involved.

A material's paint is a paint *type* (n, g, slope, distribution) baked once
into a LUT and fitted for every render engine (``lut.render.bake``), and colours
that are node-group inputs: ``bake_material`` bakes (or reuses) the type and
wires the groups; ``update_inputs`` sends the colours to the groups, which
is all a colour edit needs."""

from __future__ import annotations

import dataclasses
import json
import pathlib
import typing

import bpy

from . import export, nodes, osl, properties, validation
from ._lut import closures, eevee, fitting, lut, measure, render_bake
from .live import _loaded_lut, paint_of, update_inputs, working_space  # noqa: F401  (the API's names)

#: LUTs go here, relative to the saved .blend file.
LUT_DIRECTORY = "//paint_lut"


def lut_directory() -> pathlib.Path:
    """Where bakes are written: ``//paint_lut`` next to the saved .blend
    file, or for an unsaved file the extension's own user folder (Blender's
    ``extension_path_user``; a per-user folder under the temporary directory
    when the add-on runs outside an extension)."""
    if bpy.data.filepath:
        return pathlib.Path(bpy.path.abspath(LUT_DIRECTORY))
    return user_lut_directory()


def user_lut_directory() -> pathlib.Path:
    """Where an unsaved file's bakes go (``lut_directory``)."""
    package = __package__ or "addon"
    try:
        return pathlib.Path(bpy.utils.extension_path_user(package, path="paint_lut", create=True))
    except (ValueError, AttributeError, RuntimeError):
        import getpass
        import tempfile

        folder = pathlib.Path(tempfile.gettempdir()) / f"paint_lut-{getpass.getuser()}"
        folder.mkdir(parents=True, exist_ok=True)
        return folder


class FitError(typing.NamedTuple):
    """An engine's fit error at a material's colours: the fidelity measure
    (``lut.render.measure``) over its whole grid and over the grazing band
    (θl >= 60°), each with its goal."""

    error: float
    target: float
    grazing: float
    grazing_target: float
    #: EEVEE: "EXACT" or "CONVERGED" (the scene's mode the fit was made in),
    #: whether EEVEE sums the fit's closures exactly at one sample, and the
    #: samples its noisiest colour needs to converge (``lut.render.eevee.samples_for``).
    eevee_mode: str = ""
    exact: bool = True
    samples: int = 1

    @property
    def missed(self) -> bool:
        """Whether the whole measure or the grazing band misses its goal."""
        return self.error > self.target or self.grazing > self.grazing_target


@dataclasses.dataclass(frozen=True)
class BakeStatus:
    """A material's bake status: ``state`` ("baked", "cached", "unused" or
    "failed"), ``reason`` (why it failed), ``errors`` ({engine: fit error at
    the material's colours, the fidelity measure's whole grid}), ``misses``
    ({engine: FitError} where the fit misses its goal, whole or grazing
    band), ``key`` (the paint type's LUT key: materials with the same key
    shared one bake) and ``grazing`` ({engine: the fit error over the
    grazing band, θl >= 60°}).  ``str()`` gives the line to show
    ("failed: <reason>"); read the fields, never that text.  For scripts of
    earlier releases, which got the text itself, a status compares equal to
    its state's name (``status == "baked"``, ``status in {"baked",
    "cached"}``); string methods and ``json.dumps`` need ``str(status)``."""

    state: str
    reason: str = ""
    errors: dict = dataclasses.field(default_factory=dict)
    misses: dict = dataclasses.field(default_factory=dict)
    key: str = ""
    grazing: dict = dataclasses.field(default_factory=dict)

    def __str__(self):
        return f"{self.state}: {self.reason}" if self.reason else self.state

    def __eq__(self, other):
        # Earlier releases returned the state as a string: scripts comparing
        # ``status == "baked"`` keep working (the state alone, not the reason).
        if isinstance(other, str):
            return self.state == other
        if not isinstance(other, BakeStatus):
            return NotImplemented
        return dataclasses.astuple(self) == dataclasses.astuple(other)

    def __hash__(self):
        return hash(self.state)  # equal objects (a status and its state's name) hash alike


def engine_targets():
    """The render targets of this Blender: Cycles and EEVEE."""
    return closures.TARGETS


def eevee_calibration():
    """The Blender line whose measured EEVEE closure responses the EEVEE fit
    uses (``lut.render.eevee``): this Blender's, or None where EEVEE is not
    calibrated (Blender 4.x)."""
    return eevee.calibration_for(bpy.app.version)


#: The name of Cycles' OSL variant among a material's fit errors
#: (``fit_errors``, ``lut.render.bake.OSL_VARIANT``).
OSL_VARIANT = render_bake.OSL_VARIANT


def switch_variant(material) -> None:
    """Wire a baked material to the Cycles group its OSL setting asks for
    (the variant's or the SVM one), from its cached bake; a material not
    baked, or stale, takes it at its next bake.  Called when the setting
    changes (``properties.PaintLUTSettings.osl``)."""
    settings = material.paint_lut
    if settings.stale or not settings.lut_path:
        return
    try:
        result = render_bake.load_baked(
            bpy.path.abspath(settings.lut_path), targets=engine_targets(), exact_metallic=nodes.EXACT_METALLIC,
            eevee_calibration=eevee_calibration(), eevee_mode=eevee_mode(), osl=True,
        )  # fmt: skip
        store_result(material, paint_of(material), result, clear_stale=False)
    except (ValueError, OSError, lut.LUTError):
        settings.stale = True  # the bake's files are gone or damaged: it needs a bake (the panel says so)


properties.OSL_SWITCHED.append(switch_variant)


def cycles_variant(material, scene=None) -> str:
    """What Cycles draws of a material in a scene: "OSL" (its OSL variant:
    the material's setting is on, the bake has it and the scene renders
    Open Shading Language, ``osl.renders_osl``) or "SVM" (its SVM closures:
    the setting is off, or the scene renders SVM, where the variant's
    Script node draws nothing and the SVM closures alone render)."""
    scene = scene if scene is not None else getattr(bpy.context, "scene", None)
    if not material.paint_lut.osl or scene is None or not osl.renders_osl(scene):
        return "SVM"
    node = nodes.group_of(material, "CYCLES")
    drawn = node is not None and any(nd.type == "SCRIPT" for nd in node.node_tree.nodes)
    return OSL_VARIANT if drawn else "SVM"


def eevee_mode(scene=None) -> str:
    """How the scene's EEVEE draws paint materials (its Paint LUT setting,
    ``lut.render.fitting.EEVEE_MODES``): "CONVERGED" (the default; more
    closures where the three EEVEE sums exactly miss a goal, averaged over
    samples) or "EXACT" (at most those three: exact at one sample)."""
    scene = scene if scene is not None else getattr(bpy.context, "scene", None)
    settings = getattr(scene, "paint_lut", None) if scene is not None else None
    return settings.eevee_mode if settings is not None else fitting.DEFAULT_EEVEE_MODE


def store_result(material, paint: lut.Paint, result: render_bake.RenderBake, exact_metallic=None, clear_stale=True):
    """Record a finished bake on the material (LUT path relative to the
    .blend when it is saved), build or reuse its type's node groups (one per
    render engine), wire them, set the colour inputs and the fit errors, and
    (``clear_stale``) clear the stale flag."""
    settings = material.paint_lut
    path = result.lut_path
    settings.lut_path = str(path)
    if bpy.data.filepath:
        try:
            settings.lut_path = bpy.path.relpath(str(path))
        except ValueError:  # another drive (Windows): keep it absolute
            pass
    groups = {
        target: nodes.build_group(fit, result.fit_paths[target], exact_metallic) for target, fit in result.fits.items()
    }
    settings.osl_problem = ""
    if settings.osl and result.drawn_osl is not None and "CYCLES" in groups:  # Cycles' OSL variant (addon.osl)
        try:
            groups["CYCLES"] = nodes.build_group(result.osl, result.osl_path, exact_metallic)
        except (RuntimeError, ImportError, AttributeError) as exc:  # no OSL compiler in this Blender
            settings.osl_problem = f"The OSL variant could not be built ({exc or type(exc).__name__})"
    nodes.wire(material, groups, render_bake.node_inputs(paint, result.lut.internal_reflectance))
    settings.internal_reflectance = result.lut.internal_reflectance
    settings.diffuse_albedo = render_bake.diffuse_albedo(result.lut)
    nodes.build_seen_group(result.fits[next(iter(result.fits))], settings.diffuse_albedo)
    settings.fits = json.dumps(
        {
            target: {
                **f.grams(), "goal": f.target_error, "goals": list(f.goals),
                **(_drawing(f) if target == "EEVEE" else {}),
            }
            for target, f in result.variants().items()
            if target != OSL_VARIANT or result.drawn_osl is not None  # a variant without ramps is the SVM fit
        }
    )  # fmt: skip
    export.update_fallback(material, paint)
    if clear_stale:
        settings.stale = False


def bake_material(material, *, directory=None, force=False, exact_metallic=None, progress=None, **options):
    """Bake a material's paint now (blocking): its type's LUT and closure fits
    (cached by type: every colour of a type shares them), wired into the
    material's node tree.  ``directory``: where the files go (default
    ``lut_directory()``); ``exact_metallic``: whether Blender's Metallic BSDF
    is the exact dielectric lobe (default: this Blender's,
    ``nodes.EXACT_METALLIC``).  Returns the ``lut.render.bake.RenderBake``."""
    exact = nodes.exact_metallic_default(exact_metallic)
    paint = paint_of(material)
    result = render_bake.bake_for_render(
        paint, directory or lut_directory(), targets=engine_targets(), exact_metallic=exact,
        eevee_calibration=eevee_calibration(), eevee_mode=eevee_mode(), osl=True, force=force, progress=progress,
        **options,
    )  # fmt: skip
    store_result(material, paint, result, exact)
    material.paint_lut.enabled = True
    return result


def finish_background_bake(material, paint, result, type_key_at_start) -> bool:
    """Store a background bake's result on its material.  If the paint type
    was edited while the bake ran, the result is wired (it is a valid bake of
    the type it was started with) but the material stays stale: the panel
    never says baked for a type it did not bake.  The colours are inputs and
    are sent again either way.  Returns whether the material is current."""
    current = material.paint_lut.type_key() == type_key_at_start
    store_result(material, paint, result, clear_stale=current)
    update_inputs(material)
    material.paint_lut.enabled = True
    return current


def fit_errors(material, *, variants=False) -> dict:
    """{engine: FitError} of the material's current colours against its
    bake's fits: the fidelity measure (``lut.render.measure``) over its whole
    grid and over the grazing band, with their goals
    (``lut.render.fitting.reported_errors``); empty before a bake.  Cycles'
    OSL variant is "OSL" (``OSL_VARIANT``) where the material uses it (its
    setting is on and the variant could be built here), or with
    ``variants`` wherever it was baked with ramps (what it would render).
    A bake stored without the grazing band's matrices (an earlier release)
    reports the whole figure for the band too."""
    settings = material.paint_lut
    if not settings.fits or settings.internal_reflectance <= 0:
        return {}
    try:
        fits = json.loads(settings.fits)
        paint = paint_of(material)
    except ValueError:
        return {}
    amps = render_bake.amplitudes_of_inputs(
        render_bake.node_inputs(paint, settings.internal_reflectance), settings.internal_reflectance
    )
    out = {}
    for target, f in fits.items():
        if target == OSL_VARIANT and not (variants or _renders_osl_group(settings)):
            continue
        whole, grazing = fitting.reported_errors(f, amps)
        kind = measure.goals(target, paint.slope == 0)  # an earlier release stored the whole goal alone
        goals = f.get("goals") or (f.get("goal", kind[0]), kind[1])
        out[target] = FitError(whole, float(goals[0]), grazing, float(goals[1]), **_drawn(target, f, whole))
    return out


def _renders_osl_group(settings) -> bool:
    """Whether a material's Cycles group is its OSL variant's: the setting
    is on and the variant could be built here (no ``osl_problem``)."""
    return settings.osl and not settings.osl_problem


def _result_errors(result: render_bake.RenderBake, paint, osl=False) -> dict:
    """{engine: FitError} of a bake's fits at a paint's colours (Cycles' OSL
    variant too with ``osl``: a material that uses it)."""
    out = {}
    for target, (whole, grazing) in result.all_errors(paint).items():
        if target == OSL_VARIANT and not (osl and result.drawn_osl is not None):
            continue
        fit = result.variants()[target]
        out[target] = FitError(whole, fit.goals[0], grazing, fit.goals[1], **_drawn(target, _drawing(fit), whole))
    return out


def _drawing(fit) -> dict:
    """What a material stores of how EEVEE draws a fit: its mode, whether it
    sums exactly at one sample, and its noisiest colour's spread."""
    return {"eevee_mode": fit.eevee_mode, "exact": fit.sums_exactly, "spread": fit.noisiest_spread}


def _drawn(target, stored: dict, whole: float) -> dict:
    """How EEVEE draws a fit (``FitError``'s last fields) from what a
    material stores of it: its mode, whether exact at one sample, and the
    samples its noisiest colour needs to fall below ``whole``, the fit's
    error at the material's colour (``eevee.NOISE_FLOOR`` at least)."""
    if target != "EEVEE":
        return {}
    return {
        "eevee_mode": stored.get("eevee_mode", "EXACT"), "exact": bool(stored.get("exact", True)),
        "samples": eevee.samples_for(float(stored.get("spread", 0.0)), max(whole, eevee.NOISE_FLOOR)),
    }  # fmt: skip


def set_paint(material, paint: lut.Paint) -> None:
    """Store a paint on a material's settings: a preset by name, another
    spectral paint whole (the Spectral preset), an RGB paint by its fields
    (converted to the scene's working space).  Values outside the panel's
    limits are refused (``validation.check_paint_fits``), never clamped."""
    settings = material.paint_lut
    for name in lut.PRESETS:
        if paint == lut.preset(name, paint.space):
            settings.preset = name
            return
    validation.check_paint_fits(paint)
    if paint.spectral:
        settings.spectral_paint = json.dumps(paint.to_dict())
        settings.preset = "SPECTRAL"  # fills the fields with its RGB
        return
    settings.preset = "CUSTOM"
    properties.set_fields(settings, paint.converted(working_space()))


def new_material(name: str, paint: lut.Paint, **options):
    """A new material rendering ``paint``, baked and wired (``bake_material``'s
    options)."""
    material = bpy.data.materials.new(name)
    try:
        set_paint(material, paint)
        material.paint_lut.enabled = True
        bake_material(material, **options)
    except Exception:
        bpy.data.materials.remove(material)
        raise
    return material


def used_materials(scenes) -> set:
    """The materials ``scenes`` render (original, not evaluated, data).

    Where Blender has evaluated a view layer (the open scene's), every object
    instance its depsgraph holds: collection instances, Geometry Nodes' Set
    Material and instances included.  For every scene, also what its objects
    reach without evaluation: their slots (hidden objects too), collection
    instances, the materials and objects a Geometry Nodes modifier's inputs
    and node tree name, and the background set's objects."""
    used = set()
    for scene in scenes:
        used |= _materials_reached(scene)
        for view_layer in scene.view_layers:
            depsgraph = view_layer.depsgraph  # None for a scene Blender has not evaluated
            if depsgraph is None:
                continue
            depsgraph.update()
            for instance in depsgraph.object_instances:
                obj = instance.object
                materials = [slot.material for slot in obj.material_slots]
                materials += list(getattr(obj.data, "materials", None) or ())
                used.update(m.original for m in materials if m is not None)
    return used


def _modifier_inputs(modifier):
    """The input values of a Geometry Nodes modifier: its ID properties up to
    Blender 5.1, ``modifier.properties.inputs.<identifier>.value`` from 5.2
    (where the modifier no longer holds ID properties)."""
    try:
        return [modifier[key] for key in modifier.keys()]
    except TypeError:
        pass
    inputs = getattr(getattr(modifier, "properties", None), "inputs", None)
    group = modifier.node_group
    if inputs is None or group is None:
        return []
    values = []
    for item in group.interface.items_tree:
        if getattr(item, "in_out", "") == "INPUT" and hasattr(inputs, item.identifier):
            values.append(getattr(getattr(inputs, item.identifier), "value", None))
    return values


def _materials_reached(scene) -> set:
    """The materials a scene's objects reach without evaluating anything."""
    used, objects, trees = set(), set(), set()

    def visit_id(value):
        if isinstance(value, bpy.types.Material):
            used.add(value)
        elif isinstance(value, bpy.types.Object):
            visit_object(value)
        elif isinstance(value, bpy.types.Collection):
            for obj in value.all_objects:
                visit_object(obj)

    def visit_tree(tree):
        if tree is None or tree in trees:
            return
        trees.add(tree)
        for node in tree.nodes:
            visit_id(getattr(node, "material", None))
            if node.type == "GROUP":
                visit_tree(node.node_tree)
            for socket in node.inputs:
                if socket.type in ("MATERIAL", "OBJECT", "COLLECTION"):
                    visit_id(socket.default_value)

    def visit_object(obj):
        if obj in objects:
            return
        objects.add(obj)
        used.update(slot.material for slot in obj.material_slots if slot.material)
        if obj.instance_type == "COLLECTION":
            visit_id(obj.instance_collection)
        for modifier in obj.modifiers:
            if modifier.type == "NODES":
                for value in _modifier_inputs(modifier):
                    visit_id(value)
                visit_tree(modifier.node_group)

    while scene is not None and scene not in objects:
        objects.add(scene)  # a background-set cycle ends here
        for obj in scene.objects:
            visit_object(obj)
        scene = scene.background_set
    return used


def is_current(material, paint, *, directory=None, exact_metallic=None, **options) -> bool:
    """Whether a material's bake is up to date: not stale, its LUT where this
    paint type's belongs and verified, each engine's fit readable, verified
    and of that LUT, and the material wired to this version's groups of
    those fits (a corrupted or missing file means a rebake, not a failure)."""
    settings = material.paint_lut
    if settings.stale or not settings.lut_path:
        return False
    exact = nodes.exact_metallic_default(exact_metallic)
    path = lut.lut_path(paint, directory or lut_directory(), **options)
    # Resolved both ways: a store outside the file's folder is referenced as
    # //../store/..., which names the same file as the store's own path.
    if pathlib.Path(bpy.path.abspath(settings.lut_path)).resolve() != path.resolve():
        return False
    try:
        table = lut.load_lut(path)
        if not path.stem.endswith(table.key[:24]):  # another type's LUT renamed onto this one's name
            return False
        if settings.osl and settings.osl_problem:
            return False  # the OSL variant could not be built: a bake tries again (this Blender may have OSL)
        for target in engine_targets():
            fit_file = lut.render.fitting.fit_path(path, target, exact, eevee_calibration(), eevee_mode())
            fitted = lut.render.fitting.read_fit(fit_file)
            if target == "CYCLES" and settings.osl:
                # The Cycles group draws the OSL variant, where its ramps carry weight.
                variant_file = lut.render.fitting.fit_path(path, target, exact, osl=True)
                variant = lut.render.fitting.read_fit(variant_file)
                if variant.base_key != lut.render.fitting.content_key(fitted):
                    return False
                if variant.draws_ramps:
                    fit_file, fitted = variant_file, variant
            if fitted.lut_key != table.key or fitted.target != target or fitted.stale_goals:
                return False
            node = nodes.group_of(material, target)
            if node is None or not nodes.is_paint_group(node.node_tree):
                return False
            if node.node_tree.get("paint_lut_fit", "").split(":")[0] != table.key:
                return False
            if nodes.group_weights_path(node.node_tree) != fit_file.resolve():  # e.g. after Save As elsewhere
                return False
    except lut.LUTError:
        return False
    return True


def bake_materials(used, force=False, *, directory=None, exact_metallic=None, **options) -> dict:
    """Bake the paint materials (those with Use Paint LUT) of the file that
    are in ``used``.  Returns {material name: BakeStatus} whose ``state`` is
    "baked" (computed or wired anew), "cached" (up to date, nothing
    computed), "unused" (skipped) or "failed" (with its ``reason``; the
    material is left as it was).
    Materials of one paint type share one bake: the first computes it, the
    others find it cached on disk (``BakeStatus.key`` groups them)."""
    status = {}
    for material in bpy.data.materials:
        if not material.paint_lut.enabled:
            continue
        if material not in used:
            status[material.name] = BakeStatus("unused")
            continue
        try:
            paint = paint_of(material)
            if not force and is_current(material, paint, directory=directory, exact_metallic=exact_metallic, **options):
                key = lut.lut_path(paint, directory or lut_directory(), **options).stem.split("-")[-1]
                errors = fit_errors(material)
                status[material.name] = _status("cached", errors, key)
                continue
            result = bake_material(material, directory=directory, force=force, exact_metallic=exact_metallic, **options)
            errors = _result_errors(result, paint, _renders_osl_group(material.paint_lut))
            status[material.name] = _status("baked", errors, result.lut_path.stem.split("-")[-1])
        except (ValueError, OSError, RuntimeError, TypeError, KeyError) as exc:
            status[material.name] = BakeStatus("failed", str(exc) or type(exc).__name__)
    return status


def _status(state, errors, key):
    """A status from {engine: FitError}: a miss where either figure misses its goal."""
    return BakeStatus(
        state,
        errors={t: v.error for t, v in errors.items()},
        misses={t: v for t, v in errors.items() if v.missed},
        key=key,
        grazing={t: v.grazing for t, v in errors.items()},
    )


def bake_scene(scene, force=False, **options) -> dict:
    """Bake the paint materials the scene's objects use (``bake_materials``)."""
    return bake_materials(used_materials([scene]), force=force, **options)
